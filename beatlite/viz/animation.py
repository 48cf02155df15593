"""Synchronised matplotlib animations of one or several skeletons (ground truth | CaMN | HA2G ...).

Optional panels under the skeletons, each described by one small object: the
:class:`Timeline` (audio waveform, audio beats and motion beats under a moving
cursor), the :class:`FacePanel` (ARKit blendshapes by name, as a heat map or
bars), and the current word as a caption between the skeletons and the
timeline. Every skeleton panel has the same scale and the same joint-group
colours; a floor is drawn only under skeletons with feet. Lines are updated in
place (``set_data_3d``); axes are never rebuilt, and frames are subsampled to
the playback rate asked (``out_fps``). The figure is 960 pixels wide by default
(slide size, :data:`beatlite.viz.style.SLIDE_WIDTH_PX`).

Taught in notebook 08, section 3 ("One clock for everything").

Usage (skipped by the doctests: ``gt``, ``camn``, ``y`` and ``take`` stand for your own data; it writes a file):

>>> anim = animate_skeletons({"ground truth": gt, "CaMN": camn}, skeleton, fps=15,
...                          timeline=Timeline(audio=y, sr=16000, audio_beats=onsets),
...                          words=take.words, face=FacePanel(take.face, take.face_names))  # doctest: +SKIP
>>> anim                        # in JupyterLab: shown inline as JS/HTML (to_jshtml)  # doctest: +SKIP
>>> anim.save_as("build/clip.gif")     # or .mp4 (needs ffmpeg) or .html             # doctest: +SKIP

Taught in notebooks/08_visualisation_3d.ipynb, section 3 (one clock for everything: the synced animation).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

from beatlite.constants import SR
from beatlite.viz._files import atomic_target
from beatlite.viz._inputs import (
    Bones,
    check_fps,
    check_words,
    checked_sequences,
    frame_indices,
    word_at,
)
from beatlite.viz.face import most_active
from beatlite.viz.plot3d import SkeletonArtist, SkeletonLike, half_extents, setup_axes
from beatlite.viz.style import SLIDE_WIDTH_PX, STYLE, legend_outside, system_colours

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

    def to_html(self, *, dpi: float | None = None, frame_format: str = "png") -> str:
        """The animation as a self-contained JS/HTML player (``to_jshtml``).

        Parameters
        ----------
        dpi : float, optional
            Resolution of the embedded frames (default: the figure's, 960 px wide);
            e.g. ``dpi=80`` embeds 768-px frames to keep a saved notebook small. The
            player shows the frames at that size, so the figure is checked at that
            dpi first (:func:`beatlite.viz.check.check_figure`, as ``BEATLITE_FIGURE_CHECK``
            says): at ``dpi=60`` (576 px) the 9-pt tick labels and legends are 7.5 px
            high, under the 8 px the check asks for.
        frame_format : {"png", "jpeg"}
            Format of the embedded frames; JPEG frames are several times smaller.

        Returns
        -------
        str
            HTML with the frames base64-embedded.
        """
        import matplotlib.pyplot as plt

        from beatlite.viz.check import check_figure, check_mode, report_problems

        if (mode := check_mode()) != "off":
            shown = self._fig.dpi if dpi is None else float(dpi)
            report_problems(check_figure(self._fig, dpi=shown), f"to_html(dpi={shown:g})", mode)
            self._draw_update(0)  # the check drew the figure: back to the first frame

        params = {
            "animation.embed_limit": STYLE["animation.embed_limit"],
            "animation.frame_format": frame_format,
        }
        params["savefig.dpi"] = "figure" if dpi is None else float(dpi)
        self.__dict__.pop("_html_representation", None)  # to_jshtml caches its first answer
        with plt.rc_context(params):
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

    Raises
    ------
    ValueError
        Another suffix.
    RuntimeError
        ``.mp4`` without ffmpeg on ``PATH`` (:func:`ffmpeg_available`).
    beatlite.viz.check.FigureError
        Under ``BEATLITE_FIGURE_CHECK=raise``, a figure with text under 8 px at ``dpi`` (nothing is written).

    Examples
    --------
    Three animation frames of a moving clip make a GIF of three frames, 960 px wide:

    >>> import tempfile
    >>> from PIL import Image
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up
    >>> clip = np.repeat(pose[None], 30, axis=0)
    >>> clip[:, 3, 1] += 2.0 * np.arange(30)  # the right hand rises 2 cm per frame
    >>> anim = animate_skeletons(clip, parents, fps=30, max_frames=3)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     gif = Image.open(save_animation(anim, Path(tmp) / "clip.gif", fps=anim.fps))
    ...     gif.n_frames, gif.size[0]
    (3, 960)
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
    from beatlite.viz.check import check_figure, check_mode, report_problems

    fig = getattr(anim, "_fig", None)
    if fig is not None and (mode := check_mode()) != "off":
        shown = fig.dpi if dpi is None else float(dpi)
        report_problems(check_figure(fig, dpi=shown), f"save_animation({path.name!r})", mode)
        if isinstance(anim, SkeletonAnimation):
            anim._draw_update(0)
    with atomic_target(path) as tmp:
        if writer is None:
            html = anim.to_jshtml(fps=fps)
            tmp.write_text(html, encoding="utf-8")
        else:
            anim.save(str(tmp), writer=writer, dpi=dpi)
    return path


@dataclass(frozen=True)
class Timeline:
    """The timeline panel of :func:`animate_skeletons`: waveform, audio beats and motion beats.

    Attributes
    ----------
    audio : (N,) float array, optional
        Mono waveform in [-1, 1] (drawn as its min/max envelope).
    sr : float
        Sample rate of ``audio``, Hz.
    audio_beats : (A,) float array, optional
        Audio beat / onset times, seconds (full-height lines).
    motion_beats : (M,) float array, optional
        Motion beat times, seconds (short ticks at the bottom).

    Examples
    --------
    >>> Timeline(audio=np.zeros(32000), sr=16000).duration  # seconds
    2.0
    >>> Timeline(sr=16000).checked()
    Traceback (most recent call last):
    ...
    ValueError: timeline: give audio, audio_beats or motion_beats
    """

    audio: Any = None
    sr: float = SR
    audio_beats: Any = None
    motion_beats: Any = None

    def checked(self) -> Timeline:
        """A copy with float64 arrays, or a ValueError naming the bad field."""
        wave = None
        if self.audio is not None:
            wave = np.asarray(self.audio, dtype=np.float64)
            if wave.ndim != 1 or wave.size == 0:
                raise ValueError(f"audio must be a non-empty (N,) mono waveform, got shape {wave.shape}")
        beats = [None if b is None else np.asarray(b, dtype=np.float64).reshape(-1) for b in
                 (self.audio_beats, self.motion_beats)]  # fmt: skip
        if wave is None and beats[0] is None and beats[1] is None:
            raise ValueError("timeline: give audio, audio_beats or motion_beats")
        return Timeline(wave, check_fps(self.sr, "sr"), *beats)

    @property
    def duration(self) -> float:
        """Length of the waveform in seconds (0 without one)."""
        return 0.0 if self.audio is None else len(self.audio) / self.sr


@dataclass(frozen=True)
class FacePanel:
    """The face panel of :func:`animate_skeletons`: ARKit blendshape weights, labelled by name.

    Attributes
    ----------
    weights : (T_f, K) float array, values in [0, 1]
        Blendshape weights (BEAT: K = 51).
    names : sequence of str, optional
        The K blendshape names (row / bar labels; ``"blendshape k"`` otherwise).
    fps : float, optional
        Frame rate of ``weights`` (default: the skeletons' ``fps``; BEAT's JSON is 60).
    kind : {"heatmap", "bars"}
        Heat map over time with a cursor, or bars of the current frame.
    top : int, optional
        Show only the ``top`` blendshapes that vary most over the clip (largest
        standard deviation), in their original order, so that every label is
        readable; ``None`` shows all K.

    Examples
    --------
    :func:`animate_skeletons` draws what :meth:`checked` keeps: with ``top=1``, the one blendshape that moves:

    >>> weights = np.zeros((60, 3))
    >>> weights[:, 1] = np.linspace(0.0, 1.0, 60)
    >>> shown = FacePanel(weights, ["eyeBlinkLeft", "jawOpen", "mouthSmileLeft"], fps=60, top=1).checked(15)
    >>> shown.names, shown.weights.shape, shown.fps
    (['jawOpen'], (60, 1), 60.0)
    """

    weights: Any
    names: Sequence[str] | None = None
    fps: float | None = None
    kind: str = "heatmap"
    top: int | None = 12

    def checked(self, fps: float) -> FacePanel:
        """A copy with the rows to show selected, names filled and ``fps`` set; ValueError on bad input."""
        w = _check_face(self.weights, self.names, self.kind)
        names = list(self.names) if self.names is not None else [f"blendshape {k}" for k in range(w.shape[1])]
        rows = np.arange(w.shape[1])
        if self.top is not None:
            rows = most_active(w, self.top)
        f_fps = fps if self.fps is None else check_fps(self.fps, "FacePanel fps")
        return FacePanel(w[:, rows], [names[k] for k in rows], f_fps, self.kind, None)


def _check_face(weights: Any, names: Sequence[str] | None, kind: str) -> np.ndarray:
    """Blendshape weights as ``(T, K) float64``, or a ValueError naming the bad argument."""
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] == 0:
        raise ValueError(f"face must be (T, 51) blendshape weights, got shape {w.shape}")
    if names is not None and len(names) != w.shape[1]:
        raise ValueError(f"FacePanel names: {len(names)} names for {w.shape[1]} blendshapes")
    if kind not in FACE_PANELS:
        raise ValueError(f"FacePanel kind must be one of {FACE_PANELS}, got {kind!r}")
    return w


def _envelope(y: np.ndarray, sr: float, n_bins: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Min/max envelope of a waveform in ``n_bins`` bins: (times s, low, high)."""
    n = len(y)
    n_bins = max(1, min(n_bins, n))
    edges = np.linspace(0, n, n_bins + 1).astype(np.int64)
    lo = np.minimum.reduceat(y, edges[:-1])
    hi = np.maximum.reduceat(y, edges[:-1])
    t = (edges[:-1] + edges[1:]) / 2 / sr
    return t, lo, hi


# ----------------------------------------------------------------------------------- the steps
def _sequences(
    positions: Any, skeleton: Any, labels: Sequence[str] | None
) -> tuple[list[str] | None, list[np.ndarray], list[Bones]]:
    """Step 1: the sequences to animate, their labels and drawable bones, checked."""
    if isinstance(positions, Mapping):
        labels, seqs = (list(positions) if labels is None else labels), list(positions.values())
    else:
        seqs = list(positions) if isinstance(positions, list | tuple) else [positions]
    if labels is not None and len(labels) != len(seqs):
        raise ValueError(f"labels: {len(labels)} labels for {len(seqs)} sequences")
    seqs, bones = checked_sequences(seqs, skeleton, "positions")
    return (None if labels is None else [str(x) for x in labels]), seqs, bones


def _clock(
    n_frames: int, fps: float, out_fps: float | None, max_frames: int | None
) -> tuple[np.ndarray, np.ndarray, float]:
    """Step 2: data frame of each animation frame, its time (s) and the playback rate (frames/s)."""
    rate = None if out_fps is None else check_fps(out_fps, "out_fps")
    idx = frame_indices(n_frames, fps, rate)
    if max_frames is not None:
        idx = idx[: int(max_frames)]
    step = float(np.mean(np.diff(idx))) if len(idx) > 1 else 1.0
    play_fps = fps if rate is None or rate >= fps else fps / max(step, 1.0)
    return idx, idx / fps, play_fps


@dataclass(frozen=True)
class _Layout:
    """Step 3: the figure size and the rectangle (figure fractions) of every panel."""

    size: tuple[float, float]  # inches
    skeletons: list[tuple[float, float, float, float]]
    caption: tuple[float, float] | None  # centre (x, y)
    timeline: tuple[float, float, float, float] | None
    face: tuple[float, float, float, float] | None


def _face_heights(face: FacePanel | None) -> tuple[float, float]:
    """Inches of the face panel's axes and of its labels below (blendshape names for bars), (0, 0) without one."""
    if face is None:
        return 0.0, 0.0
    if face.kind == "heatmap":
        return max(1.0, 0.16 * face.weights.shape[1]), 0.55
    return 1.3, 1.5  # bars, names written vertically below


def _layout(
    n: int,
    width: float,
    *,
    titles: bool,
    timeline: bool,
    caption: bool,
    face: FacePanel | None,
) -> _Layout:
    """Stack from the top: skeleton row, caption band, timeline, face; side margins for names and legends."""
    below = timeline or face is not None
    sk_h = min(width / n, 3.6 if below else 5.4)  # square panels up to 3.6 in (5.4 alone), inches
    title_h, cap_h, tl_h = 0.4 * titles, 0.55 * caption, 1.55 * timeline
    face_h, face_below = _face_heights(face)
    height = title_h + sk_h + cap_h + tl_h + face_h + face_below + 0.1 * below
    left, right = min(1.6, 0.22 * width), min(1.8, 0.22 * width)
    w_frac = (width - left - right) / width

    def rect(top_in: float, h_in: float) -> tuple[float, float, float, float]:
        return (left / width, 1 - (top_in + h_in) / height, w_frac, h_in / height)

    skeletons = [(i / n, 1 - (title_h + sk_h) / height, 1 / n, sk_h / height) for i in range(n)]
    sk_h += title_h
    cap = (0.5, 1 - (sk_h + cap_h / 2) / height) if caption else None
    tl = rect(sk_h + cap_h + 0.05, 1.0) if timeline else None
    fc = rect(sk_h + cap_h + tl_h + 0.05, face_h) if face is not None else None
    return _Layout((width, height), skeletons, cap, tl, fc)


def _draw_skeletons(fig: Any, layout: _Layout, seqs: list[np.ndarray], bones: list[Bones],
                    labels: list[str] | None, view: Any) -> list[SkeletonArtist]:  # fmt: skip
    """Step 4: one 3D panel per sequence, one scale for all, titled in the system's colour."""
    half = half_extents(seqs)
    colours = system_colours(labels) if labels is not None else []
    artists = []
    for i, (rect, seq, b) in enumerate(zip(layout.skeletons, seqs, bones)):
        ax = fig.add_axes(rect, projection="3d")
        setup_axes(ax, seq, view=view, floor=b.has_feet, half=half)
        artists.append(SkeletonArtist(ax, b))
        if labels is not None:
            ax.set_title(labels[i], color=colours[i], fontsize=13, fontweight="bold")
    return artists


def _draw_timeline(fig: Any, rect: Any, tl: Timeline, end: float) -> Any:
    """Step 5: waveform envelope, audio beats, motion beats, legend outside; returns the cursor line."""
    ax = fig.add_axes(rect)
    if tl.audio is not None:
        tw, lo, hi = _envelope(tl.audio, tl.sr, 2000)
        ax.fill_between(tw, lo, hi, color="0.65", lw=0, label="audio")
    if tl.audio_beats is not None:
        ax.vlines(tl.audio_beats, -1, 1, color="#1f77b4", lw=1.0, alpha=0.8, label="audio beats")
    if tl.motion_beats is not None:
        ax.vlines(tl.motion_beats, -1, -0.4, color="#d62728", lw=2.0, label="motion beats")
    ax.set_xlim(0, end)
    ax.set_ylim(-1, 1)
    ax.set_yticks([-1, 0, 1] if tl.audio is not None else [])
    ax.set_ylabel("amplitude" if tl.audio is not None else "beats")
    ax.set_xlabel("time (s)")
    ax.grid(False)
    legend_outside(ax, "right")
    return ax.axvline(0.0, color="k", lw=1.4)


def _draw_face(fig: Any, rect: Any, face: FacePanel) -> tuple[Any, Any]:
    """Step 6: blendshapes by name, heat map (returns its cursor) or bars (returns the bars)."""
    ax = fig.add_axes(rect)
    w, k = face.weights, face.weights.shape[1]
    top = max(1.0, float(w.max()))
    ax.grid(False)
    if face.kind == "bars":
        bars = ax.bar(np.arange(k), w[0], color="#2e8b57", width=0.8)
        ax.set_ylim(0, top)
        ax.set_xlim(-0.6, k - 0.4)
        ax.set_ylabel("weight (0-1)")
        ax.set_xticks(np.arange(k), face.names, rotation=90, fontsize=9)
        return None, bars
    im = ax.imshow(w.T, aspect="auto", origin="upper", extent=(0, len(w) / face.fps, k - 0.5, -0.5),
                   vmin=0, vmax=top, cmap="magma", interpolation="nearest")  # fmt: skip
    ax.set_yticks(np.arange(k), face.names, fontsize=9)
    ax.set_xlabel("time (s)")
    x0, y0, wd, ht = rect
    bar_ax = fig.add_axes((x0 + wd + 0.01, y0, 0.012, ht))
    fig.colorbar(im, cax=bar_ax).set_label("weight (0-1)", fontsize=9)
    return ax.axvline(0.0, color="w", lw=1.4), None


def _updater(idx: np.ndarray, times: np.ndarray, seqs: list[np.ndarray], artists: list[SkeletonArtist],
             cursors: list[Any], bars: Any, face: FacePanel | None, caption: Any,
             words: Any) -> Callable[[int], list[Any]]:  # fmt: skip
    """Step 7: the function that moves every artist to animation frame k."""

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
            row = face.weights[min(int(round(t * face.fps)), len(face.weights) - 1)]
            for rect, h in zip(bars, row):
                rect.set_height(h)
            changed += list(bars)
        if caption is not None:
            caption.set_text(word_at(t, *words))
            changed.append(caption)
        return changed

    return update


def animate_skeletons(
    positions: Any,
    skeleton: SkeletonLike | Sequence[SkeletonLike],
    fps: float,
    *,
    out_fps: float | None = 15.0,
    labels: Sequence[str] | None = None,
    timeline: Timeline | None = None,
    words: Any = None,
    face: FacePanel | None = None,
    view: str | tuple[float, float] = "default",
    width: float = SLIDE_WIDTH_PX,
    dpi: float = 100,
    max_frames: int | None = None,
) -> SkeletonAnimation:
    """Animate one or several skeletons side by side, in sync, with optional timeline, face and word panels.

    Parameters
    ----------
    positions : (T, J, 3) array, or mapping label -> (T_i, J_i, 3), or sequence of arrays
        Joint positions, centimetres, Y up, all at ``fps``. Several sequences are
        shown left to right (e.g. ``{"ground truth": gt, "CaMN": a, "HA2G": b}``)
        on the same clock and the same scale; a shorter one holds its last frame.
    skeleton : Skeleton or (J,) parents array, or a sequence of them (one per sequence)
        Hierarchy of each sequence (HA2G's TED-43 parents array is recognised).
    fps : float
        Frame rate of ``positions`` (frames per second).
    out_fps : float or None
        Playback rate; frames are subsampled to it (``None``: every frame).
    labels : sequence of str, optional
        Panel titles (default: mapping keys, or none for one sequence), in the
        systems' colours (:func:`beatlite.viz.style.system_colours`).
    timeline : Timeline, optional
        Waveform, audio beats and motion beats under the skeletons, with a cursor.
    words : (starts, ends, words) or WordIntervals, optional
        Word timings in seconds; the current word is the caption under the skeletons.
    face : FacePanel, optional
        Blendshape weights by name, as a heat map with a cursor or as bars.
    view : str or (elev, azim)
        Camera of every skeleton panel.
    width : float
        Figure width in pixels (default 960, slide size).
    dpi : float
        Pixels per inch; fonts are in points, so a larger ``dpi`` at the same
        ``width`` makes the text larger.
    max_frames : int, optional
        Stop after this many animation frames.

    Returns
    -------
    SkeletonAnimation
        A ``FuncAnimation``; ends a notebook cell -> inline player; ``.save_as("x.gif")``.

    Examples
    --------
    One second at 30 fps played at 15 fps is 15 animation frames, 1/15 s apart; the shorter second panel holds
    its last frame. A frame drawn as an image is 960 px wide:

    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up
    >>> clip = np.repeat(pose[None], 30, axis=0)
    >>> clip[:, 3, 1] += 2.0 * np.arange(30)  # the right hand rises 2 cm per frame
    >>> anim = animate_skeletons({"ground truth": clip, "CaMN": clip[:20]}, parents, fps=30,
    ...                          timeline=Timeline(audio=np.zeros(16000), sr=16000, audio_beats=[0.5]))
    >>> anim.fps, len(anim.times), np.round(anim.times[:3], 4).tolist()
    (15.0, 15, [0.0, 0.0667, 0.1333])
    >>> [ax.get_title() for ax in anim.figure.axes[:2]], anim.frame_image(-1).shape[1:]
    (['ground truth', 'CaMN'], (960, 3))
    """
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fps, dpi = check_fps(fps), check_fps(dpi, "dpi")
    labels, seqs, bones = _sequences(positions, skeleton, labels)
    n_frames = max(len(p) for p in seqs)
    idx, times, play_fps = _clock(n_frames, fps, out_fps, max_frames)
    timeline = None if timeline is None else timeline.checked()
    face = None if face is None else face.checked(fps)
    word_table = None if words is None else check_words(words)
    layout = _layout(
        len(seqs),
        check_fps(width, "width") / dpi,
        titles=labels is not None,
        timeline=timeline is not None,
        caption=word_table is not None,
        face=face,
    )
    with plt.rc_context(dict(STYLE)):
        fig = Figure(figsize=layout.size, dpi=dpi)
        FigureCanvasAgg(fig)
        artists = _draw_skeletons(fig, layout, seqs, bones, labels, view)
        cursors, bars = [], None
        if timeline is not None:
            cursors.append(
                _draw_timeline(fig, layout.timeline, timeline, max(n_frames / fps, timeline.duration))
            )
        if face is not None:
            cursor, bars = _draw_face(fig, layout.face, face)
            cursors += [] if cursor is None else [cursor]
        caption = None
        if layout.caption is not None:
            caption = fig.text(*layout.caption, "", ha="center", va="center", fontsize=16, fontweight="bold")
    update = _updater(idx, times, seqs, artists, cursors, bars, face, caption, word_table)
    update(0)
    return SkeletonAnimation(fig, update, times, play_fps)
