"""Score any model's outputs: ``python -m beatlite.score PRED --data DATA``.

``PRED`` is a folder of generated takes named like the ground-truth takes of the scored split, one file per
take (matched by stem, everything before the first dot, in any case; ``res_{stem}``, as BEAT's and EMAGE's test
code name their results, too):

=====================  ===================================================================================
``{stem}.bvh[.gz]``    BEAT's skeleton (joint names), any frame rate (resampled to 15 fps by
                       :func:`beatlite.io.take.resample_frames`, rotations along the shorter arc), any Euler
                       channel order (converted through rotation matrices), or a subset of BEAT's joints that
                       holds the 47 joints of ``spine_neck_141`` (the others at rest). Only the rotations
                       are read (and the root position): they are applied to beatlite's BEAT skeleton, as the
                       in-library evaluation of Euler models does. Joints above Hips (a ``Reference`` root)
                       are not BEAT's: their rotation is folded into Hips' (the body turns as in the file).
``{stem}.npz``         BEAT2's SMPL-X parameters (:func:`beatlite.io.smplx.read_smplx`: ``poses``, ``trans``,
                       ``mocap_frame_rate``), retargeted to BEAT's skeleton
                       (:func:`beatlite.skeleton.smplx.smplx_to_beat`, the approximate rest skeleton) and
                       then read as a BVH is. Scored against a BEAT2 folder (``--data`` holding
                       ``smplxflame_30/``, ``wave16k/``, ``textgrid/``, ``train_test_split.csv``), whose
                       takes are retargeted the same way, or against BEAT.
``{stem}.npy``         ``(T, 42, 3)`` TED-43 unit bone directions (HA2G's vector order,
                       :data:`beatlite.skeleton.ted.TED_BONES`), ``(T, 126)`` the same flattened, or
                       ``(T, 141)`` ``spine_neck_141`` Euler degrees (CaMN's output, BEAT's channel order).
                       Read with ``allow_pickle=False``, at 15 fps unless ``--pred-fps`` gives the rows' rate
                       (then resampled as a BVH's rows are; directions interpolated and normalised).
=====================  ===================================================================================

``--protocol clips`` scores HA2G's evaluation protocol instead of whole takes: one 34-frame prediction
``{stem}@{start}.*`` (same formats) per window of every take, ``start`` = 0, 10, 20, ... (frames at 15 fps),
each generated from that clip's first 4 ground-truth frames (:func:`load_split`,
:func:`beatlite.train.testset.clip_test_set`); ``--export`` then writes a checkpoint's clips.

Every prediction becomes the :class:`~beatlite.metrics.scoring.Takes` of one row exactly as
:func:`beatlite.train.evaluation.evaluate_models` builds a model's row (TED-43 directions, positions of the
common space, extractor features of the 34-frame windows, the 141 Euler channels where the file has them),
and is scored against the split's ground truth by :func:`beatlite.metrics.scoring.evaluate`.

The Euler metrics read each predicted track on the ground truth's representation (of a rotation's equivalent
Euler angles, the other branch of the middle angle and 360° turns: at the first frame those nearest the ground
truth's, :func:`beatlite.skeleton.rotations.nearest_euler`, then continuous over time), so angles written from
rotation matrices score as the same motion; the warning and ``info["euler_rewritten"]`` count the rotations so
rewritten (0 for the shipped checkpoints' exports on ``data_samples/``).

Checks, each one line on stderr: a missing take is an error (``--allow-missing`` scores the takes that are
there); an extra file is listed and ignored (hidden files such as macOS' ``._*`` are skipped; suffixes match in
any case); a prediction longer than its take is cut to it, one shorter is
scored against the take cut to the same length (one warning each saying by how many frames), and one shorter
than a window (34 frames) is an error. One :data:`RATE_FACTOR` (1.5) times longer or shorter than its take is an
error naming the rate at which its rows would span the take: its rows are at another rate than the file says
(BEAT's code writes its 15 fps results under the 120 fps ``Frame Time: 0.008333`` of its template);
``--pred-fps`` (``pred_fps=``) gives the rate of every file's rows, trusted. A file that
cannot be converted (another skeleton, NaN, another shape) is a :class:`~beatlite.io.FormatError` naming the
file and the field. Errors end the command with exit code 2 and no traceback.

``--bootstrap N`` adds 95 % percentile intervals over takes (:func:`bootstrap_intervals`); ``--self-check``
scores the split's own motion written as BVH files (:func:`self_check`); ``--export CHECKPOINT`` writes a
shipped checkpoint's generations into ``PRED`` (:func:`export_checkpoint_takes`), ready to be scored.

Taught in ``notebooks/09_scoring.ipynb`` (export, score, variants, bootstrap intervals); ``README.md`` ("Score
your model") shows the command.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import math
import sys
import tempfile
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH

__all__ = [
    "EXPORT_PRECISION",
    "MIN_FRAMES",
    "RATE_FACTOR",
    "Prediction",
    "ScoreInputError",
    "ScoreResult",
    "ScoreWarning",
    "beat_channels",
    "bootstrap_intervals",
    "export_checkpoint_takes",
    "load_split",
    "main",
    "match_predictions",
    "mean_interval",
    "read_prediction",
    "score_folder",
    "self_check",
    "trim_test_set",
]

MIN_FRAMES = WINDOW_LENGTH
"""A prediction needs at least one FGD window (34 frames at 15 fps)."""

RATE_FACTOR = 1.5
"""A prediction this many times longer or shorter than its take is refused, not trimmed: its rows are at another
rate than the file says (BEAT's code writes 15 fps rows under a 120 fps ``Frame Time``); ``pred_fps`` gives it."""

EXPORT_PRECISION = 12
"""Decimals of the BVH files :func:`export_checkpoint_takes` writes (5e-13 degrees: the scores equal the in-library ones to rtol 1e-6)."""

_SUFFIXES = (".bvh", ".bvh.gz", ".npy", ".npz")
_PREFIX = (
    "res_"  # BEAT's and EMAGE's test code name a take's result res_{take} (and its ground truth gt_{take})
)


class ScoreInputError(ValueError):
    """The prediction folder cannot be scored; ``lines`` holds one line per problem (whitespace collapsed, so each
    prints as one line on stderr).

    Examples
    --------
    >>> error = ScoreInputError(["pred: no prediction for   1 of the 8 takes", "x.npy: NaN"])
    >>> error.lines
    ['pred: no prediction for 1 of the 8 takes', 'x.npy: NaN']
    >>> isinstance(error, ValueError)
    True
    """

    def __init__(self, lines: Sequence[str]) -> None:
        self.lines = [" ".join(str(line).split()) for line in lines]
        super().__init__("\n".join(self.lines))


class ScoreWarning(UserWarning):
    """A prediction was scored after a change (trimmed, converted, normalised) or a file was ignored."""


@dataclasses.dataclass(eq=False)
class Prediction:
    """One take's prediction in the forms the metrics read.

    Attributes
    ----------
    directions : (T, 42, 3) float64
        TED-43 unit bone directions.
    euler : (T, 141) float64 or None
        ``spine_neck_141`` Euler degrees (None for direction files).
    form : str
        What the file was, e.g. ``"bvh 30 fps -> 15 fps"`` or ``"npy directions (T, 42, 3)"``.
    rows : int or None
        Frames of the file before resampling (None: ``n_frames``).
    fps : float
        The rate those rows were read at (the file's ``Frame Time`` or ``mocap_frame_rate``, 15 for a ``.npy``, or
        ``fps`` of :func:`read_prediction`).

    Examples
    --------
    Made by :func:`read_prediction`; ``n_frames`` counts its 15 fps frames, ``rows`` the file's.

    >>> up = np.tile([0.0, 1.0, 0.0], (4, 42, 1))  # 4 frames of 42 bones pointing up
    >>> p = Prediction(up, None, "npy directions (42, 3)")
    >>> p.n_frames, p.rows, p.fps
    (4, None, 15.0)
    """

    directions: np.ndarray
    euler: np.ndarray | None
    form: str
    rows: int | None = None
    fps: float = float(FPS)

    @property
    def n_frames(self) -> int:
        return int(self.directions.shape[0])


# ------------------------------------------------------------------------------------ reading one file
def beat_channels(motion: Any, path: str | Path) -> np.ndarray:
    """Rows of beatlite's BEAT skeleton from a BVH motion of BEAT's joints, at the motion's own rate.

    Parameters
    ----------
    motion : Motion
        Read by :func:`beatlite.io.read_bvh`: BEAT's joint names, any Euler order per joint, possibly only a
        subset of BEAT's joints (which must hold all 47 of ``spine_neck_141``).
    path : str or Path
        Named in errors.

    Returns
    -------
    (T, 228) float64
        :func:`beatlite.skeleton.beat.beat_skeleton` channel rows (degrees, ``Xrotation Yrotation
        Zrotation``; root position in cm; joints the file lacks at 0 = rest). A joint in another Euler order
        is converted through its rotation matrices; of the two equivalent angle triples the one continuous
        with the previous frame is kept from the first frame's ``|Y| <= 90°`` on
        (:func:`beatlite.synth.motion.continuous_euler`), so the Euler-space metrics see continuous tracks;
        a file whose first frame lies on the other branch gives other (equivalent) Euler values.

    Raises
    ------
    FormatError
        Another skeleton (joints of ``spine_neck_141`` missing, a joint under another parent) or a joint
        without three rotation channels (field ``HIERARCHY`` / ``CHANNELS``).

    Examples
    --------
    A BVH of beatlite's own skeleton gives its channels unchanged; one of another skeleton is refused.

    >>> from beatlite.io.motion import Motion
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> channels = np.random.default_rng(0).uniform(-90, 90, (5, 228))
    >>> bool(np.array_equal(beat_channels(Motion(beat_skeleton(), channels, 15.0), "x.bvh"), channels))
    True
    >>> from beatlite.skeleton.core import Skeleton
    >>> arm = Skeleton(("Shoulder", "Elbow"), [-1, 0], [[0, 0, 0], [30, 0, 0]], (("Zrotation", "Xrotation", "Yrotation"),) * 2)
    >>> beat_channels(Motion(arm, np.zeros((5, 6)), 15.0), "arm.bvh")
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: arm.bvh, field 'HIERARCHY': not BEAT's skeleton: 47 of the 47 spine_neck_141 joints are missing (Spine, Neck, Neck1, ...); the file has 2 joints (Shoulder, Elbow, ...)
    """
    from beatlite.io import FormatError
    from beatlite.skeleton.beat import JOINT_SUBSETS, beat_skeleton
    from beatlite.skeleton.rotations import euler_to_matrix, matrix_to_euler
    from beatlite.synth.motion import continuous_euler

    beat, src = beat_skeleton(), motion.skeleton
    if src.same_topology(beat):
        return np.array(motion.channels, dtype=np.float64)
    names = set(src.names)
    lacking = [n for n in JOINT_SUBSETS["spine_neck_141"] if n not in names]
    if lacking:
        raise FormatError(
            path,
            f"not BEAT's skeleton: {len(lacking)} of the 47 spine_neck_141 joints are missing "
            f"({', '.join(lacking[:3])}, ...); the file has {src.n_joints} joints ({', '.join(src.names[:3])}, ...)",
            field="HIERARCHY",
        )
    _check_parents(src, beat, path)
    above = _above_beat(src, beat, motion)
    out = np.zeros((motion.n_frames, beat.n_channels))
    for j, name in enumerate(beat.names):
        if name not in names:
            continue
        k = src.index(name)
        order, want = src.rotation_order(k), beat.rotation_order(j)
        if len(order) != 3:
            raise FormatError(
                path, f"joint {name} has {len(order)} rotation channels, not 3", field="CHANNELS"
            )
        angles = motion.channels[:, src.rotation_channel_indices(k)]
        if k in above:  # under joints BEAT lacks that turn it: their rotation becomes part of this joint's
            angles = continuous_euler(matrix_to_euler(above[k][0] @ euler_to_matrix(angles, order), want))
        elif order != want:  # the branch of the middle angle kept continuous over time (BEAT's tracks are)
            angles = continuous_euler(matrix_to_euler(euler_to_matrix(angles, order), want))
        out[:, beat.rotation_channel_indices(j)] = angles
    hips = src.index("Hips") if "Hips" in names else -1
    if hips in above:
        out[:, beat.position_channel_indices(0)] = above[hips][1]
    elif hips >= 0 and len(src.position_channel_indices(hips)):
        out[:, beat.position_channel_indices(0)] = motion.channels[:, src.position_channel_indices(hips)]
    extra = [n for n in src.names if n not in set(beat.names)]
    if extra:
        turned = [src.names[k] for k in above]
        warnings.warn(
            f"{path}: {len(extra)} joints that BEAT lacks ignored ({', '.join(extra[:3])})"
            + (f"; the rotation of those above {', '.join(turned)} is folded into it" if turned else ""),
            ScoreWarning,
            stacklevel=2,
        )
    return out


def _above_beat(src: Any, beat: Any, motion: Any) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """``{k: (world rotations (T, 3, 3) of its parent, its world positions (T, 3))}`` for each BEAT joint ``k``
    of ``src`` that hangs under joints BEAT lacks (a root above Hips) whose rotation is not the identity."""
    from beatlite.skeleton.kinematics import global_transforms

    tops = [k for k in range(src.n_joints)
            if src.names[k] in beat.names and src.parents[k] >= 0 and src.names[src.parents[k]] not in beat.names]  # fmt: skip
    if not tops:
        return {}
    rotations, positions = global_transforms(src, motion.channels)
    return {
        k: (rotations[:, src.parents[k]], positions[:, k])
        for k in tops
        if np.abs(rotations[:, src.parents[k]] - np.eye(3)).max() > 1e-12
    }


def _check_parents(src: Any, beat: Any, path: str | Path) -> None:
    """Each BEAT joint of ``src`` must hang under its nearest BEAT ancestor that ``src`` has."""
    from beatlite.io import FormatError

    have = set(src.names)
    for j, name in enumerate(beat.names):
        if name not in have:
            continue
        p = int(beat.parents[j])
        while p >= 0 and beat.names[p] not in have:
            p = int(beat.parents[p])
        want = beat.names[p] if p >= 0 else None
        k = src.index(name)
        got = src.names[int(src.parents[k])] if src.parents[k] >= 0 else None
        if got != want and not (want is None and got not in beat.names):  # a root above BEAT's is allowed
            raise FormatError(
                path,
                f"not BEAT's skeleton: joint {name} hangs under {got}, in BEAT under {want}",
                field="HIERARCHY",
            )


def _bvh_prediction(path: Path, fps: float | None = None) -> Prediction:
    """A BVH file -> directions and Euler channels at 15 fps (see :func:`beat_channels`); ``fps`` is the rows'
    rate instead of the file's ``Frame Time``."""
    from beatlite.io import read_bvh

    motion = read_bvh(path, fps=fps)
    return _channels_prediction(beat_channels(motion, path), motion.fps, "bvh", path)


def _smplx_prediction(path: Path, fps: float | None = None) -> Prediction:
    """A BEAT2 ``.npz`` -> BEAT's skeleton (:func:`beatlite.skeleton.smplx.smplx_to_beat`) -> as a BVH; ``fps``
    is the rows' rate instead of the file's ``mocap_frame_rate``."""
    from beatlite.io.smplx import read_smplx

    motion = read_smplx(path)
    if fps is not None:
        motion = dataclasses.replace(motion, fps=float(fps))
    return _channels_prediction(motion.to_beat().channels, motion.fps, "npz smplx -> BEAT skeleton,", path)  # type: ignore[attr-defined]


def _channels_prediction(channels: np.ndarray, fps: float, form: str, path: Path) -> Prediction:
    """BEAT-skeleton rows at ``fps`` -> directions and Euler channels at 15 fps."""
    from beatlite.io import FormatError
    from beatlite.io.motion import Motion
    from beatlite.io.take import resample_frames, rotation_columns
    from beatlite.skeleton.beat import beat_skeleton, subset_columns
    from beatlite.skeleton.ted import channels_to_directions

    form, rows = f"{form} {fps:g} fps", len(channels)
    motion = Motion(beat_skeleton(), channels[:1], fps)
    if fps != FPS:
        cols = rotation_columns(motion)
        channels = resample_frames(channels, fps, FPS, angle_columns=cols)
        form += f" -> {FPS:g} fps"
    euler = channels[:, subset_columns(beat_skeleton(), "spine_neck_141")]
    try:  # zero-length bones when positions (a root at 1e30 cm) are too large to tell a bone's ends apart
        directions = channels_to_directions(channels)
    except ValueError as exc:
        raise FormatError(
            path,
            f"{str(exc).split(';')[0]} on BEAT's skeleton: values too large to give directions",
            field="values",
        ) from None
    return Prediction(directions, euler, form, rows=rows, fps=float(fps))


def _npy_prediction(path: Path, fps: float | None = None) -> Prediction:
    """A ``.npy`` of (T, 42, 3) / (T, 126) directions or (T, 141) Euler degrees, its rows at ``fps`` (default 15):
    resampled to 15 fps as a BVH's channels are (Euler angles along the shorter arc, directions interpolated and
    normalised, :func:`_resample_directions`)."""
    from beatlite.io import FormatError
    from beatlite.io.take import resample_frames
    from beatlite.skeleton.ted import euler_to_directions

    rate = FPS if fps is None else float(fps)
    x = _load_npy(path)
    if not isinstance(x, np.ndarray) or x.dtype.kind not in "iuf":
        raise FormatError(
            path, f"dtype {getattr(x, 'dtype', type(x).__name__)} is not a real number type", field="dtype"
        )
    x = np.asarray(x, np.float64)
    if x.ndim and not len(x):
        raise FormatError(path, f"no frames: shape {x.shape}", field="shape")
    at = "" if rate == FPS else f" {rate:g} fps -> {FPS:g} fps"
    if x.ndim == 2 and x.shape[1] == 141:
        _check_finite(x, path)
        rows, form = len(x), "npy euler (T, 141)" + at
        if at:
            x = resample_frames(x, rate, FPS, angle_columns=np.arange(141))
        return Prediction(euler_to_directions(x), x, form, rows=rows, fps=rate)
    if (x.ndim == 3 and x.shape[1:] == (42, 3)) or (x.ndim == 2 and x.shape[1] == 126):
        _check_finite(x, path)
        d = _unit_directions(x.reshape(len(x), 42, 3), path)
        form = f"npy directions {x.shape[1:]}" + at
        return Prediction(_resample_directions(d, rate, path) if at else d, None, form, rows=len(x), fps=rate)
    raise FormatError(
        path, f"shape {x.shape} is none of (T, 42, 3) or (T, 126) TED-43 directions, (T, 141) Euler degrees",
        field="shape",
    )  # fmt: skip


def _resample_directions(d: np.ndarray, fps: float, path: Path) -> np.ndarray:
    """(T, 42, 3) unit directions at ``fps`` -> at 15 fps: each bone's vector interpolated linearly between the
    two nearest rows (:func:`beatlite.io.take.resample_frames`; rows at integer positions copied) and normalised.
    Halfway between two rows where a bone turns by 180° it has no direction: a :class:`~beatlite.io.FormatError`.
    """
    from beatlite.io import FormatError
    from beatlite.io.take import resample_frames

    out = resample_frames(d.reshape(len(d), -1), fps, FPS).reshape(-1, 42, 3)
    norms = np.linalg.norm(out, axis=-1, keepdims=True)
    if len(out) and norms.min() < 1e-6:
        frame, bone = (int(i) for i in np.argwhere(norms[..., 0] < 1e-6)[0])
        row = int(np.floor(frame * fps / FPS + 1e-9))
        raise FormatError(
            path,
            f"bone {bone} turns by 180 degrees between rows {row} and {row + 1}: no direction halfway, where a "
            f"{FPS:g} fps frame falls",
            field="values",
        )
    return out / norms


def _rate_error(fps: float) -> str | None:
    """Why ``fps`` cannot be the rate of a prediction's rows, or None: the rates a BVH's ``Frame Time`` may give
    (:data:`beatlite.io.bvh.FRAME_RATE_RANGE`), so that resampling to 15 fps stays bounded (1e-300 fps would ask
    for 1e301 frames)."""
    from beatlite.io.bvh import FRAME_RATE_RANGE

    low, high = FRAME_RATE_RANGE
    try:
        rate = float(fps)
    except (TypeError, ValueError):
        rate = math.nan
    if math.isfinite(rate) and low <= rate <= high:
        return None
    return f"the rows' frame rate must be a number from {low:g} to {high:g} fps"


def _load_npy(path: Path) -> np.ndarray:
    """``np.load`` of a ``.npy`` file whose header is checked first: its magic, and a shape whose bytes the file
    holds (a header may claim any size: read as is, it would allocate it)."""
    from beatlite.io import FormatError
    from beatlite.io.textfile import describe_bytes, npy_header

    with open(path, "rb") as fh:
        head = fh.read(64)
        fh.seek(0)
        if not head.startswith(b"\x93NUMPY"):
            raise FormatError(path, f"not a .npy array: {describe_bytes(head)}")
        npy_header(fh, path.stat().st_size, path)
    try:
        return np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise FormatError(path, f"not a readable .npy array ({' '.join(str(exc).split())})") from None


def _check_finite(x: np.ndarray, path: Path) -> None:
    from beatlite.io import FormatError

    bad = np.argwhere(~np.isfinite(x))
    if len(bad):
        raise FormatError(
            path,
            f"value {x[tuple(bad[0])]} at index {tuple(int(i) for i in bad[0])} is not finite",
            field="values",
        )


def _unit_directions(d: np.ndarray, path: Path) -> np.ndarray:
    """``d`` divided by its norms; zero vectors are an error, norms off 1 by more than 1e-3 a warning."""
    from beatlite.io import FormatError

    with np.errstate(over="ignore"):  # too long to normalise: refused below
        norms = np.linalg.norm(d, axis=-1, keepdims=True)
    if not np.isfinite(norms).all():
        frame, bone = (int(i) for i in np.argwhere(~np.isfinite(norms[..., 0]))[0])
        raise FormatError(
            path, f"bone {bone} of frame {frame} has a direction too long to normalise", field="values"
        )
    if norms.min() < 1e-6:
        frame, bone = (int(i) for i in np.argwhere(norms[..., 0] < 1e-6)[0])
        raise FormatError(path, f"bone {bone} of frame {frame} has a zero direction vector", field="values")
    if np.abs(norms - 1).max() > 1e-3:
        warnings.warn(
            f"{path.name}: directions are not unit vectors (norms {norms.min():.3g}..{norms.max():.3g}): normalised",
            ScoreWarning,
            stacklevel=2,
        )
    return d / norms


def read_prediction(path: str | Path, *, fps: float | None = None) -> Prediction:
    """One prediction file (``.bvh``, ``.bvh.gz``, ``.npy`` or BEAT2's ``.npz``, see the module docstring) at 15 fps.

    Parameters
    ----------
    path : str or Path
    fps : float, optional
        The rate of the rows instead of the file's own: a ``.bvh``'s ``Frame Time``, an ``.npz``'s
        ``mocap_frame_rate`` (e.g. 15 for BEAT's code's results, written under a 120 fps header), a ``.npy``'s
        15 fps (it states none; e.g. 30 for a model trained on BEAT2's 30 fps).

    Raises
    ------
    FormatError
        Naming the file and the field when it cannot be converted.
    ValueError
        When ``fps`` is outside the frame rates a BVH's ``Frame Time`` may give
        (:data:`beatlite.io.bvh.FRAME_RATE_RANGE`: 1 to 100,000 fps).

    Returns
    -------
    Prediction
        At 15 fps: ``(T, 42, 3)`` unit directions, and the ``(T, 141)`` Euler degrees of a BVH, ``.npz`` or
        Euler ``.npy``.

    Examples
    --------
    Two seconds of a model that writes 30 fps rows of flattened directions: read at 30 fps, the 60 rows are 30
    frames at 15 fps (every other row, an integer ratio).

    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> rows = np.tile([0.0, 1.0, 0.0], (60, 42))  # (60, 126): 42 bones pointing up
    >>> np.save(f"{tmp.name}/2_scott_0_1_1.npy", rows)
    >>> p = read_prediction(f"{tmp.name}/2_scott_0_1_1.npy", fps=30)
    >>> p.directions.shape, p.rows, p.form
    ((30, 42, 3), 60, 'npy directions (126,) 30 fps -> 15 fps')
    >>> np.save(f"{tmp.name}/bad.npy", np.zeros((60, 43, 3)))
    >>> read_prediction(f"{tmp.name}/bad.npy")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: .../bad.npy, field 'shape': shape (60, 43, 3) is none of (T, 42, 3) or ...
    >>> tmp.cleanup()
    """
    from beatlite.io import FormatError

    if fps is not None and (why := _rate_error(fps)):
        raise ValueError(f"read_prediction: fps {fps}: {why}")
    p = Path(path)
    name = p.name.lower()
    if name.endswith((".bvh", ".bvh.gz")):
        return _bvh_prediction(p, fps)
    if name.endswith(".npy"):
        return _npy_prediction(p, fps)
    if name.endswith(".npz"):
        return _smplx_prediction(p, fps)
    raise FormatError(p, f"not a prediction file (expected one of {', '.join(_SUFFIXES)})")


# ------------------------------------------------------------------------------------ the folder
def match_predictions(pred: str | Path, takes: Sequence[str]) -> tuple[dict[str, Path], list[str], list[str]]:
    """Prediction files of ``pred`` by take stem.

    Returns
    -------
    (files, missing, extra)
        ``{stem: path}`` for the takes of ``takes`` that have a file, the takes without one, and the names of
        the other files (ignored): predictions whose stem is no take of the split and files of no prediction
        suffix. Names match in any case (``2_Scott_0_1_1.BVH``), and ``res_{stem}`` (as BEAT's and EMAGE's test
        code name their results; their ``gt_{stem}`` files are extra). Hidden files (``.DS_Store``, macOS'
        ``._*``) are skipped.

    Raises
    ------
    ScoreInputError
        ``pred`` is not a folder, or two files predict the same take.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> for name in ("2_Scott_0_1_1.BVH", "res_2_scott_0_73_73.npy", "gt_2_scott_0_73_73.npy", ".DS_Store"):
    ...     (Path(tmp.name) / name).touch()
    >>> files, missing, extra = match_predictions(tmp.name, ["2_scott_0_1_1", "2_scott_0_73_73", "6_carla_0_87_87"])
    >>> {take: path.name for take, path in files.items()}
    {'2_scott_0_1_1': '2_Scott_0_1_1.BVH', '2_scott_0_73_73': 'res_2_scott_0_73_73.npy'}
    >>> missing, extra
    (['6_carla_0_87_87'], ['gt_2_scott_0_73_73.npy'])
    >>> tmp.cleanup()
    """
    folder = Path(pred)
    if not folder.is_dir():
        raise ScoreInputError([f"{folder}: not a folder of predictions"])
    wanted = {t.lower(): t for t in takes}
    by_take: dict[str, list[Path]] = {}
    extra = []
    for p in sorted(folder.iterdir()):
        if not p.is_file() or p.name.startswith("."):
            continue
        take = _take_of(p.name.split(".")[0], wanted) if p.name.lower().endswith(_SUFFIXES) else None
        if take is None:
            extra.append(p.name)
        else:
            by_take.setdefault(take, []).append(p)
    twice = [
        f"{t}: several predictions ({', '.join(p.name for p in ps)})"
        for t, ps in by_take.items()
        if len(ps) > 1
    ]
    if twice:
        raise ScoreInputError(twice)
    files = {t: by_take[t][0] for t in takes if t in by_take}
    return files, [t for t in takes if t not in by_take], sorted(extra)


def _take_of(stem: str, wanted: dict[str, str]) -> str | None:
    """The take (of ``{lowercase name: name}``) that a file stem predicts: its name in any case, or with BEAT's and
    EMAGE's ``res_`` prefix (their test code writes ``res_{take}.bvh`` / ``res_{take}.npz``)."""
    key = stem.lower()
    if key not in wanted and key.startswith(_PREFIX):
        key = key[len(_PREFIX) :]
    return wanted.get(key)


def trim_test_set(test: Any, frames: Sequence[int]) -> Any:
    """``test`` with take ``k`` cut to its first ``frames[k]`` frames (0 drops the take).

    Every per-take array is cut (directions, Euler, semantic, streams; audio to
    :func:`beatlite.data.windows.audio_samples`); the audio onsets of a cut take are detected again on its
    cut audio. The train-split statistics (normalisers, MAAC) stay. For scoring, not for generation.
    """
    from beatlite.data.windows import audio_samples, mel_frames
    from beatlite.metrics.beats import audio_beats

    keep = [k for k, n in enumerate(frames) if n > 0]
    beats = test.beats()
    out: dict[str, list[Any]] = {key: [] for key in ("takes", "streams", "gt_directions", "gt_directions_141",
                                                    "gt_euler", "semantic", "audio", "audio_beats")}  # fmt: skip
    for k in keep:
        n, total = int(frames[k]), len(test.gt_directions[k])
        n_audio = audio_samples(n, FPS, SR)
        stream = {
            key: (v[:n] if isinstance(v, np.ndarray) and len(v) == total else v)
            for key, v in test.streams[k].items()
        }
        stream["audio"], stream["mel"] = stream["audio"][:n_audio], stream["mel"][: mel_frames(n_audio)]
        out["takes"].append(test.takes[k])
        out["streams"].append(stream)
        for key in ("gt_directions", "gt_directions_141", "gt_euler", "semantic"):
            out[key].append(getattr(test, key)[k][:n])
        out["audio"].append(test.audio[k][:n_audio])
        out["audio_beats"].append(beats[k] if n == total else audio_beats(out["audio"][-1], SR))
    return dataclasses.replace(test, **out)


# ------------------------------------------------------------------------------------ scoring
@dataclasses.dataclass
class ScoreResult:
    """The scores of one prediction folder.

    Attributes
    ----------
    evaluation : Evaluation
        The prediction's scores (:func:`beatlite.metrics.scoring.evaluate`).
    truth : Evaluation
        The ground truth's own value of each metric (scored against itself).
    intervals : dict of str -> (float, float)
        95 % bootstrap intervals per metric key (empty without ``bootstrap``).
    info : dict
        Data folder and fingerprints, takes, frames, extractor and its sha256, beatlite's version,
        the files and what was done to them (JSON-friendly). The paths, ``pred``, ``data`` and ``extractor``, are
        as :func:`beatlite.paths.shareable` writes them (relative to the repository or as given, else the
        folder's or file's name), so a report names no folder of the machine that wrote it; the sha256 values
        and fingerprints identify the data and the extractor.
    """

    evaluation: Any
    truth: Any
    intervals: dict[str, tuple[float, float]]
    info: dict[str, Any]

    def to_markdown(self) -> str:
        """The table (metric, value, 95 % interval, ground truth's value) and its caption."""
        from beatlite.metrics.scoring import ARROWS, describe
        from beatlite.report import markdown_table

        own = self.truth.values()
        rows = []
        for r in self.evaluation.results:
            lo, hi = self.intervals.get(r.key, (math.nan, math.nan))
            ci = f"[{lo:.4g}, {hi:.4g}]" if r.key in self.intervals else ""
            arrow = ARROWS[r.higher_is_better]
            rows.append([r.key + arrow, f"{r.value:.4g}", ci, f"{own.get(r.key, math.nan):.4g}"])
        text = markdown_table(["metric", "value", "95 % interval", "ground truth"], rows)
        keys = [r.key for r in self.evaluation.results]
        return text + "\n\n" + describe(keys, sources=True) + "\n\n" + self._caption()

    def _caption(self) -> str:
        i = self.info
        lines = [
            f"Predictions `{i['pred']}` ({len(i['files'])} takes) vs the `{i['split']}` split of `{i['data']}` "
            f"({len(i['takes'])} takes, {i['frames']} frames at {i['fps']:g} fps; ground truth sha256 "
            f"{i['truth_sha256']}, train-split fingerprint {i['data_fingerprint'] or 'unknown'}).",
            f"FGD extractor `{i['extractor']}` (sha256 {i['extractor_sha256']})"
            + (
                f", Euler autoencoder sha256 {i['euler_extractor_sha256']}"
                if i.get("euler_extractor_sha256")
                else ""
            )
            + (
                f", 6D autoencoder sha256 {i['rot6d_extractor_sha256']}"
                if i.get("rot6d_extractor_sha256")
                else ""
            )
            + f"; beatlite {i['beatlite_version']}.",
        ]
        if i.get("bootstrap"):
            lines.append(
                f"Intervals: 95 % percentiles of {i['bootstrap']} resamples of the takes with replacement "
                f"(seed {i['seed']}), every metric recomputed on the drawn takes."
            )
        if i.get("missing"):
            lines.append(f"Missing takes (not scored): {', '.join(i['missing'])}.")
        if i.get("pred_fps"):
            lines.append(
                f"The predictions' rows read at {i['pred_fps']:g} fps (--pred-fps), not at the files' own rates."
            )
        if i.get("trimmed"):
            lines.append(
                "Trimmed: " + ", ".join(f"{s} ({d:+d} frames)" for s, d in i["trimmed"].items()) + "."
            )
        gap = (i.get("self_check") or {}).get("largest_gap")
        if gap:
            lines.append(f"Self-check: FGD as in the table; the largest gap of any other metric to the ground truth's "
                         f"own value is {gap[1]:.2g} ({gap[0]}; relative, absolute for values below 1).")  # fmt: skip
        lines += [f"Skipped {key}: {why}." for key, why in self.evaluation.skipped.items()]
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: ``{"metrics": {key: {value, ground_truth, interval, variant, describe, ...}}, "skipped",
        "info"}`` (non-finite numbers as None)."""
        from beatlite.metrics.scoring import METRICS

        own = self.truth.values()
        metrics = {
            r.key: {
                "name": r.name,
                "variant": r.variant,
                "value": _finite(r.value),
                "ground_truth": _finite(own.get(r.key, math.nan)),
                "interval": [_finite(v) for v in self.intervals[r.key]] if r.key in self.intervals else None,
                "higher_is_better": r.higher_is_better,
                "describe": r.describe,
                "source": METRICS[r.key].source,
            }
            for r in self.evaluation.results
        }
        return {"metrics": metrics, "skipped": dict(self.evaluation.skipped), "info": self.info}


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _file_sha(path: str | Path) -> str:
    """First 16 hex digits of the sha256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def _truth_sha(test: Any) -> str:
    """First 16 hex digits of a sha256 over the scored takes' names and ground-truth arrays."""
    h = hashlib.sha256()
    for k, stem in enumerate(test.takes):
        h.update(stem.encode())
        for a in (test.gt_directions[k], test.gt_euler[k], test.semantic[k], test.audio[k]):
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


#: Values of ``protocol``: whole takes, or HA2G's evaluator (every 34-frame clip, stride 10, a take of its own).
PROTOCOLS = ("takes", "clips")


def load_split(data: str | Path | None = None, split: str = "test", *, protocol: str = "takes") -> Any:
    """The ground truth a folder of predictions is scored against.

    Parameters
    ----------
    data : str or Path, optional
        BEAT-format data folder (default :func:`beatlite.paths.data_dir`).
    split : str
        Which takes (``"test"``).
    protocol : {"takes", "clips"}
        ``"takes"``: whole takes, one prediction ``{stem}.*`` each. ``"clips"``: HA2G's evaluator, every 34-frame
        window (stride 10) of every take on its own (:func:`beatlite.train.testset.clip_test_set`), one prediction
        ``{stem}@{start}.*`` each (34 frames, generated from that clip's first 4 ground-truth frames).

    Returns
    -------
    EvaluationSet
        With ``folder``, the resolved data folder.
    """
    from beatlite.data.index import index_folder
    from beatlite.paths import data_dir
    from beatlite.train.testset import clip_test_set, load_test_set

    if protocol not in PROTOCOLS:
        raise ValueError(f"protocol must be one of {PROTOCOLS}, got {protocol!r}")
    folder = Path(data_dir() if data is None else data)
    if not folder.is_dir():
        raise ScoreInputError([f"{folder}: no such data folder"])
    index = index_folder(folder)
    usable = sorted({r.split for r in index if r.usable and r.split})
    if split not in usable:
        raise ScoreInputError(
            [
                f"{folder}: no usable takes in the {split!r} split (splits with usable takes: {', '.join(usable) or 'none'})"
            ]
        )
    test = load_test_set(index, split=split)
    if protocol == "clips":
        test = clip_test_set(test)
    return test


def score_folder(
    pred: str | Path,
    data: str | Path | None = None,
    *,
    split: str = "test",
    metrics: Sequence[str] | None = None,
    bootstrap: int = 0,
    seed: int = 0,
    extractor: str | Path | None = None,
    allow_missing: bool = False,
    pred_fps: float | None = None,
    test: Any = None,
    progress: bool = False,
) -> ScoreResult:
    """Score a folder of generated takes against the ground truth of ``split`` (see the module docstring).

    Parameters
    ----------
    pred : str or Path
        Folder of ``{stem}.bvh`` / ``{stem}.npy`` predictions.
    data : str or Path, optional
        BEAT-format data folder (default :func:`beatlite.paths.data_dir`).
    split : str
        Which takes are the ground truth (``"test"``).
    metrics : sequence of str, optional
        Keys of :data:`beatlite.metrics.scoring.METRICS` (default all; those whose inputs are missing, e.g.
        Euler metrics for direction files, are skipped with the reason).
    bootstrap : int
        Resamples of :func:`bootstrap_intervals` (0: no intervals).
    seed : int
        Seed of the Diversity pairing and of the bootstrap draws.
    extractor : str or Path, optional
        FGD extractor checkpoint of the ``dirvec`` space (default the shipped ``checkpoints/fgd_dirvec.pt``).
    allow_missing : bool
        Score the takes that have a prediction when some have none (default: an error).
    pred_fps : float, optional
        The rate of every file's rows instead of the file's own (a ``.npy``'s: 15 fps; :func:`read_prediction`),
        trusted: a prediction :data:`RATE_FACTOR` times longer or shorter than its take is then scored on the
        overlap, not refused.
    test : EvaluationSet, optional
        The loaded split (instead of ``data`` and ``split``; :attr:`~beatlite.train.testset.EvaluationSet.folder`
        names the data folder).
    progress : bool
        tqdm progress bars on stderr.

    Returns
    -------
    ScoreResult

    Raises
    ------
    ScoreInputError
        One line per problem: missing takes, unreadable or unconvertible files, too short predictions.

    Examples
    --------
    The repository's samples scored against themselves: the 8 test takes' ground-truth directions saved as
    ``.npy`` files are a perfect prediction (FGD 0 up to rounding, every keypoint correct, no position error).

    >>> import tempfile
    >>> from beatlite.paths import repo_root
    >>> test = load_split(repo_root() / "data_samples")  # the test split's ground truth, loaded once
    >>> len(test.takes), test.gt_directions[0].shape  # frames at 15 fps, TED-43's 42 bones
    (8, (222, 42, 3))
    >>> tmp = tempfile.TemporaryDirectory()
    >>> for stem, truth in zip(test.takes, test.gt_directions):
    ...     np.save(f"{tmp.name}/{stem}.npy", truth)
    >>> scores = score_folder(tmp.name, test=test, metrics=["FGD", "PCK", "MPJPE"]).evaluation.values()
    >>> bool(abs(scores["FGD"]) < 1e-9), scores["PCK"], bool(scores["MPJPE"] < 1e-9)
    (True, 1.0, True)

    Every take held still in its first frame is no longer perfect:

    >>> for stem, truth in zip(test.takes, test.gt_directions):
    ...     np.save(f"{tmp.name}/{stem}.npy", np.repeat(truth[:1], len(truth), axis=0))
    >>> still = score_folder(tmp.name, test=test, metrics=["FGD", "PCK"]).evaluation.values()
    >>> bool(still["FGD"] > 1.0), bool(still["PCK"] < 1.0)
    (True, True)
    >>> tmp.cleanup()
    """
    from beatlite.paths import shareable

    if pred_fps is not None and (why := _rate_error(pred_fps)):
        raise ScoreInputError([f"pred_fps {pred_fps}: {why}"])
    test = load_split(data, split) if test is None else test
    files, missing, extra = match_predictions(pred, test.takes)
    problems = []
    if extra:
        warnings.warn(
            f"{pred}: {len(extra)} files are no prediction of a take of the split, ignored: {', '.join(extra)}",
            ScoreWarning,
            stacklevel=2,
        )
    if missing:
        message = (
            f"{pred}: no prediction for {len(missing)} of the {len(test.takes)} takes: {', '.join(missing)}"
        )
        near = [name for name in extra if any(t.lower() in name.lower() for t in missing)]
        if near:
            message += (
                f" (files named after them, not {{take}}.* or res_{{take}}.* with a suffix of {', '.join(_SUFFIXES)}:"
                f" {', '.join(near)})"
            )
        if not allow_missing:
            problems.append(message + " (--allow-missing scores the others)")
        else:
            warnings.warn(message + ": scored without them", ScoreWarning, stacklevel=2)
    if not files and allow_missing:
        problems.append(f"{pred}: no prediction for any of the {len(test.takes)} takes")
    preds = _read_all(files, problems, progress, pred_fps)
    frames, trimmed = _frames(test, files, preds, problems, rate_given=pred_fps is not None)
    if problems:
        raise ScoreInputError(problems)
    if frames != [len(d) for d in test.gt_directions]:
        test = trim_test_set(test, frames)
    chosen = [preds[stem] for stem in test.takes]
    euler, moved = None, 0
    if all(p.euler is not None for p in chosen):
        euler = [p.euler[: len(d)] for p, d in zip(chosen, test.gt_directions, strict=True)]
        euler, moved = _truth_euler_branch(euler, test.gt_euler)
        if moved:
            n = sum(e.size // 3 for e in euler)
            warnings.warn(
                f"{pred}: {moved} of {n} joint rotations (frames x joints) are read as equivalent Euler angles "
                "(the other branch of the middle angle, or 360° turns) on the ground truth's representation: "
                "from its first frame's, continuous over time",
                ScoreWarning,
                stacklevel=2,
            )
    elif any(p.euler is not None for p in chosen):
        warnings.warn(
            "some predictions are directions: the Euler metrics are skipped for all",
            ScoreWarning,
            stacklevel=2,
        )
    directions = [p.directions[: len(d)] for p, d in zip(chosen, test.gt_directions, strict=True)]
    info = {
        "pred": shareable(pred),
        "files": {stem: f"{files[stem].name}: {preds[stem].form}" for stem in test.takes},
        "missing": missing,
        "extra": extra,
        "trimmed": trimmed,
        "euler_rewritten": moved,
        "pred_fps": pred_fps,
    }
    return _score(directions, euler, test, metrics, bootstrap, seed, extractor, progress, info)


def _truth_euler_branch(
    euler: Sequence[np.ndarray], truth: Sequence[np.ndarray]
) -> tuple[list[np.ndarray], int]:
    """Predicted Euler channels written as the equivalent angles nearest the ground truth's.

    One rotation has many Euler triples (:func:`beatlite.skeleton.rotations.nearest_euler`): a model that
    writes its rotations from matrices gets ``|Y| <= 90°`` in ``(-180, 180]`` where BEAT's tracks are
    continuous and unwrapped, and the Euler metrics (FGD of the Euler autoencoder, the reference SRGR and
    L1div) would score that representation, not the motion. Per take and joint, the first frame's triple becomes
    its equivalent nearest the ground truth's first frame, and each later one the equivalent continuing the
    track (:func:`beatlite.synth.motion.continuous_euler`): the prediction's motion, on the ground truth's
    representation (not pulled towards the ground truth frame by frame, which would add 360° jumps to a
    motion that is not the ground truth's). A continuous prediction within 180° of the ground truth's first
    frame is unchanged.

    Parameters
    ----------
    euler, truth : sequences of (T_k, 141) float, degrees
        Per take, ``spine_neck_141`` channels (47 joints, ``Xrotation Yrotation Zrotation``) of the prediction
        and of the ground truth, same lengths.

    Returns
    -------
    (list of (T_k, 141) float64, int)
        The channels, and how many triples (frames x joints) changed by more than 1e-6 degrees.

    Examples
    --------
    >>> truth = np.zeros((2, 141)); truth[:, 0] = 370.0
    >>> pred = truth.copy(); pred[:, 0] = 10.0
    >>> out, moved = _truth_euler_branch([pred], [truth])
    >>> out[0][:, 0], moved
    (array([370., 370.]), 2)
    """
    from beatlite.skeleton.rotations import nearest_euler
    from beatlite.synth.motion import continuous_euler

    out, moved = [], 0
    for e, g in zip(euler, truth, strict=True):
        e = np.asarray(e, dtype=np.float64)
        triples = e.reshape(len(e), -1, 3)
        near = np.empty_like(triples)
        near[0] = nearest_euler(triples[0], np.asarray(g, dtype=np.float64).reshape(triples.shape)[0])
        for j in range(triples.shape[1]):  # from there the prediction's own track, kept continuous
            near[:, j] = continuous_euler(np.vstack([near[:1, j], triples[1:, j]]))
        moved += int((np.abs(near - triples).max(axis=-1) > 1e-6).sum())
        out.append(near.reshape(e.shape))
    return out, moved


def _read_all(
    files: dict[str, Path], problems: list[str], progress: bool, fps: float | None = None
) -> dict[str, Prediction]:
    """Read every file (``fps``: :func:`read_prediction`'s); each one that cannot be converted adds its error line
    to ``problems``."""
    from tqdm import tqdm

    from beatlite.io import FormatError

    preds = {}
    for stem, path in tqdm(
        files.items(), desc="reading", unit="take", file=sys.stderr, disable=None if progress else True
    ):
        try:
            preds[stem] = read_prediction(path, fps=fps)
        except FormatError as exc:
            problems.append(str(exc))
    return preds


def _frames(
    test: Any,
    files: dict[str, Path],
    preds: dict[str, Prediction],
    problems: list[str],
    rate_given: bool = False,
) -> tuple[list[int], dict[str, int]]:
    """Frames scored per take (0: no prediction) and ``{stem: prediction frames - take frames}`` where they differ;
    a prediction :data:`RATE_FACTOR` times off its take's length (unless ``rate_given``; a file of fewer rows than a
    window is too short at any rate) or shorter than a window adds its line to ``problems``."""
    frames, trimmed = [], {}
    for stem, truth in zip(test.takes, test.gt_directions, strict=True):
        have = len(truth)
        n = preds[stem].n_frames if stem in preds else 0
        rows = (preds[stem].rows or n) if stem in preds else 0
        if rows >= MIN_FRAMES and not rate_given and max(n, have) >= RATE_FACTOR * min(n, have):
            problems.append(_rate_problem(files[stem], preds[stem], rows, have))
        elif stem in preds and n < MIN_FRAMES:
            problems.append(
                f"{files[stem]}: {n} frames at {FPS:g} fps, fewer than one {MIN_FRAMES}-frame window"
            )
        elif n and n != have:
            trimmed[stem] = n - have
            what = (f"its last {n - have} frames dropped" if n > have
                    else f"scored against the take's first {n} frames (the take has {have - n} more)")  # fmt: skip
            warnings.warn(
                f"{files[stem].name}: {n} frames at {FPS:g} fps, the take {have}: {what}",
                ScoreWarning,
                stacklevel=2,
            )
        frames.append(min(n, have))
    return frames, trimmed


def _rate_problem(path: Path, pred: Prediction, rows: int, have: int) -> str:
    """The error line of a prediction of ``rows`` rows :data:`RATE_FACTOR` times off its take's ``have`` frames: the
    rate its rows would need."""
    from beatlite.io import FormatError

    field = {".npz": "mocap_frame_rate", ".npy": "shape"}.get(path.suffix.lower(), "Frame Time")
    why = {
        "shape": "(a .npy states no rate: read at 15 fps)",
        "mocap_frame_rate": "(the file's mocap_frame_rate is not its rows' rate)",
    }.get(field, "(BEAT's code writes 15 fps rows under a 120 fps Frame Time)")
    message = (
        f"{rows} rows at {pred.fps:g} fps last {rows / pred.fps:.2f} s, the take {have / FPS:.2f} s; at "
        f"{rows * FPS / have:.4g} fps they would span it: if that is their rate {why}, give it with --pred-fps"
    )
    return str(FormatError(path, message, field=field))


def _score(
    directions: list[np.ndarray],
    euler: list[np.ndarray] | None,
    test: Any,
    metrics: Sequence[str] | None,
    bootstrap: int,
    seed: int,
    extractor_path: str | Path | None,
    progress: bool,
    info: dict[str, Any],
) -> ScoreResult:
    """Build the row's Takes as :func:`~beatlite.train.evaluation.evaluate_models` does and score it."""
    import torch

    import beatlite
    from beatlite.metrics.extractor import load_extractor
    from beatlite.metrics.scoring import METRICS, evaluate
    from beatlite.paths import n_threads, shareable
    from beatlite.train.testset import directions_takes

    keys = list(METRICS) if metrics is None else list(metrics)
    unknown = [k for k in keys if k not in METRICS]
    if unknown:
        raise ScoreInputError([f"unknown metric {k!r}; known: {', '.join(METRICS)}" for k in unknown])
    torch.set_num_threads(n_threads())
    extractor = _extractor(extractor_path)
    euler_ae = load_extractor("pose") if "FGD (BEAT AE)" in keys else None
    rot6d_ae = load_extractor("rot6d") if "FGD (rot6d)" in keys else None
    truth = test.ground_truth(extractor, euler_ae, rot6d_ae)
    generated = directions_takes(
        directions, test, extractor, euler=euler, euler_extractor=euler_ae, rot6d_extractor=rot6d_ae
    )
    evaluation = evaluate(generated, truth, metrics=keys, seed=seed)
    own = evaluate(truth.takes, truth, metrics=keys, seed=seed)
    scored = [r.key for r in evaluation.results]
    intervals = bootstrap_intervals(generated, truth, scored, n=bootstrap, seed=seed, progress=progress)
    info = {
        **info,
        "data": shareable(test.folder) if test.folder else "",
        "split": test.split,
        "takes": list(test.takes),
        "frames": int(sum(len(d) for d in test.gt_directions)),
        "fps": FPS,
        "truth_sha256": _truth_sha(test),
        "data_fingerprint": test.fingerprint,
        "extractor": shareable(extractor.meta["path"]),
        "extractor_sha256": _file_sha(extractor.meta["path"]),
        "euler_extractor_sha256": None if euler_ae is None else _file_sha(euler_ae.meta["path"]),
        "rot6d_extractor_sha256": None if rot6d_ae is None else _file_sha(rot6d_ae.meta["path"]),
        "beatlite_version": beatlite.__version__,
        "bootstrap": int(bootstrap),
        "seed": int(seed),
    }
    return ScoreResult(evaluation, own, intervals, info)


def _extractor(path: str | Path | None) -> Any:
    """The FGD extractor of the ``dirvec`` space: the shipped one, or the checkpoint at ``path``."""
    from beatlite.metrics.extractor import load_extractor

    if path is None:
        return load_extractor("dirvec")
    try:
        extractor = load_extractor("dirvec", path)
    except FileNotFoundError:
        raise ScoreInputError([f"{path}: no such FGD extractor checkpoint"]) from None
    except ValueError as exc:  # a FormatError names the file and the field
        raise ScoreInputError([str(exc)]) from None
    except Exception as exc:  # torch.load(weights_only=True) raises several types on a foreign file
        raise ScoreInputError(
            [f"{path}: not a beatlite FGD extractor checkpoint ({type(exc).__name__})"]
        ) from None
    if extractor.space != "dirvec":
        raise ScoreInputError(
            [f"{path}: an extractor of the {extractor.space!r} space; FGD here needs 'dirvec' (126-d)"]
        )
    return extractor


# ------------------------------------------------------------------------------------ intervals
def bootstrap_intervals(
    generated: Any,
    truth: Any,
    metrics: Sequence[str],
    *,
    n: int,
    seed: int = 0,
    level: float = 0.95,
    progress: bool = False,
) -> dict[str, tuple[float, float]]:
    """Percentile intervals of every metric over takes drawn with replacement.

    Each of the ``n`` resamples draws K of the K takes with replacement (``numpy.random.default_rng(seed)``)
    and recomputes every metric with :func:`beatlite.metrics.scoring.evaluate` on the drawn takes, generated
    and ground truth paired (a take drawn twice counts twice):

    - FGD (all variants): Fréchet distance between the features of the drawn takes' generated windows and of
      the same takes' ground-truth windows (the features are computed once; a take's windows are its rows);
    - Diversity: 500 random pairs (seed ``seed``) of the drawn takes' windows;
    - SRGR, PCK, MPJPE: over the drawn takes' frames; BeatAlign and BC: over the drawn takes' audio beats
      (onsets detected once), or per drawn 34-frame clip for ``"BC (ha2g)"``; L1div: over the drawn takes;
    - the train-split MAAC of BC is not resampled (it belongs to the training data).

    Parameters
    ----------
    generated : Takes
    truth : GroundTruth
    metrics : sequence of str
        Keys of :data:`beatlite.metrics.scoring.METRICS` (those ``evaluate`` can score on these inputs).
    n : int
        Resamples (0: no intervals).
    seed : int
    level : float
        Coverage of the central interval (0.95: the 2.5th and 97.5th percentiles).
    progress : bool
        tqdm progress bar on stderr.

    Returns
    -------
    dict of str -> (low, high)
        Over the resamples that give the metric a value: one that draws only takes it cannot score (no window,
        no audio beat) counts as none, and a :class:`ScoreWarning` says how many of the ``n`` that were; ``(nan,
        nan)`` when none does. Fewer than 2 takes: no intervals (``{}``, with a warning: every resample would be
        the same takes).

    Examples
    --------
    Three takes of 40 frames, each predicted 1, 2 and 3 cm off its truth. A resample's MPJPE is the mean offset
    of the takes it draws; only the draw of the first take three times (1/27 = 3.7 % of resamples, more than the
    2.5 % below the interval) gives 1 cm, and only the third three times gives 3 cm:

    >>> from beatlite.metrics.scoring import GroundTruth, Takes
    >>> truth = GroundTruth(Takes(positions=[np.zeros((40, 2, 3))] * 3))
    >>> off = Takes(positions=[np.full((40, 2, 3), [c, 0.0, 0.0]) for c in (1.0, 2.0, 3.0)])
    >>> bootstrap_intervals(off, truth, ["MPJPE"], n=1000)
    {'MPJPE': (1.0, 3.0)}
    >>> bootstrap_intervals(off, truth, ["MPJPE"], n=1000, level=0.5)["MPJPE"]  # the middle half of resamples
    (1.6666666666666667, 2.3333333333333335)
    """
    from tqdm import tqdm

    from beatlite.data.windows import window_starts
    from beatlite.metrics.scoring import evaluate

    if n <= 0:
        return {}
    counts = [len(window_starts(len(p))) for p in truth.takes.positions]
    if len(counts) < 2:
        warnings.warn(
            f"bootstrap intervals need at least 2 takes to resample, got {len(counts)}: none given",
            ScoreWarning,
            stacklevel=2,
        )
        return {}
    bounds = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    if generated.features is not None and len(generated.features) != bounds[-1]:
        raise ValueError(f"features have {len(generated.features)} rows, the takes {bounds[-1]} windows")
    rng = np.random.default_rng(seed)
    beats = truth.beats()
    values: dict[str, list[float]] = {key: [] for key in metrics}
    for _ in tqdm(range(n), desc="bootstrap", file=sys.stderr, disable=None if progress else True):
        idx = rng.integers(len(counts), size=len(counts))
        draw_truth = dataclasses.replace(
            truth, takes=_draw(truth.takes, idx, bounds), semantic=_pick(truth.semantic, idx),
            audio=_pick(truth.audio, idx), audio_beats=_pick(beats, idx),
            onsets={key: _pick(v, idx) for key, v in truth.onsets.items()},
        )  # fmt: skip
        scores = evaluate(_draw(generated, idx, bounds), draw_truth, metrics=metrics, seed=seed).values()
        for key in metrics:
            values[key].append(scores[key])
    q, out = 50 * (1 - level), {}
    for key, v in values.items():
        scored = np.asarray(v)[np.isfinite(v)]
        if len(scored) < n:
            warnings.warn(
                f"bootstrap: {n - len(scored)} of {n} resamples gave no {key} (evaluate skipped it on the takes "
                f"they drew: too few windows, no beats): its interval is over the other {len(scored)}",
                ScoreWarning,
                stacklevel=2,
            )
        out[key] = (
            tuple(float(x) for x in np.percentile(scored, [q, 100 - q])) if len(scored) else (math.nan,) * 2
        )
    return out


def mean_interval(values: Any, n: int, seed: int = 0, *, level: float = 0.95) -> np.ndarray:
    """Percentile interval of the mean of one value per take over ``n`` resamples of the takes.

    What :func:`bootstrap_intervals` gives a metric that is a mean over takes, on the values alone (the reference
    of notebook 09's exercise 3): each resample draws ``K`` of the ``K`` values with replacement by
    ``rng.integers(K, size=K)`` from ``rng = numpy.random.default_rng(seed)``, in order, and takes their mean.

    Parameters
    ----------
    values : (K,) float
        One value per take.
    n : int
        Resamples (at least 1).
    seed : int
    level : float
        Coverage of the central interval (0.95: the 2.5th and 97.5th percentiles).

    Returns
    -------
    (2,) float64
        ``[low, high]``.

    Examples
    --------
    >>> mean_interval([2.0, 2.0, 2.0], 50).tolist()  # every resample has the same mean
    [2.0, 2.0]
    >>> low, high = mean_interval(np.arange(8.0), 2000)
    >>> bool(low < 3.5 < high)
    True
    """
    x = np.asarray(values, dtype=np.float64)
    if x.ndim != 1 or len(x) == 0 or n < 1:
        raise ValueError(
            f"mean_interval needs a non-empty 1-D array and n >= 1, got shape {x.shape} and n={n}"
        )
    rng = np.random.default_rng(seed)
    means = [x[rng.integers(len(x), size=len(x))].mean() for _ in range(n)]
    q = 50 * (1 - level)
    return np.percentile(means, [q, 100 - q])


def _pick(xs: list[Any] | None, idx: np.ndarray) -> list[Any] | None:
    return None if xs is None else [xs[i] for i in idx]


def _draw(takes: Any, idx: np.ndarray, bounds: np.ndarray) -> Any:
    """The :class:`~beatlite.metrics.scoring.Takes` of the drawn takes (feature rows of their windows)."""
    rows = np.concatenate([np.arange(bounds[i], bounds[i + 1]) for i in idx])
    return dataclasses.replace(
        takes,
        positions=_pick(takes.positions, idx),
        directions=_pick(takes.directions, idx),
        euler=_pick(takes.euler, idx),
        features=None if takes.features is None else takes.features[rows],
        euler_features=None if takes.euler_features is None else takes.euler_features[rows],
        rot6d_features=None if takes.rot6d_features is None else takes.rot6d_features[rows],
    )


# ------------------------------------------------------------------------------------ writing takes
def _save_npy(path: Path, array: np.ndarray) -> None:
    from beatlite.io.atomic import atomic_write

    with atomic_write(path, "wb") as fh:
        np.save(fh, np.asarray(array, np.float64), allow_pickle=False)


def export_checkpoint_takes(
    checkpoint: str | Path,
    out_dir: str | Path,
    data: str | Path | None = None,
    *,
    split: str = "test",
    format: str = "bvh",
    test: Any = None,
    precision: int = EXPORT_PRECISION,
) -> list[Path]:
    """Write a checkpoint's generation of every take of ``split``, ready for :func:`score_folder`.

    The generation is :func:`beatlite.train.evaluation.evaluate_models`' (whole takes seeded by their first 4
    ground-truth frames, the checkpoint's own normalisers), at 15 fps, so scoring the folder gives the
    in-library numbers.

    Parameters
    ----------
    checkpoint : str or Path
        A shipped checkpoint name (``"camn_tiny"``) or a checkpoint path.
    out_dir : str or Path
        Created if needed; files ``{stem}.bvh`` or ``{stem}.npy``.
    data, split, test
        As :func:`score_folder`.
    format : {"bvh", "npy"}
        ``"bvh"``: an Euler model's 141 channels in BEAT's full 228-channel skeleton (other joints at rest,
        root at the origin; :func:`beatlite.skeleton.beat.expand_subset`), ``precision`` decimals. A direction
        model (HA2G) writes ``(T, 42, 3)`` direction ``.npy`` files instead: a BVH would need inverse
        kinematics and could not hold its directions exactly. ``"npy"``: ``(T, 141)`` Euler degrees or
        ``(T, 42, 3)`` directions.
    precision : int
        BVH decimals.

    Returns
    -------
    list of Path
        The files written, in take order.
    """
    import torch

    from beatlite.io import write_bvh
    from beatlite.io.motion import Motion
    from beatlite.paths import n_threads
    from beatlite.skeleton.beat import beat_skeleton, expand_subset
    from beatlite.train.testset import generate_takes, load_checkpoint_for

    if format not in ("bvh", "npy"):
        raise ValueError(f"format must be 'bvh' or 'npy', got {format!r}")
    test = load_split(data, split) if test is None else test
    torch.set_num_threads(n_threads())
    model, norms, _, _ = load_checkpoint_for(str(checkpoint), test)
    with torch.no_grad():
        directions, euler = generate_takes(model, test, norms)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for k, stem in enumerate(test.takes):
        if euler is not None and format == "bvh":
            path = out / f"{stem}.bvh"
            write_bvh(
                path,
                Motion(beat_skeleton(), expand_subset(euler[k], "spine_neck_141"), FPS),
                precision=precision,
            )
        else:
            path = out / f"{stem}.npy"
            _save_npy(path, directions[k] if euler is None else euler[k])
        written.append(path)
    return written


def export_ground_truth(test: Any, out_dir: str | Path, data: str | Path | None = None) -> list[Path]:
    """Write the ground truth of ``test``'s takes as ``{stem}.bvh`` files (the data's own skeleton and 228
    channels at 15 fps, as the evaluation loads them), for :func:`self_check`."""
    from beatlite.data.index import index_folder
    from beatlite.io import load_take, write_bvh
    from beatlite.io.motion import Motion

    index = index_folder(getattr(test, "folder", None) or data, read_durations=False)
    out, written = Path(out_dir), []
    for stem, truth in zip(test.takes, test.gt_directions, strict=True):
        take_stem, _, start = stem.partition("@")  # a clip of the "clips" protocol: {stem}@{start}
        record, first = index[take_stem], int(start or 0)
        take = load_take(record.path("motion"), fps=FPS, bvh_fps=record.bvh_fps)
        motion = Motion(take.motion.skeleton, take.motion.channels[first : first + len(truth)], FPS)
        written.append(out / f"{stem}.bvh")
        write_bvh(written[-1], motion, precision=EXPORT_PRECISION)
    return written


def self_check(
    data: str | Path | None = None,
    *,
    split: str = "test",
    metrics: Sequence[str] | None = None,
    bootstrap: int = 0,
    seed: int = 0,
    extractor: str | Path | None = None,
    test: Any = None,
    progress: bool = False,
) -> ScoreResult:
    """Score the split's own motion, written as BVH files and read back like any prediction.

    A sound pipeline gives FGD about 0 and every other metric equal to the ground truth's own value (the
    ``ground truth`` column); a difference shows where files and evaluation disagree (e.g. a data skeleton
    whose offsets are not beatlite's: predictions are scored on beatlite's BEAT skeleton).
    Arguments as :func:`score_folder`.
    """
    test = load_split(data, split) if test is None else test
    with tempfile.TemporaryDirectory(prefix="beatlite_self_check_") as tmp:
        export_ground_truth(test, tmp, data)
        result = score_folder(
            tmp, split=split, metrics=metrics, bootstrap=bootstrap, seed=seed, extractor=extractor, test=test,
            progress=progress,
        )  # fmt: skip
    result.info["pred"] = f"self-check: the {split} split's own BVH motion"
    own = result.truth.values()
    gaps = {
        r.key: abs(r.value - own[r.key]) / max(abs(own[r.key]), 1.0)  # absolute where 0 by definition (MPJPE)
        for r in result.evaluation.results
        if math.isfinite(r.value) and math.isfinite(own[r.key]) and not r.key.startswith("FGD")
    }
    worst = max(gaps, key=gaps.get) if gaps else None
    result.info["self_check"] = {"largest_gap": worst and [worst, gaps[worst]]}
    return result


# ------------------------------------------------------------------------------------ command line
def _print_warning(
    message: Any, category: Any, filename: str, lineno: int, file: Any = None, line: Any = None
) -> None:
    print(f"warning: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def _parser() -> argparse.ArgumentParser:
    from beatlite.metrics.scoring import METRICS

    p = argparse.ArgumentParser(prog="python -m beatlite.score", description=__doc__.split("\n")[0])
    p.add_argument("pred", nargs="?", help="folder of {stem}.bvh / {stem}.npy predictions")
    p.add_argument("--data", help="BEAT-format data folder (default $BEATLITE_DATA or data_samples/)")
    p.add_argument("--split", default="test", help="the ground-truth takes (default test)")
    p.add_argument(
        "--protocol",
        choices=PROTOCOLS,
        default="takes",
        help="takes: one {stem}.* per take; clips: HA2G's evaluator, one 34-frame {stem}@{start}.* per window (stride 10)",
    )
    p.add_argument(
        "--metrics",
        nargs="+",
        choices=list(METRICS),
        metavar="KEY",
        help=f"keys of beatlite.metrics.scoring.METRICS (default all): {', '.join(METRICS)}",
    )
    p.add_argument("--json", help="also write the scores as JSON here")
    p.add_argument("--md", help="also write the Markdown table here")
    p.add_argument(
        "--bootstrap", type=int, default=0, metavar="N", help="95 %% intervals from N resamples of takes"
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the Diversity pairs and the bootstrap draws")
    p.add_argument("--self-check", action="store_true", help="score the ground truth written as BVH files")
    p.add_argument("--extractor", help="FGD extractor checkpoint (dirvec space; default the shipped one)")
    p.add_argument("--allow-missing", action="store_true", help="score the takes that have a prediction")
    p.add_argument(
        "--pred-fps",
        type=float,
        metavar="FPS",
        help="frame rate of the rows instead of the files' own (e.g. 15 for BEAT's code's results, written under a "
        "120 fps Frame Time; a .npy's own is 15); a prediction of another length is then scored on the overlap",
    )
    p.add_argument("--export", metavar="CHECKPOINT", help="write CHECKPOINT's generations into PRED and stop")
    p.add_argument("--format", choices=("bvh", "npy"), default="bvh", help="--export file format")
    return p


def _run(args: argparse.Namespace) -> int:
    from beatlite.io.atomic import atomic_write

    if args.export and not args.pred:
        raise ScoreInputError(["--export needs PRED, the folder to write"])
    for flag, out in (("--json", args.json), ("--md", args.md)):
        if out and (Path(out).is_dir() or not Path(out).parent.is_dir()):
            raise ScoreInputError([f"{flag} {out}: not a file in an existing folder"])
    if args.bootstrap < 0:
        raise ScoreInputError([f"--bootstrap {args.bootstrap}: give 0 (none) or a number of resamples"])
    if not (args.export or args.self_check or args.pred):
        raise ScoreInputError(["give PRED (a folder of predictions) or --self-check"])
    test = load_split(args.data, args.split, protocol=args.protocol)
    if args.export:
        files = export_checkpoint_takes(args.export, args.pred, test=test, format=args.format)
        print(f"wrote {len(files)} files to {args.pred}")
        return 0
    common = {"split": args.split, "metrics": args.metrics, "bootstrap": args.bootstrap, "seed": args.seed,
              "extractor": args.extractor, "progress": True, "test": test}  # fmt: skip
    if args.self_check:
        result = self_check(args.data, **common)
    else:
        result = score_folder(
            args.pred, args.data, allow_missing=args.allow_missing, pred_fps=args.pred_fps, **common
        )
    text = result.to_markdown()
    print(text)
    if args.md:
        with atomic_write(args.md, "w") as fh:
            fh.write(text + "\n")
    if args.json:
        import json

        with atomic_write(args.json, "w") as fh:
            json.dump(result.to_dict(), fh, indent=2, sort_keys=True)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m beatlite.score PRED --data DATA ...``: 0 on success, 2 when the input cannot be scored."""
    from beatlite.io import FormatError

    args = _parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = _print_warning
        try:
            return _run(args)
        except ScoreInputError as exc:
            lines = exc.lines
        except (FormatError, OSError) as exc:  # (FileNotFoundError, PermissionError, IsADirectoryError, ...)
            lines = [" ".join(str(exc).split())]
    for line in lines:
        print(f"error: {line}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
