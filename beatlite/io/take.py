"""Loading every file of one BEAT take onto a single timeline.

A take ``2_scott_0_1_1`` has up to six files beside each other:
``.bvh[.gz]`` (120 fps motion), ``.wav`` (speech), ``.json[.gz]`` (60 fps
face), ``.TextGrid[.gz]`` (words), ``.txt`` (semantic) and ``.csv``
(emotion). :func:`load_take` reads those present and resamples motion and
face to one frame rate (default 15 fps).

A BEAT2 take (:mod:`beatlite.io.smplx`) is ``smplxflame_30/{stem}.npz`` (30 fps SMPL-X, read as a motion on
BEAT's skeleton by :func:`beatlite.skeleton.smplx.smplx_to_beat`) with ``wave16k/{stem}.wav`` and
``textgrid/{stem}.TextGrid`` in the sibling folders (or beside it); its FLAME expressions become
:attr:`Take.expressions` (BEAT2 has no ARKit face, so ``face`` is None). :attr:`Take.format` says which.

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
  frame 0 (frames 0, 4, 8, ... at 60 fps), as BEAT does. BEAT2's expressions, rows of the motion's
  ``.npz``, keep the motion's frames.

Modalities of different lengths are truncated to the shortest, with an
:class:`~beatlite.io.errors.AlignmentWarning` (a ``UserWarning``) naming each
duration when they differ by more than one frame.

Frame rates that lie
--------------------
The rate of the BVH rows is settled before anything is cut: :func:`read_bvh`
trusts the header duration when ``Frames`` and the row count differ by a clean
integer factor, and :func:`reconcile_rate` then compares the motion with the
audio (else face, else TextGrid) duration and, when they disagree by more than
:data:`RATE_GAP_S`, picks the one clean factor of the header rate that makes
them agree. Each change is one :class:`~beatlite.io.errors.BVHWarning` naming
both readings; ``bvh_fps=`` overrides it all. The dataset index runs the same
code (:func:`read_take_motion`), so it reports the duration loading produces.

Taught in notebooks/01_beat_formats.ipynb, section 11 (one timeline: ``load_take`` at 15 fps).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from beatlite.constants import FPS, SR
from beatlite.io.audio import read_audio
from beatlite.io.bvh import parse_frame_time, read_bvh, read_bvh_header
from beatlite.io.emotion import EmotionSegment, emotion_to_frames, read_emotion
from beatlite.io.errors import AlignmentWarning, BVHWarning, FormatError
from beatlite.io.facial import ARKIT_51, Facial, read_facial
from beatlite.io.motion import Motion
from beatlite.io.names import TakeName, parse_take_name
from beatlite.io.semantic import SemanticSegment, read_semantic, semantic_to_frames
from beatlite.io.textfile import resolve
from beatlite.io.textgrid import WordIntervals, read_words

__all__ = [
    "Take",
    "load_take",
    "take_stem",
    "take_files",
    "read_take_motion",
    "read_take_words",
    "reconcile_rate",
    "reference_duration",
    "resample_frames",
    "rotation_columns",
    "clip_take",
    "PHASES",
    "TAKE_EXTENSIONS",
    "BEAT2_FOLDERS",
    "RATE_GAP_S",
]

PHASES = ("start", "beat")
TAKE_EXTENSIONS = (".bvh", ".wav", ".json", ".TextGrid", ".txt", ".csv")
#: Where a BEAT2 take's other files live, relative to its ``smplxflame_30/`` folder (docs/data.md#beat2).
BEAT2_FOLDERS = {".wav": "wave16k", ".TextGrid": "textgrid"}
#: Seconds by which motion may differ from the other modalities before its frame rate is questioned
#: (the dataset index's ``MAX_DURATION_GAP``).
RATE_GAP_S = 1.0
#: Degrees from which a float64 angle holds no fraction of a degree (2**52): :func:`resample_frames` reduces
#: such angles modulo 360 before interpolating them.
ANGLE_EXACT = 2.0**52


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
        The files read, by extension (``".bvh"`` or, for BEAT2, ``".npz"``).
    expressions : (T, E) float32 or None
        BEAT2's FLAME expression coefficients resampled to ``fps`` (None for BEAT).

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> take = load_take(repo_root() / "data_samples" / "2_scott_0_1_1")
    >>> take.name, take.fps, take.n_frames, take.motion.channels.shape, take.face.shape
    ('2_scott_0_1_1', 15.0, 222, (222, 228), (222, 51))
    >>> take.audio.shape == (take.n_frames * take.sr // 15,)  # cut to the motion: 222 / 15 s at 16 kHz
    True
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
    expressions: np.ndarray | None = None

    @property
    def format(self) -> str:
        """``"beat2"`` for a take read from BEAT2's SMPL-X ``.npz``, else ``"beat"`` (BVH)."""
        return "beat2" if ".npz" in self.paths else "beat"

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
    """``data/2_scott_0_1_1.bvh.gz`` -> ``data/2_scott_0_1_1`` (:func:`beatlite.io.names.split_take_file`: the
    BEAT extension dropped; other dots are part of the stem, as the index reads it).

    Examples
    --------
    >>> take_stem("data/2_scott_0_1_1.bvh.gz").as_posix()
    'data/2_scott_0_1_1'
    >>> take_stem("data/2_scott_0_1_1.v2.bvh").as_posix()
    'data/2_scott_0_1_1.v2'
    """
    from beatlite.io.names import split_take_file

    p = Path(path_or_stem)
    return p.with_name(split_take_file(p)[0])


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
        Columns holding angles in degrees, interpolated along the shorter arc. A pair of angles at or
        beyond :data:`ANGLE_EXACT` degrees is reduced modulo 360 first (such a float holds no fraction of
        a degree, and the pair's difference may exceed float64); other pairs of finite values too far apart
        for ``b - a`` interpolate as ``(1 - w) a + w b``. Finite frames give finite frames.

    Returns
    -------
    (T', D) array of ``values.dtype``
        ``T'`` = number of output times inside the source span.

    Examples
    --------
    >>> values = np.arange(8.0)[:, None]  # (T, 1) at 120 fps
    >>> resample_frames(values, 120, 30)[:, 0]  # every 4th frame
    array([0., 4.])
    >>> resample_frames(values, 120, 30, shift=1)[:, 0]  # BEAT's phase: from frame 1
    array([1., 5.])
    >>> resample_frames(np.array([[170.0], [-170.0]]), 10, 20, angle_columns=np.array([0]))[:, 0]  # the short arc
    array([ 170.,  180., -170.])
    >>> resample_frames(np.array([[1e308], [-1e308]]), 10, 20)[:, 0]  # b - a is beyond float64; (a + b) / 2 is not
    array([ 1.e+308,  0.e+000, -1.e+308])
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
    a, b = v[i0].astype(np.float64), v[i1].astype(np.float64)
    cols = np.asarray([] if angle_columns is None else angle_columns, dtype=np.int64)
    vast = np.zeros(a.shape, bool)
    vast[:, cols] = np.maximum(np.abs(a[:, cols]), np.abs(b[:, cols])) >= ANGLE_EXACT
    a[vast], b[vast] = a[vast] % 360.0, b[vast] % 360.0
    with np.errstate(over="ignore", invalid="ignore"):  # |b - a| beyond float64: the convex form below
        delta = b - a
        delta[:, cols] = (delta[:, cols] + 180.0) % 360.0 - 180.0
        out = a + w[:, None] * delta
        far = ~np.isfinite(delta) & np.isfinite(a) & np.isfinite(b)
    out[far] = (a * (1.0 - w[:, None]) + b * w[:, None])[far]
    return out.astype(v.dtype)


def rotation_columns(motion: Motion) -> np.ndarray:
    """(K,) int64: the columns of ``motion.channels`` that hold rotations (degrees), for :func:`resample_frames`.

    Examples
    --------
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> columns = rotation_columns(Motion(beat_skeleton(), np.zeros((1, 228)), fps=15))
    >>> columns.shape, columns[:3].tolist()  # all but the three root position channels
    ((225,), [3, 4, 5])
    """
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


def take_files(stem_or_path: str | os.PathLike[str]) -> tuple[Path, dict[str, Path]]:
    """The stem of a take and its files by extension (:data:`TAKE_EXTENSIONS`, plain or ``.gz``).

    The motion is the ``.bvh`` / ``.bvh.gz``, else (BEAT2) the ``.npz``; a BEAT2 take's audio and TextGrid are
    looked for beside it, then in :data:`BEAT2_FOLDERS` next to its folder.

    Raises
    ------
    FileNotFoundError
        If there is neither a ``.bvh`` / ``.bvh.gz`` nor an ``.npz`` for the stem.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> stem, files = take_files(repo_root() / "data_samples" / "2_scott_0_1_1.wav")
    >>> stem.name, list(files), files[".bvh"].name
    ('2_scott_0_1_1', ['.bvh', '.wav', '.json', '.TextGrid', '.txt', '.csv'], '2_scott_0_1_1.bvh.gz')
    """
    stem = take_stem(stem_or_path)
    npz = stem.with_name(stem.name + ".npz")
    if str(stem_or_path).endswith(".npz") or (npz.is_file() and _optional(stem, ".bvh") is None):
        if not npz.is_file():
            raise FileNotFoundError(f"no file {npz}")
        paths = {".npz": npz}
        for ext in TAKE_EXTENSIONS[1:]:
            found = _optional(stem, ext)
            if found is None and ext in BEAT2_FOLDERS:
                found = _optional(stem.parent.parent / BEAT2_FOLDERS[ext] / stem.name, ext)
            if found is not None:
                paths[ext] = found
        return stem, paths
    paths = {".bvh": resolve(stem, ".bvh")}
    for ext in TAKE_EXTENSIONS[1:]:
        if (found := _optional(stem, ext)) is not None:
            paths[ext] = found
    return stem, paths


def read_take_words(path: str | os.PathLike[str]) -> WordIntervals:
    """The words of a take's TextGrid: tier ``"words"`` (MFA), else tier 0 as BEAT's loader does.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> words = read_take_words(repo_root() / "data_samples" / "2_scott_0_1_1.TextGrid")
    >>> words.words[:3], float(words.starts[0]) < float(words.ends[0])
    (('my', 'idea', 'is'), True)
    """
    try:
        return read_words(path, tier="words")
    except FormatError as exc:
        if exc.field != "words":
            raise
        return read_words(path, tier=0)


def reference_duration(durations: dict[str, float], half: str | None = None) -> float | None:
    """The duration the motion should match: the audio's, else the face's, else the TextGrid's.

    The TextGrid of an ``_a``/``_b`` half spans the whole sequence (docs/reference_code.md#textgrid), so it is not used then.

    Examples
    --------
    >>> reference_duration({"audio": 14.8, "face": 14.7, "text": 15.0})  # the audio's
    14.8
    >>> reference_duration({"text": 62.0}, half="a") is None  # a half's TextGrid spans both halves
    True
    """
    for modality in ("audio", "face", "text"):
        if modality in durations and not (modality == "text" and half):
            return float(durations[modality])
    return None


def reconcile_rate(n_rows: int, fps: float, header_fps: float, reference_s: float | None) -> float | None:
    """A clean-factor motion rate that matches the other modalities, when ``fps`` does not.

    When ``n_rows / fps`` is more than :data:`RATE_GAP_S` seconds from ``reference_s``, the
    rates ``header_fps``, ``header_fps * k`` and ``header_fps / k`` (``k = 2..16``) are tried;
    the one rate whose duration ``n_rows / r`` lies within ``max(0.15 s, 1 %)`` of
    ``reference_s`` is returned. ``None`` keeps ``fps`` (no reference, close enough, no fit,
    or an ambiguous fit).

    Examples
    --------
    >>> reconcile_rate(240, 24.0, 24.0, 2.0)  # 120 fps rows under 'Frame Time: 0.041667' (docs/reference_code.md#bvh-header)
    120.0
    >>> reconcile_rate(957, 15.0, 120.0, 64.0) is None  # already agrees
    True
    """
    if reference_s is None or reference_s <= 0 or n_rows < 2:
        return None
    if abs(n_rows / fps - reference_s) <= RATE_GAP_S:
        return None
    rates = {header_fps} | {header_fps * k for k in range(2, 17)} | {header_fps / k for k in range(2, 17)}
    tolerance = max(0.15, 0.01 * reference_s)
    fits = [r for r in rates if r >= 1.0 and r != fps and abs(n_rows / r - reference_s) <= tolerance]
    return fits[0] if len(fits) == 1 else None


def read_take_motion(
    path: str | os.PathLike[str], *, bvh_fps: float | None = None, reference_s: float | None = None
) -> Motion:
    """Read a take's BVH at the frame rate that agrees with the take's other files.

    Parameters
    ----------
    path : str or PathLike
        The ``.bvh`` / ``.bvh.gz``, or a BEAT2 ``.npz`` (retargeted to BEAT's skeleton at the file's rate).
    bvh_fps : float, optional
        The rate of the rows, an override: nothing is inferred.
    reference_s : float, optional
        Duration of the other modalities (:func:`reference_duration`). Without an override,
        :func:`read_bvh` settles the rate from the header (:func:`~beatlite.io.bvh.infer_row_rate`),
        then :func:`reconcile_rate` may change it to a clean factor of the header rate that
        matches ``reference_s``, with one :class:`BVHWarning` naming both readings and the override.

    Returns
    -------
    Motion

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.bvh"
    >>> from beatlite.io.bvh import write_bvh
    >>> write_bvh(path, Motion(beat_skeleton(), np.zeros((240, 228)), fps=24))  # a wrong Frame Time
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     motion = read_take_motion(path, reference_s=2.0)  # the audio lasts 2 s: the rows are 120 fps
    >>> motion.fps, motion.n_frames, [w.category.__name__ for w in caught]
    (120.0, 240, ['BVHWarning'])
    >>> tmp.cleanup()
    """
    p = Path(path)
    if p.name.endswith(".npz"):  # BEAT2: the file states its rate; bvh_fps still overrides it
        return _beat2_motion(p, bvh_fps)[0]
    if bvh_fps is not None:
        return read_bvh(p, fps=bvh_fps)
    motion = read_bvh(p)
    _, _, frame_time = read_bvh_header(p)
    header_fps = parse_frame_time(repr(frame_time))
    rate = reconcile_rate(motion.n_frames, motion.fps, header_fps, reference_s)
    if rate is None:
        return motion
    warnings.warn(
        f"{p}: {motion.n_frames} rows at {motion.fps:g} fps last {motion.duration:.2f} s but the take's "
        f"other files last {reference_s:.2f} s; reading the rows at {rate:g} fps ({motion.n_frames / rate:.2f} s), "
        f"a clean factor of the header's {header_fps:g} fps. Pass bvh_fps= to load_take/index_folder to choose",
        BVHWarning,
        stacklevel=2,
    )
    return Motion(motion.skeleton, motion.channels, rate)


def _beat2_motion(path: Path, bvh_fps: float | None) -> tuple[Motion, np.ndarray | None]:
    """A BEAT2 ``.npz`` as a motion on BEAT's skeleton at its rate (``bvh_fps`` overrides it), and its FLAME
    expressions (None without) at the same rate."""
    from beatlite.io.smplx import read_smplx

    smplx = read_smplx(path)
    beat = smplx.to_beat()
    rate = smplx.fps if bvh_fps is None else float(bvh_fps)
    return Motion(beat.skeleton, beat.channels, rate), smplx.expressions  # type: ignore[attr-defined]


def _check_load_args(fps: float, phase: str) -> float:
    if phase not in PHASES:
        raise ValueError(f"load_take: phase must be one of {PHASES}, got {phase!r}")
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"load_take: fps must be positive, got {fps!r}")
    return float(fps)


def _align(
    name: str, source: Motion, audio: np.ndarray | None, sr: int, face: Facial | None, fps: float, phase: str
) -> tuple[Motion, np.ndarray | None, np.ndarray | None]:
    """Motion and face resampled to ``fps`` and every modality cut to the shortest (with a warning)."""
    shift = 1 if phase == "beat" else 0
    channels = resample_frames(
        source.channels, source.fps, fps, shift=shift, angle_columns=rotation_columns(source)
    )
    lengths = {"motion": channels.shape[0] / fps}
    n_frames = channels.shape[0]
    if audio is not None:
        lengths["audio"] = audio.shape[0] / sr
        n_frames = min(n_frames, int(math.floor(audio.shape[0] * fps / sr + 1e-9)))
    face_frames = None
    if face is not None:
        face_frames = resample_frames(face.weights, face.fps, fps, shift=0)
        lengths["face"] = face_frames.shape[0] / fps
        n_frames = min(n_frames, face_frames.shape[0])
    if max(lengths.values()) - min(lengths.values()) > 1.0 / fps + 1e-9:
        detail = ", ".join(f"{k} {v:.3f} s" for k, v in lengths.items())
        hint = ""
        if any(abs(v - lengths["motion"]) > RATE_GAP_S for v in lengths.values()):
            hint = f" (motion read at {source.fps:g} fps: if that rate is wrong, pass bvh_fps=)"
        warnings.warn(
            f"{name}: modalities differ in length ({detail}); truncating to {n_frames / fps:.3f} s{hint}",
            AlignmentWarning,
            stacklevel=3,
        )
    if audio is not None:
        audio = audio[: int(math.floor(n_frames * sr / fps + 1e-9))]
    return (
        Motion(source.skeleton, channels[:n_frames], fps),
        audio,
        None if face_frames is None else face_frames[:n_frames],
    )


def _annotations(
    paths: dict[str, Path], info: TakeName | None, n_frames: int, fps: float
) -> dict[str, object]:
    """Semantic and emotion segments and their per-frame arrays (emotion from the name without a ``.csv``)."""
    semantic_segments = read_semantic(paths[".txt"]) if ".txt" in paths else []
    emotion_segments = read_emotion(paths[".csv"]) if ".csv" in paths else []
    default_emotion = info.emotion if info is not None and ".csv" not in paths else 0
    return {
        "semantic": semantic_to_frames(semantic_segments, n_frames, fps),
        "semantic_segments": semantic_segments,
        "emotion": emotion_to_frames(emotion_segments, n_frames, fps, default=default_emotion),
        "emotion_segments": emotion_segments,
    }


def load_take(
    stem_or_path: str | os.PathLike[str],
    *,
    fps: float = FPS,
    phase: str = "start",
    audio_sr: int = SR,
    bvh_fps: float | None = None,
    blendshapes: Sequence[str] | None = ARKIT_51,
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
        Rate of the BVH rows, an override of everything the files say. By default the
        rate is reconciled with the audio (else face, else TextGrid) duration
        (:func:`read_take_motion`), warning when it differs from the header's.
    blendshapes : sequence of str or None
        Canonical face columns, picked by name (default :data:`ARKIT_51`; a missing name
        is a :class:`FormatError`, extra names such as ``tongueOut`` are dropped with a
        warning). ``None`` keeps the file's columns.

    Returns
    -------
    Take

    Raises
    ------
    FileNotFoundError
        If there is no ``.bvh`` / ``.bvh.gz`` for the stem.
    FormatError
        From the reader of a malformed file.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> take = load_take(repo_root() / "data_samples" / "2_scott_0_1_1", fps=15)
    >>> take.n_frames, take.semantic.shape, take.emotion.shape, take.info.split
    (222, (222,), (222,), 'test')
    """
    fps = _check_load_args(fps, phase)
    stem, paths = take_files(stem_or_path)
    durations: dict[str, float] = {}
    audio = facial = words = None
    if ".wav" in paths:
        audio, audio_sr = read_audio(paths[".wav"], sr=audio_sr)
        durations["audio"] = audio.shape[0] / audio_sr
    if ".json" in paths:
        facial = read_facial(paths[".json"], names=blendshapes)
        durations["face"] = facial.n_frames / facial.fps
    if ".TextGrid" in paths:
        words = read_take_words(paths[".TextGrid"])
        durations["text"] = float(words.xmax or 0.0)
    try:
        info: TakeName | None = parse_take_name(stem.name)
    except FormatError:
        info = None
    reference = reference_duration(durations, info.half if info is not None else None)
    expressions = None
    if ".npz" in paths:
        source, flame = _beat2_motion(paths[".npz"], bvh_fps)
        if flame is not None:
            shift = 1 if phase == "beat" else 0  # the motion's frames: they are rows of the same file
            expressions = resample_frames(flame, source.fps, fps, shift=shift).astype(np.float32)
    else:
        source = read_take_motion(paths[".bvh"], bvh_fps=bvh_fps, reference_s=reference)
    motion, audio, face = _align(stem.name, source, audio, int(audio_sr), facial, fps, phase)
    return Take(
        name=stem.name,
        fps=fps,
        motion=motion,
        audio=audio,
        sr=int(audio_sr),
        face=face,
        face_names=() if facial is None else facial.names,
        words=words,
        info=info,
        paths=paths,
        expressions=None if expressions is None else expressions[: motion.n_frames],
        **_annotations(paths, info, motion.n_frames, fps),  # type: ignore[arg-type]
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
