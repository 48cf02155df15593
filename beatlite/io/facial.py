"""Facial blendshape weights (ARKit, 60 fps) stored as BEAT's JSON.

The format is ``{"names": [51 names], "frames": [{"time": t, "weights": [51 floats]}, ...]}``
with ``time`` in seconds (docs/reference_code.md#facial-json). BEAT has 51 weights: ARKit's 52 minus
``tongueOut``.

Taught in notebooks/01_beat_formats.ipynb, section 8 (the face: 51 ARKit blendshapes at 60 fps).
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError, FormatWarning
from beatlite.io.textfile import read_text

__all__ = [
    "ARKIT_52",
    "ARKIT_51",
    "Facial",
    "read_facial",
    "select_blendshapes",
    "write_facial",
    "estimate_fps",
]

#: The 52 ARKit blendshapes in the standard order (ARKit documentation / Live Link Face CSV).
ARKIT_52: tuple[str, ...] = (
    "eyeBlinkLeft", "eyeLookDownLeft", "eyeLookInLeft", "eyeLookOutLeft", "eyeLookUpLeft",
    "eyeSquintLeft", "eyeWideLeft", "eyeBlinkRight", "eyeLookDownRight", "eyeLookInRight",
    "eyeLookOutRight", "eyeLookUpRight", "eyeSquintRight", "eyeWideRight", "jawForward", "jawLeft",
    "jawRight", "jawOpen", "mouthClose", "mouthFunnel", "mouthPucker", "mouthLeft", "mouthRight",
    "mouthSmileLeft", "mouthSmileRight", "mouthFrownLeft", "mouthFrownRight", "mouthDimpleLeft",
    "mouthDimpleRight", "mouthStretchLeft", "mouthStretchRight", "mouthRollLower", "mouthRollUpper",
    "mouthShrugLower", "mouthShrugUpper", "mouthPressLeft", "mouthPressRight", "mouthLowerDownLeft",
    "mouthLowerDownRight", "mouthUpperUpLeft", "mouthUpperUpRight", "browDownLeft", "browDownRight",
    "browInnerUp", "browOuterUpLeft", "browOuterUpRight", "cheekPuff", "cheekSquintLeft",
    "cheekSquintRight", "noseSneerLeft", "noseSneerRight", "tongueOut",
)  # fmt: skip

#: BEAT's 51 facial channels: :data:`ARKIT_52` without ``tongueOut`` (docs/reference_code.md#facial-json).
ARKIT_51: tuple[str, ...] = tuple(n for n in ARKIT_52 if n != "tongueOut")

DEFAULT_FPS = 60.0
#: Frame rates the time stamps may imply (Hz).
FPS_RANGE = (1.0, 1000.0)


@dataclass(eq=False)
class Facial:
    """Blendshape weights of one take.

    Attributes
    ----------
    names : tuple of str, length K
        Blendshape names (51 for BEAT, :data:`ARKIT_51`).
    weights : (T, K) float32
        Weights, nominally in [0, 1].
    times : (T,) float64, seconds
        Time stamp of each frame, strictly increasing.
    fps : float
        Frame rate estimated from ``times`` (:func:`estimate_fps`).

    Examples
    --------
    >>> face = Facial(("jawOpen",), np.zeros((3, 1), np.float32), np.array([0.0, 1 / 60, 2 / 60]), 60.0)
    >>> face.weights.shape, face.fps
    ((3, 1), 60.0)
    """

    names: tuple[str, ...]
    weights: np.ndarray
    times: np.ndarray
    fps: float

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.weights.shape[0])

    def __repr__(self) -> str:
        return f"Facial({self.n_frames} frames x {len(self.names)} blendshapes @ {self.fps:g} fps)"


def estimate_fps(times: np.ndarray, default: float = DEFAULT_FPS) -> float:
    """Frame rate from time stamps: ``1 / median(diff(times))``, snapped to an integer within 1 %.

    Parameters
    ----------
    times : (T,) float, seconds
        Increasing time stamps.
    default : float
        Returned when there are fewer than two frames.

    Examples
    --------
    >>> estimate_fps(np.arange(10) / 60.0)
    60.0
    >>> estimate_fps(np.arange(10) * 0.0401)  # within 1 % of 25: snapped
    25.0
    """
    t = np.asarray(times, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"estimate_fps: times must be (T,), got shape {t.shape}")
    if t.size < 2:
        return float(default)
    fps = 1.0 / float(np.median(np.diff(t)))
    if not math.isfinite(fps):
        return fps
    n = round(fps)
    return float(n) if n >= 1 and abs(fps - n) <= 0.01 * n else fps


class _DuplicateKey(Exception):
    pass


def _unique_keys(pairs: list[tuple[str, object]]) -> dict:
    """A JSON object as a dict; a key given twice raises (``json`` would keep the last one silently)."""
    doc = dict(pairs)
    if len(doc) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise _DuplicateKey(key)
            seen.add(key)
    return doc


def _parse_json(p: Path) -> dict:
    """The JSON object of ``p``; numbers become floats (no digit limit, no overflow); no key twice in an object."""
    text = read_text(p)
    if not text.strip():
        raise FormatError(p, "empty file: expected facial JSON")
    try:
        doc = json.loads(text, parse_int=float, object_pairs_hook=_unique_keys)
    except _DuplicateKey as exc:
        key = str(exc.args[0])
        raise FormatError(
            p, f"key {key!r} appears twice in one object (which one is meant is unknown)", field=key
        ) from None
    except json.JSONDecodeError as exc:
        raise FormatError(p, f"invalid JSON: {exc.msg}", line=exc.lineno, column=exc.colno) from None
    except RecursionError:
        raise FormatError(p, "invalid JSON: nested too deeply") from None
    if not isinstance(doc, dict):
        raise FormatError(p, f"top level must be an object, got {type(doc).__name__}")
    for key in ("names", "frames"):
        if key not in doc:
            raise FormatError(
                p, f"missing key {key!r} (keys present: {sorted(map(str, doc))[:10]})", field=key
            )
    names = doc["names"]
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        raise FormatError(p, "'names' must be a non-empty list of strings", field="names")
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise FormatError(p, f"blendshape names appear twice: {twice[:5]}", field="names")
    if not isinstance(doc["frames"], list):
        raise FormatError(p, f"'frames' must be a list, got {type(doc['frames']).__name__}", field="frames")
    return doc


def _frame_values(p: Path, i: int, frame: object, k: int) -> tuple[float, list[float]]:
    """``(time, weights)`` of frame ``i``, each a finite float (bools and strings refused)."""
    if not isinstance(frame, dict):
        raise FormatError(p, f"frame {i} is not an object", field=f"frames[{i}]")
    for key in ("time", "weights"):
        if key not in frame:
            raise FormatError(p, f"frame {i} has no {key!r}", field=f"frames[{i}].{key}")
    t, w = frame["time"], frame["weights"]
    if type(t) is not float or not math.isfinite(t):
        raise FormatError(p, f"frame {i}: time {t!r:.40} is not a finite number", field=f"frames[{i}].time")
    if not isinstance(w, list) or len(w) != k:
        got = len(w) if isinstance(w, list) else type(w).__name__
        raise FormatError(
            p, f"frame {i} has {got} weights but there are {k} names", field=f"frames[{i}].weights"
        )
    bad = next((j for j, v in enumerate(w) if type(v) is not float or not math.isfinite(v)), None)
    if bad is not None:
        raise FormatError(
            p,
            f"frame {i}: weight {bad} ({w[bad]!r:.40}) is not a finite number",
            field=f"frames[{i}].weights",
        )
    return t, w


def select_blendshapes(
    facial: Facial, names: Sequence[str] = ARKIT_51, *, path: str | os.PathLike[str] | None = None
) -> Facial:
    """The weights of ``names``, in that order, picked from ``facial`` by name.

    Parameters
    ----------
    facial : Facial
        As read (any column order, e.g. an ARKit export with 52 names).
    names : sequence of str
        The canonical order (default :data:`ARKIT_51`, BEAT's 51 channels).
    path : str or PathLike, optional
        File named in errors and warnings.

    Returns
    -------
    Facial
        ``weights`` (T, len(names)) float32 in the order of ``names``.

    Raises
    ------
    FormatError
        If a name of ``names`` is missing (naming it). Extra names (``tongueOut``) are
        dropped, and a different column order is reordered, each with one
        :class:`FormatWarning`.

    Examples
    --------
    >>> face = Facial(("mouthClose", "jawOpen"), np.array([[0.1, 0.9]], np.float32), np.zeros(1), 60.0)
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     picked = select_blendshapes(face, ["jawOpen", "mouthClose"])
    >>> picked.names, picked.weights, len(caught)  # reordered by name, with one FormatWarning
    (('jawOpen', 'mouthClose'), array([[0.9, 0.1]], dtype=float32), 1)
    """
    wanted = tuple(names)
    where = {n: i for i, n in enumerate(facial.names)}
    missing = [n for n in wanted if n not in where]
    if missing:
        raise FormatError(
            path,
            f"blendshape {missing[0]!r} is missing ({len(missing)} of {len(wanted)} missing: {missing[:5]})",
            field="names",
        )
    extra = [n for n in facial.names if n not in set(wanted)]
    kept = [n for n in facial.names if n not in set(extra)]
    if extra:
        warnings.warn(
            f"{path}: dropping {len(extra)} blendshapes not in the canonical {len(wanted)}: {extra[:5]}",
            FormatWarning,
            stacklevel=2,
        )
    if kept != list(wanted):
        warnings.warn(
            f"{path}: blendshape columns are in another order; reordered by name to the canonical order",
            FormatWarning,
            stacklevel=2,
        )
    cols = np.array([where[n] for n in wanted], dtype=np.int64)
    return Facial(names=wanted, weights=facial.weights[:, cols], times=facial.times, fps=facial.fps)


def read_facial(path: str | os.PathLike[str], *, names: Sequence[str] | None = None) -> Facial:
    """Read a BEAT facial JSON file (``.json`` or ``.json.gz``).

    Parameters
    ----------
    path : str or PathLike
        The file.
    names : sequence of str, optional
        Canonical blendshape order to map the columns to by name
        (:func:`select_blendshapes`, e.g. :data:`ARKIT_51`); default: the file's own.

    Returns
    -------
    Facial
        ``weights`` (T, K) float32 (K = 51 for BEAT), ``times`` (T,) float64 seconds, ``fps``.

    Raises
    ------
    FormatError
        Invalid or too deeply nested JSON (line/column), a missing key, a key given
        twice in one object (e.g. two ``"names"``), duplicate names, a frame whose weight count differs from the number of names, a weight
        or time that is not a finite number (strings and booleans included), or time
        stamps that do not increase (each naming the frame index).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.json.gz"
    >>> write_facial(path, ARKIT_51, np.full((120, 51), 0.25), fps=60)
    >>> face = read_facial(path)
    >>> face.weights.shape, face.fps, float(face.weights[0, 0]), round(float(face.times[-1]), 6)
    ((120, 51), 60.0, 0.25, 1.983333)
    >>> tmp.cleanup()
    """
    p = Path(path)
    doc = _parse_json(p)
    frames, k = doc["frames"], len(doc["names"])
    if not frames:
        raise FormatError(p, "no frames: an empty facial track", field="frames")
    times = np.empty(len(frames), dtype=np.float64)
    weights = np.empty((len(frames), k), dtype=np.float32)
    for i, frame in enumerate(frames):
        times[i], weights[i] = _frame_values(p, i, frame, k)
    if not np.isfinite(weights).all():  # finite float64 beyond float32's range
        i = int(np.flatnonzero(~np.isfinite(weights).all(axis=1))[0])
        raise FormatError(p, f"frame {i} has a weight beyond float32 range", field=f"frames[{i}].weights")
    steps = np.diff(times)
    if steps.size and not (steps > 0).all():
        i = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise FormatError(
            p,
            f"time stamps must increase: frame {i} has time {times[i]} after {times[i - 1]}",
            field=f"frames[{i}].time",
        )
    fps = estimate_fps(times)
    if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:
        raise FormatError(
            p, f"frame times imply {fps:g} fps, outside {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}", field="frames"
        )
    _warn_on_holes(p, times, fps)
    facial = Facial(names=tuple(doc["names"]), weights=weights, times=times, fps=fps)
    return facial if names is None else select_blendshapes(facial, names, path=p)


#: A step between time stamps longer than this many frame periods is a hole in the track.
HOLE_PERIODS = 1.5


def _warn_on_holes(path: Path, times: np.ndarray, fps: float) -> None:
    """One :class:`FormatWarning` naming the largest gap when the time stamps skip frames: the weights are used
    as a uniform ``fps`` track (``Facial.weights[i]`` at ``i / fps``), so frames after a hole come early."""
    steps = np.diff(times)
    holes = np.flatnonzero(steps > HOLE_PERIODS / fps)
    if holes.size:
        i = int(holes[np.argmax(steps[holes])])
        missing = float(np.sum(steps[holes]) - holes.size / fps)
        warnings.warn(
            FormatWarning(
                f"{path}: {holes.size} hole(s) in the time stamps at {fps:g} fps, the largest {steps[i]:.3f} s "
                f"after frame {i} ({times[i]:.3f} s); read as a uniform track, frames after the holes are "
                f"{missing:.3f} s early (resample by `times` to keep them in place)"
            ),
            stacklevel=3,
        )


def write_facial(
    path: str | os.PathLike[str],
    names: Sequence[str],
    weights: np.ndarray,
    fps: float = DEFAULT_FPS,
    *,
    times: np.ndarray | None = None,
) -> None:
    """Write blendshape weights as BEAT facial JSON, atomically (``.gz`` suffix gzips).

    Parameters
    ----------
    path : str or PathLike
        Destination.
    names : sequence of str, length K
        Blendshape names (e.g. :data:`ARKIT_51`).
    weights : (T, K) float
        Weights, written rounded to 6 decimals (values already rounded read back equal as float32).
    fps : float
        Frame rate; frame ``i`` gets ``time = i / fps`` unless ``times`` is given.
    times : (T,) float, optional
        Explicit increasing time stamps in seconds (written rounded to 6 decimals).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.json"
    >>> weights = np.round(np.random.default_rng(0).uniform(0, 1, (5, 2)), 6)
    >>> write_facial(path, ["jawOpen", "mouthClose"], weights, fps=30)
    >>> face = read_facial(path)
    >>> face.names, bool(np.array_equal(face.weights, weights.astype(np.float32))), face.fps
    (('jawOpen', 'mouthClose'), True, 30.0)
    >>> tmp.cleanup()
    """
    names = [str(n) for n in names]
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 2 or w.shape[1] != len(names):
        raise ValueError(f"write_facial: weights must be (T, {len(names)}), got shape {w.shape}")
    if not np.isfinite(w).all():
        raise ValueError("write_facial: weights contain NaN or infinite values")
    if not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"write_facial: fps must be positive, got {fps}")
    if times is None:
        t = np.arange(w.shape[0], dtype=np.float64) / float(fps)
    else:
        t = np.asarray(times, dtype=np.float64)
        if t.shape != (w.shape[0],):
            raise ValueError(f"write_facial: times must be ({w.shape[0]},), got shape {t.shape}")
        if t.size > 1 and not (np.diff(t) > 0).all():
            raise ValueError("write_facial: times must be strictly increasing")
    frames = [
        {"time": round(float(ti), 6), "weights": [round(v, 6) for v in row]} for ti, row in zip(t, w.tolist())
    ]
    with atomic_write(path, "w") as f:
        json.dump({"names": names, "frames": frames}, f, separators=(",", ":"))
