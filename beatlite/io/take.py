"""Loading every file of one BEAT take onto a single timeline.

A take ``2_scott_0_1_1`` has up to six files beside each other:
``.bvh[.gz]`` (120 fps motion), ``.wav`` (speech), ``.json[.gz]`` (60 fps
face), ``.TextGrid[.gz]`` (words), ``.txt`` (semantic) and ``.csv``
(emotion). :func:`load_take` reads those present and resamples motion and
face to one frame rate (default 15 fps).

Resampling phase
----------------
- ``phase="start"``: output frame ``i`` is the source at ``t = i / fps``. For an
  integer ratio ``r = source_fps / fps`` this is exact decimation from frame 0
  (frames 0, r, 2r, ...); otherwise the two neighbouring source frames are
  interpolated linearly (rotation channels along the shorter way round the
  circle, so 179 -> -179 passes through 180, not 0).
- ``phase="beat"``: BEAT's preprocessing (docs/reference_code.md#downsampling): motion keeps source frames
  1, 1 + r, 1 + 2r, ... (120 -> 15 fps keeps frames 1, 9, 17, ...), i.e. output
  frame ``i`` is at ``t = i / fps + 1 / source_fps``; the face is decimated from
  frame 0 (frames 0, 4, 8, ... at 60 fps), as BEAT does.

Modalities of different lengths are truncated to the shortest, with an
:class:`~beatlite.io.errors.AlignmentWarning` (a ``UserWarning``) naming each
duration when they differ by more than one frame.

Taught in notebooks/01_beat_formats.ipynb, section 11 (one timeline: ``load_take`` at 15 fps).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from beatlite.io.audio import read_audio
from beatlite.io.bvh import read_bvh
from beatlite.io.emotion import EmotionSegment, emotion_to_frames, read_emotion
from beatlite.io.errors import AlignmentWarning, FormatError
from beatlite.io.facial import read_facial
from beatlite.io.motion import Motion
from beatlite.io.names import TakeName, parse_take_name
from beatlite.io.semantic import SemanticSegment, read_semantic, semantic_to_frames
from beatlite.io.textfile import resolve
from beatlite.io.textgrid import WordIntervals, read_words

__all__ = ["Take", "load_take", "take_stem", "resample_frames", "clip_take", "PHASES", "TAKE_EXTENSIONS"]

PHASES = ("start", "beat")
TAKE_EXTENSIONS = (".bvh", ".wav", ".json", ".TextGrid", ".txt", ".csv")


@dataclass(eq=False)
class Take:
    """All modalities of one take on one timeline of ``n_frames`` frames at ``fps``.

    Attributes
    ----------
    name : str
        The stem, e.g. ``"2_scott_0_1_1"``.
    fps : float
        Frame rate of every per-frame array.
    motion : Motion
        Channels resampled to ``fps``: ``(T, C) float64`` (cm, degrees).
    audio : (N,) float32 or None
        Speech at ``sr`` Hz, cut to ``T / fps`` seconds.
    sr : int
        Audio rate in Hz.
    face : (T, 51) float32 or None
        Blendshape weights resampled to ``fps``.
    face_names : tuple of str
        Blendshape names (empty without a face file).
    words : WordIntervals or None
        Words with times in seconds (not cut; use ``words_to_frames`` with ``n_frames``).
    semantic : (T,) float32
        Semantic score per frame (0 without a ``.txt``).
    semantic_segments : list of SemanticSegment
    emotion : (T,) int64
        Emotion class per frame (from the ``.csv``; without one, the class the
        take name implies).
    emotion_segments : list of EmotionSegment
    info : TakeName or None
        Parsed name (None for a name that is not BEAT's pattern).
    paths : dict str -> Path
        The files read, by extension.
    """

    name: str
    fps: float
    motion: Motion
    audio: np.ndarray | None
    sr: int
    face: np.ndarray | None
    face_names: tuple[str, ...]
    words: WordIntervals | None
    semantic: np.ndarray
    semantic_segments: list[SemanticSegment]
    emotion: np.ndarray
    emotion_segments: list[EmotionSegment] = field(default_factory=list)
    info: TakeName | None = None
    paths: dict[str, Path] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return self.motion.n_frames

    @property
    def duration(self) -> float:
        """``T / fps`` seconds."""
        return self.n_frames / self.fps

    def positions(self) -> np.ndarray:
        """World joint positions by forward kinematics, (T, J, 3) float64, centimetres."""
        return self.motion.positions()

    def __repr__(self) -> str:
        have = [k for k in ("audio", "face", "words") if getattr(self, k) is not None]
        return f"Take({self.name!r}, {self.n_frames} frames @ {self.fps:g} fps, with {', '.join(have) or 'motion only'})"


def take_stem(path_or_stem: str | os.PathLike[str]) -> Path:
    """``data/2_scott_0_1_1.bvh.gz`` -> ``data/2_scott_0_1_1`` (everything after the first dot dropped)."""
    p = Path(path_or_stem)
    return p.with_name(p.name.split(".")[0]) if "." in p.name else p


def _sample_times(n_source: int, source_fps: float, fps: float, shift: int) -> np.ndarray:
    """Fractional source-frame positions of the output frames that fall inside the source."""
    ratio = source_fps / fps
    if n_source <= shift:
        return np.zeros(0)
    r_int = round(ratio)
    if abs(ratio - r_int) < 1e-9 and r_int >= 1:
        return np.arange(shift, n_source, r_int, dtype=np.float64)
    n_out = int(math.floor((n_source - 1 - shift) / ratio + 1e-9)) + 1
    return shift + np.arange(n_out, dtype=np.float64) * ratio


def resample_frames(
    values: np.ndarray,
    source_fps: float,
    fps: float,
    *,
    shift: int = 0,
    angle_columns: np.ndarray | None = None,
) -> np.ndarray:
    """Resample ``(T, D)`` frames from ``source_fps`` to ``fps``.

    Output frame ``i`` is source frame position ``shift + i * source_fps / fps``.
    Integer positions copy the source frame exactly (plain decimation for an
    integer ratio); others interpolate linearly between the two neighbours.

    Parameters
    ----------
    values : (T, D) float array
        Source frames.
    source_fps, fps : float
        Rates.
    shift : int
        First source frame used (BEAT's decimation starts at 1).
    angle_columns : (K,) int, optional
        Columns holding angles in degrees, interpolated along the shorter arc.

    Returns
    -------
    (T', D) array of ``values.dtype``
        ``T'`` = number of output times inside the source span.
    """
    v = np.asarray(values)
    if v.ndim != 2:
        raise ValueError(f"resample_frames: values must be (T, D), got shape {v.shape}")
    pos = _sample_times(v.shape[0], float(source_fps), float(fps), int(shift))
    i0 = np.floor(pos + 1e-9).astype(np.int64)
    w = pos - i0
    if np.all(np.abs(w) < 1e-9):
        return v[i0].copy()
    i1 = np.minimum(i0 + 1, v.shape[0] - 1)
    a = v[i0].astype(np.float64)
    delta = v[i1].astype(np.float64) - a
    if angle_columns is not None and len(angle_columns):
        cols = np.asarray(angle_columns, dtype=np.int64)
        delta[:, cols] = (delta[:, cols] + 180.0) % 360.0 - 180.0
    return (a + w[:, None] * delta).astype(v.dtype)


def _rotation_columns(motion: Motion) -> np.ndarray:
    cols = [
        int(start) + k
        for start, chans in zip(motion.skeleton.channel_starts, motion.skeleton.channels)
        for k, c in enumerate(chans)
        if c.endswith("rotation")
    ]
    return np.array(cols, dtype=np.int64)


def _optional(stem: Path, ext: str) -> Path | None:
    try:
        return resolve(stem, ext)
    except FileNotFoundError:
        return None


def load_take(
    stem_or_path: str | os.PathLike[str],
    *,
    fps: float = 15,
    phase: str = "start",
    audio_sr: int = 16000,
    bvh_fps: float | None = None,
) -> Take:
    """Read every file of a take and align them on one timeline.

    Parameters
    ----------
    stem_or_path : str or PathLike
        ``data/2_scott_0_1_1`` or any of its files (``.../2_scott_0_1_1.bvh.gz``).
    fps : float
        Output frame rate (default 15, the models' rate).
    phase : {"start", "beat"}
        Resampling phase (see the module docstring).
    audio_sr : int
        Audio rate in Hz.
    bvh_fps : float, optional
        Override of the BVH's ``Frame Time`` (some real BEAT files are wrong, docs/reference_code.md#bvh-header).

    Returns
    -------
    Take

    Raises
    ------
    FileNotFoundError
        If there is no ``.bvh`` / ``.bvh.gz`` for the stem.
    FormatError
        From the reader of a malformed file.
    """
    if phase not in PHASES:
        raise ValueError(f"load_take: phase must be one of {PHASES}, got {phase!r}")
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"load_take: fps must be positive, got {fps!r}")
    fps = float(fps)
    stem = take_stem(stem_or_path)
    paths: dict[str, Path] = {}
    bvh_path = resolve(stem, ".bvh")
    paths[".bvh"] = bvh_path
    source = read_bvh(bvh_path, fps=bvh_fps)
    channels = resample_frames(
        source.channels,
        source.fps,
        fps,
        shift=1 if phase == "beat" else 0,
        angle_columns=_rotation_columns(source),
    )
    lengths = {"motion": channels.shape[0] / fps}
    n_frames = channels.shape[0]

    audio = None
    if (wav := _optional(stem, ".wav")) is not None:
        paths[".wav"] = wav
        audio, audio_sr = read_audio(wav, sr=audio_sr)
        lengths["audio"] = audio.shape[0] / audio_sr
        n_frames = min(n_frames, int(math.floor(audio.shape[0] * fps / audio_sr + 1e-9)))

    face = None
    face_names: tuple[str, ...] = ()
    if (face_path := _optional(stem, ".json")) is not None:
        paths[".json"] = face_path
        facial = read_facial(face_path)
        face = resample_frames(facial.weights, facial.fps, fps, shift=0)
        face_names = facial.names
        lengths["face"] = face.shape[0] / fps
        n_frames = min(n_frames, face.shape[0])

    if max(lengths.values()) - min(lengths.values()) > 1.0 / fps + 1e-9:
        detail = ", ".join(f"{k} {v:.3f} s" for k, v in lengths.items())
        warnings.warn(
            f"{stem.name}: modalities differ in length ({detail}); truncating to {n_frames / fps:.3f} s",
            AlignmentWarning,
            stacklevel=2,
        )
    motion = Motion(source.skeleton, channels[:n_frames], fps)
    if audio is not None:
        audio = audio[: int(math.floor(n_frames * audio_sr / fps + 1e-9))]
    if face is not None:
        face = face[:n_frames]

    words = None
    if (tg := _optional(stem, ".TextGrid")) is not None:
        paths[".TextGrid"] = tg
        try:
            words = read_words(tg, tier="words")
        except FormatError as exc:
            if exc.field != "words":
                raise
            words = read_words(tg, tier=0)  # no "words" tier: BEAT's loader uses tier 0

    try:
        info = parse_take_name(stem.name)
    except FormatError:
        info = None

    semantic_segments: list[SemanticSegment] = []
    if (txt := _optional(stem, ".txt")) is not None:
        paths[".txt"] = txt
        semantic_segments = read_semantic(txt)
    emotion_segments: list[EmotionSegment] = []
    default_emotion = info.emotion if info is not None else 0
    if (csv := _optional(stem, ".csv")) is not None:
        paths[".csv"] = csv
        emotion_segments = read_emotion(csv)
        default_emotion = 0

    return Take(
        name=stem.name,
        fps=fps,
        motion=motion,
        audio=audio,
        sr=int(audio_sr),
        face=face,
        face_names=face_names,
        words=words,
        semantic=semantic_to_frames(semantic_segments, n_frames, fps),
        semantic_segments=semantic_segments,
        emotion=emotion_to_frames(emotion_segments, n_frames, fps, default=default_emotion),
        emotion_segments=emotion_segments,
        info=info,
        paths=paths,
    )


def clip_take(take: Take, t0: float, t1: float) -> Take:
    """The part of ``take`` in ``[t0, t1)`` seconds, on a timeline that starts at 0.

    Frames ``a = round(t0 * fps)`` to ``b = round(t1 * fps)`` (exclusive, at most ``n_frames``) of
    every per-frame array are kept; the audio keeps samples ``round(a / fps * sr)`` to
    ``round(b / fps * sr)``. Words and semantic / emotion segments that overlap the clip are kept,
    shifted by ``-a / fps`` and cut to ``[0, (b - a) / fps]``, so they line up with the clipped
    frames (a word caption, an animation's timeline).

    Parameters
    ----------
    take : Take
    t0, t1 : float
        Seconds, ``0 <= t0 < t1``; ``t1`` past the end is cut to the end.

    Returns
    -------
    Take
        A new take (arrays are copies); ``name`` and ``info`` as the source's.

    Raises
    ------
    ValueError
        An empty or negative interval, or ``t0`` at or after the end.

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> sk = Skeleton(("Hips",), np.array([-1]), np.zeros((1, 3)), (("Xrotation",),))
    >>> take = Take("t", 15.0, Motion(sk, np.arange(30.0)[:, None], 15.0), np.zeros(32000, np.float32),
    ...             16000, None, (), WordIntervals(np.array([0.5]), np.array([1.2]), ("hi",)),
    ...             np.zeros(30, np.float32), [], np.zeros(30, np.int64))
    >>> clip = clip_take(take, 1.0, 1.6)  # frames 15 to 23, 0.6 s
    >>> clip.motion.channels[:, 0].tolist(), len(clip.audio), clip.words.ends.round(6).tolist()
    ([15.0, 16.0, 17.0, 18.0, 19.0, 20.0, 21.0, 22.0, 23.0], 9600, [0.2])
    """
    import dataclasses

    if not 0 <= t0 < t1:
        raise ValueError(f"clip_take: need 0 <= t0 < t1, got t0={t0!r}, t1={t1!r}")
    a, b = int(round(t0 * take.fps)), min(int(round(t1 * take.fps)), take.n_frames)
    if a >= b:
        raise ValueError(f"clip_take: [{t0}, {t1}) s holds no frame of the {take.duration:.2f} s take")
    start, duration = a / take.fps, (b - a) / take.fps

    def cut(s: float, e: float) -> tuple[float, float] | None:  # shifted into the clip, None if outside
        if e <= start or s >= start + duration:
            return None
        return max(s - start, 0.0), min(e - start, duration)

    words = take.words
    if words is not None:
        kept = [(cut(s, e), w) for s, e, w in zip(words.starts, words.ends, words.words, strict=True)]
        kept = [(se, w) for se, w in kept if se is not None]
        words = WordIntervals(
            np.array([se[0] for se, _ in kept]),
            np.array([se[1] for se, _ in kept]),
            tuple(w for _, w in kept),
            duration,
        )
    segments = {}
    for key in ("semantic_segments", "emotion_segments"):
        out = []
        for seg in getattr(take, key):
            se = cut(seg.start, seg.end)
            if se is not None:
                out.append(seg._replace(start=se[0], end=se[1], duration=se[1] - se[0]))
        segments[key] = out
    audio = take.audio
    if audio is not None:
        audio = audio[int(round(start * take.sr)) : int(round((start + duration) * take.sr))].copy()
    return dataclasses.replace(
        take,
        motion=Motion(take.motion.skeleton, take.motion.channels[a:b].copy(), take.motion.fps),
        audio=audio,
        face=None if take.face is None else take.face[a:b].copy(),
        words=words,
        semantic=take.semantic[a:b].copy(),
        emotion=take.emotion[a:b].copy(),
        paths=dict(take.paths),
        **segments,
    )
