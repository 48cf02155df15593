"""Synchronised matplotlib animations of one or several skeletons (ground truth | CaMN | HA2G ...).

Optional panels under the skeletons: the audio waveform with audio beats and
motion beats under a moving cursor, the ARKit blendshapes of the face (bars or
a heat map), and the current word as a caption. Lines are updated in place
(``set_data_3d``); axes are never rebuilt, and frames are subsampled to the
playback rate asked (``out_fps``).

Usage (skipped by the doctests: ``gt``, ``camn``, ``y`` and ``take`` stand for your own data; it writes a file):

>>> anim = animate_skeletons({"ground truth": gt, "CaMN": camn}, skeleton, fps=15,
...                          audio=y, sr=16000, words=take.words)        # doctest: +SKIP
>>> anim                        # in JupyterLab: shown inline as JS/HTML (to_jshtml)  # doctest: +SKIP
>>> anim.save_as("build/clip.gif")     # or .mp4 (needs ffmpeg) or .html             # doctest: +SKIP

Taught in notebooks/08_visualisation_3d.ipynb, section 3 (one clock for everything: the synced animation).
"""

from __future__ import annotations

import shutil
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

from beatlite.viz._files import atomic_target
from beatlite.viz._inputs import (
    check_fps,
    check_positions,
    check_words,
    frame_indices,
    skeleton_bones,
    word_at,
)
from beatlite.viz.plot3d import SkeletonArtist, SkeletonLike, setup_axes
from beatlite.viz.style import STYLE, SYSTEM_COLOURS

FACE_PANELS = ("bars", "heatmap")


class SkeletonAnimation(FuncAnimation):
    """A ``FuncAnimation`` that knows its playback rate, shows itself inline and saves to GIF/MP4/HTML.

    Attributes
    ----------
    fps : float
        Playback frames per second.
    times : (K,) float64
        Time in seconds of each animation frame.
    """

    def __init__(self, fig: Any, update: Any, times: np.ndarray, fps: float) -> None:
        self.fps = float(fps)
        self.times = times
        self._draw_update = update
        super().__init__(
            fig, update, frames=len(times), interval=1000.0 / fps, blit=False, cache_frame_data=False
        )

    @property
    def figure(self) -> Any:
        """The matplotlib Figure being animated (not registered with pyplot)."""
        return self._fig

    def frame_image(self, k: int) -> np.ndarray:
        """Draw animation frame ``k`` and return it as an ``(H, W, 3) uint8`` RGB image (thumbnails, tests)."""
        if not -len(self.times) <= int(k) < len(self.times):
            raise ValueError(f"k={k} is out of range for {len(self.times)} animation frames")
        k = int(k) % len(self.times)
        self._draw_update(k)
        self._fig.canvas.draw()
        image = np.asarray(self._fig.canvas.buffer_rgba())[..., :3].copy()
        self._draw_update(k)  # the first draw event resets the artists to frame 0 (FuncAnimation._start)
        return image

    def to_html(self) -> str:
        """The animation as a self-contained JS/HTML player (``to_jshtml``)."""
        import matplotlib.pyplot as plt

        with plt.rc_context({"animation.embed_limit": STYLE["animation.embed_limit"]}):
            return self.to_jshtml(fps=self.fps)

    def _repr_html_(self) -> str:  # JupyterLab shows the player when the object ends a cell
        return self.to_html()

    def save_as(self, path: str | Path, *, dpi: float | None = None) -> Path:
        """Write the animation to ``.gif`` (pillow), ``.mp4`` (ffmpeg) or ``.html`` (JS player), atomically.

        Parameters
        ----------
        path : str or Path
            Output file; the suffix chooses the format.
        dpi : float, optional
            Resolution (default: the figure's).

        Returns
        -------
        Path
            ``path``.
        """
        return save_animation(self, path, fps=self.fps, dpi=dpi)


def ffmpeg_available() -> bool:
    """True when an ``ffmpeg`` executable is on ``PATH`` (needed for MP4 export)."""
    return shutil.which("ffmpeg") is not None


def save_animation(anim: Any, path: str | Path, *, fps: float, dpi: float | None = None) -> Path:
    """Save a matplotlib animation as GIF (pillow), MP4 (ffmpeg) or HTML (JS player), atomically.

    Parameters
    ----------
    anim : matplotlib.animation.Animation
        The animation.
    path : str or Path
        Output; suffix ``.gif``, ``.mp4`` or ``.html``.
    fps : float
        Playback frames per second.
    dpi : float, optional
        Resolution.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    fps = check_fps(fps)
    suffix = path.suffix.lower()
    if suffix == ".gif":
        writer: Any = PillowWriter(fps=fps)
    elif suffix == ".mp4":
        if not ffmpeg_available():
            raise RuntimeError(
                f"cannot write {path}: MP4 export needs the ffmpeg program, which is not on PATH. "
                "Install it (Debian/Ubuntu: `sudo apt-get install ffmpeg`; or run scripts/system_deps.sh) "
                "or save as .gif instead."
            )
        writer = FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
    elif suffix in (".html", ".htm"):
        writer = None
    else:
        raise ValueError(f"path must end in .gif, .mp4 or .html, got {path.name!r}")
    with atomic_target(path) as tmp:
        if writer is None:
            html = anim.to_jshtml(fps=fps)
            tmp.write_text(html, encoding="utf-8")
        else:
            anim.save(str(tmp), writer=writer, dpi=dpi)
    return path


def _as_list(values: Any, n: int, name: str) -> list[Any]:
    """One skeleton per sequence: a list/tuple of skeletons is used as is, anything else is repeated."""
    is_per_sequence = isinstance(values, list | tuple) and len(values) > 0 and not _is_int(values[0])
    if is_per_sequence:
        if len(values) != n:
            raise ValueError(f"{name}: {len(values)} given for {n} sequences")
        return list(values)
    return [values] * n


def _is_int(v: Any) -> bool:
    return isinstance(v, int | np.integer)


def _envelope(y: np.ndarray, sr: float, n_bins: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Min/max envelope of a waveform in ``n_bins`` bins: (times s, low, high)."""
    n = len(y)
    n_bins = max(1, min(n_bins, n))
    edges = np.linspace(0, n, n_bins + 1).astype(np.int64)
    lo = np.minimum.reduceat(y, edges[:-1])
    hi = np.maximum.reduceat(y, edges[:-1])
    t = (edges[:-1] + edges[1:]) / 2 / sr
    return t, lo, hi


def animate_skeletons(
    positions: Any,
    skeleton: SkeletonLike | Sequence[SkeletonLike],
    fps: float,
    *,
    out_fps: float | None = 15.0,
    labels: Sequence[str] | None = None,
    audio: Any = None,
    sr: float = 16000,
    audio_beats: Any = None,
    motion_beats: Any = None,
    words: Any = None,
    face: Any = None,
    face_names: Sequence[str] | None = None,
    face_fps: float | None = None,
    face_panel: str = "bars",
    view: str | tuple[float, float] = "default",
    panel_size: float = 3.0,
    dpi: float = 80,
    max_frames: int | None = None,
) -> SkeletonAnimation:
    """Animate one or several skeletons side by side, in sync, with optional audio, face and word panels.

    Parameters
    ----------
    positions : (T, J, 3) array, or mapping label -> (T_i, J_i, 3), or sequence of arrays
        Joint positions, centimetres, Y up, all at ``fps``. Several sequences are
        shown left to right (e.g. ``{"ground truth": gt, "CaMN": a, "HA2G": b}``)
        on the same clock; a shorter one holds its last frame.
    skeleton : Skeleton or (J,) parents array, or a sequence of them (one per sequence)
        Hierarchy of each sequence.
    fps : float
        Frame rate of ``positions`` (frames per second).
    out_fps : float or None
        Playback rate; frames are subsampled to it (``None``: every frame).
    labels : sequence of str, optional
        Panel titles (default: mapping keys, or none for one sequence).
    audio : (N,) float array, optional
        Waveform in [-1, 1] for the timeline panel.
    sr : float
        Audio sample rate, Hz.
    audio_beats : (A,) float array, optional
        Audio beat / onset times, seconds (drawn as full-height lines).
    motion_beats : (M,) float array, optional
        Motion beat times, seconds (drawn as short ticks at the bottom).
    words : (starts, ends, words) or WordIntervals, optional
        Word timings in seconds; the current word is shown as a caption.
    face : (T_f, 51) float array, optional
        ARKit blendshape weights in [0, 1] at ``face_fps``.
    face_names : sequence of str, optional
        Blendshape names (bar labels / heat-map rows).
    face_fps : float, optional
        Frame rate of ``face`` (default ``fps``; BEAT's JSON is 60 fps).
    face_panel : {"bars", "heatmap"}
        Bars of the current frame, or the heat map over time with a cursor.
    view : str or (elev, azim)
        Camera of every skeleton panel.
    panel_size : float
        Width and height of a skeleton panel, inches.
    dpi : float
        Figure resolution (pixels = inches x dpi).
    max_frames : int, optional
        Stop after this many animation frames.

    Returns
    -------
    SkeletonAnimation
        A ``FuncAnimation``; ends a notebook cell -> inline player; ``.save_as("x.gif")``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fps = check_fps(fps)
    rate = None if out_fps is None else check_fps(out_fps, "out_fps")
    if isinstance(positions, Mapping):
        labels = list(positions) if labels is None else labels
        seqs = list(positions.values())
    elif isinstance(positions, list | tuple):
        seqs = list(positions)
    else:
        seqs = [positions]
    if not seqs:
        raise ValueError("positions: no sequence to animate")
    n = len(seqs)
    if labels is not None and len(labels) != n:
        raise ValueError(f"labels: {len(labels)} labels for {n} sequences")
    skels = _as_list(skeleton, n, "skeleton")
    bones = [skeleton_bones(s) for s in skels]
    seqs = [check_positions(p, b.n_joints, f"positions[{i}]") for i, (p, b) in enumerate(zip(seqs, bones))]
    n_frames = max(len(p) for p in seqs)
    idx = frame_indices(n_frames, fps, rate)
    if max_frames is not None:
        idx = idx[: int(max_frames)]
    times = idx / fps
    play_fps = (
        fps if rate is None or rate >= fps else fps / max(np.mean(np.diff(idx)) if len(idx) > 1 else 1, 1)
    )

    wave = None
    if audio is not None:
        wave = np.asarray(audio, dtype=np.float64)
        if wave.ndim != 1 or wave.size == 0:
            raise ValueError(f"audio must be a non-empty (N,) mono waveform, got shape {wave.shape}")
        sr = check_fps(sr, "sr")
    beats_a = None if audio_beats is None else np.asarray(audio_beats, dtype=np.float64).reshape(-1)
    beats_m = None if motion_beats is None else np.asarray(motion_beats, dtype=np.float64).reshape(-1)
    timeline = wave is not None or beats_a is not None or beats_m is not None
    word_table = None if words is None else check_words(words)

    weights = None
    if face is not None:
        weights = np.asarray(face, dtype=np.float64)
        if weights.ndim != 2 or weights.shape[0] == 0:
            raise ValueError(f"face must be (T, 51) blendshape weights, got shape {weights.shape}")
        if face_names is not None and len(face_names) != weights.shape[1]:
            raise ValueError(f"face_names: {len(face_names)} names for {weights.shape[1]} blendshapes")
        if face_panel not in FACE_PANELS:
            raise ValueError(f"face_panel must be one of {FACE_PANELS}, got {face_panel!r}")
        f_fps = fps if face_fps is None else check_fps(face_fps, "face_fps")

    heights = [panel_size] + ([1.1] if timeline else []) + ([1.4] if weights is not None else [])
    caption_h = 0.3 if word_table is not None else 0.0
    width = max(panel_size * n, 6.0 if (timeline or weights is not None) else 0.0)
    with plt.rc_context(dict(STYLE)):
        fig = Figure(figsize=(width, sum(heights) + caption_h), dpi=dpi)
        FigureCanvasAgg(fig)
        grid = fig.add_gridspec(
            len(heights),
            n,
            height_ratios=heights,
            hspace=0.35,
            wspace=0.0,
            left=0.08,
            right=0.98,
            bottom=(caption_h + 0.3) / (sum(heights) + caption_h)
            if len(heights) > 1
            else caption_h / (sum(heights) + caption_h),
            top=0.93,
        )
        artists = []
        for i in range(n):
            ax = fig.add_subplot(grid[0, i], projection="3d")
            setup_axes(ax, seqs[i], view=view)
            artists.append(SkeletonArtist(ax, bones[i]))
            if labels is not None:
                ax.set_title(str(labels[i]), color=SYSTEM_COLOURS[i % len(SYSTEM_COLOURS)])
        row = 1
        cursors = []
        if timeline:
            ax_t = fig.add_subplot(grid[row, :])
            row += 1
            end = max(n_frames / fps, len(wave) / sr if wave is not None else 0.0)
            if wave is not None:
                tw, lo, hi = _envelope(wave, sr, 2000)
                ax_t.fill_between(tw, lo, hi, color="0.6", lw=0, label="audio")
            if beats_a is not None:
                ax_t.vlines(beats_a, -1, 1, color="#1f77b4", lw=0.8, alpha=0.8, label="audio beats")
            if beats_m is not None:
                ax_t.vlines(beats_m, -1, -0.4, color="#d62728", lw=1.6, label="motion beats")
            ax_t.set_xlim(0, end)
            ax_t.set_ylim(-1, 1)
            ax_t.set_yticks([])
            ax_t.set_xlabel("time (s)")
            ax_t.legend(loc="upper right", ncol=3, fontsize=7)
            cursors.append(ax_t.axvline(0.0, color="k", lw=1.2))
        bars = None
        if weights is not None:
            ax_f = fig.add_subplot(grid[row, :])
            k_face = weights.shape[1]
            if face_panel == "bars":
                bars = ax_f.bar(np.arange(k_face), weights[0], color="#2e8b57", width=0.8)
                ax_f.set_ylim(0, max(1.0, float(weights.max())))
                ax_f.set_xlim(-0.6, k_face - 0.4)
                ax_f.set_ylabel("weight")
                if face_names is not None:
                    ax_f.set_xticks(np.arange(k_face), face_names, rotation=90, fontsize=5)
                else:
                    ax_f.set_xlabel("blendshape")
            else:
                t_face = len(weights) / f_fps
                ax_f.imshow(
                    weights.T,
                    aspect="auto",
                    origin="lower",
                    extent=(0, t_face, -0.5, k_face - 0.5),
                    vmin=0,
                    vmax=1,
                    cmap="magma",
                    interpolation="nearest",
                )
                ax_f.set_ylabel("blendshape")
                ax_f.set_xlabel("time (s)")
                cursors.append(ax_f.axvline(0.0, color="w", lw=1.2))
        caption = fig.text(0.5, 0.02, "", ha="center", va="bottom", fontsize=13) if word_table else None

    def update(k: int) -> list[Any]:
        t = float(times[k])
        changed: list[Any] = []
        for art, seq in zip(artists, seqs):
            art.update(seq[min(int(idx[k]), len(seq) - 1)])
            changed += art.artists
        for c in cursors:
            c.set_xdata([t, t])
            changed.append(c)
        if bars is not None:
            row_w = weights[min(int(round(t * f_fps)), len(weights) - 1)]
            for rect, h in zip(bars, row_w):
                rect.set_height(h)
            changed += list(bars)
        if caption is not None:
            caption.set_text(word_at(t, *word_table))
            changed.append(caption)
        return changed

    update(0)
    return SkeletonAnimation(fig, update, times, play_fps)
