"""Input checks and skeleton helpers shared by the viz modules (no matplotlib, no pyvista here)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from beatlite.skeleton.core import Skeleton

GROUPS: tuple[str, ...] = ("body", "hands", "head")


@dataclass(frozen=True)
class Bones:
    """The drawable bones of a skeleton, split by joint group.

    Attributes
    ----------
    n_joints : int
        Number of joints J the positions must have.
    pairs : dict str -> (B_g, 2) int64
        For each group in :data:`GROUPS`, the (parent, child) joint indices of its
        bones; a bone belongs to its child's group.
    joints : dict str -> (J_g,) int64
        The joint indices of each group.
    has_feet : bool
        True when a joint is named like a foot, toe or ankle: the skeleton stands,
        so plots draw a floor under it. An upper body (HA2G's TED-43) or an
        unnamed parents array gets no floor.
    """

    n_joints: int
    pairs: dict[str, np.ndarray]
    joints: dict[str, np.ndarray]
    has_feet: bool = False


_TED_HANDS = ("wrist", "thumb", "index", "middle", "ring", "pinky")
_TED_HEAD = ("nose", "eye", "ear")
_FEET = ("foot", "toe", "ankle")


def joint_group(name: str) -> str:
    """The plot group of a joint from its name: hands, head (and neck) or body.

    BEAT names (``"RightHandIndex2"``, ``"Neck1"``) are matched by the words
    "Hand", "Head" and "Neck"; TED-43 names (``"right_wrist"``, ``"left_thumb2"``,
    ``"nose"``), split at underscores, by wrist and finger words (hands) and
    nose, eye and ear (head), so a TED-43 skeleton has the colours of a BEAT one.

    Parameters
    ----------
    name : str
        Joint name, e.g. ``"RightHandIndex2"`` (hands), ``"Neck1"`` (head), ``"Spine"`` (body).

    Returns
    -------
    str
        One of ``"body"``, ``"hands"``, ``"head"``.
    """
    low = name.lower()
    words = low.rstrip("0123456789").split("_")
    if "hand" in low or any(w in _TED_HANDS for w in words):
        return "hands"
    if "head" in low or "neck" in low or any(w in _TED_HEAD for w in words):
        return "head"
    return "body"


def _ted43_names(parents: np.ndarray) -> tuple[str, ...] | None:
    """TED-43 joint names when ``parents`` is HA2G's TED-43 hierarchy (so its plots get named colours)."""
    from beatlite.skeleton.ted import TED43_JOINTS, TED_BONES

    if parents.size != len(TED43_JOINTS):
        return None
    ted = np.full(len(TED43_JOINTS), -1)
    for parent, child in TED_BONES:
        ted[child] = parent
    return TED43_JOINTS if np.array_equal(ted, parents) else None


def _check_parents(skeleton: Any) -> np.ndarray:
    """A ``(J,) int64`` parents array (-1 at roots, else another joint's index), or a TypeError/ValueError."""
    parents = np.asarray(skeleton)
    if parents.ndim != 1 or parents.size == 0 or not np.issubdtype(parents.dtype, np.integer):
        raise TypeError(
            "skeleton must be a beatlite Skeleton or a (J,) integer parents array, "
            f"got {type(skeleton).__name__} with shape {getattr(parents, 'shape', None)} "
            f"and dtype {getattr(parents, 'dtype', None)}"
        )
    parents = parents.astype(np.int64)
    bad = np.flatnonzero((parents < -1) | (parents >= parents.size) | (parents == np.arange(parents.size)))
    if bad.size:
        raise ValueError(f"skeleton: parents[{bad[0]}] = {parents[bad[0]]} is not -1 or another joint index")
    return parents


def _joint_groups(names: Sequence[str] | None, n: int) -> np.ndarray:
    """``(J,)`` group name of each joint (all ``"body"`` without names)."""
    if names is None:
        return np.array(["body"] * n)
    if len(names) != n:
        raise ValueError(f"names: {len(names)} names for {n} joints")
    return np.array([joint_group(str(nm)) for nm in names])


def bone_groups(skeleton: Skeleton | Sequence[int] | np.ndarray, names: Sequence[str] | None = None) -> Bones:
    """Drawable bones and joint groups of a :class:`Skeleton` or of a parents array.

    (Not :func:`beatlite.skeleton.skeleton_bones`, which lists the bone vectors of a Skeleton.)

    Parameters
    ----------
    skeleton : Skeleton or (J,) int array
        The hierarchy; a parents array has ``-1`` at roots and ``0 <= parents[j] < J`` elsewhere.
    names : sequence of str, optional
        Joint names used to colour groups when ``skeleton`` is a parents array. Without
        them HA2G's TED-43 hierarchy is recognised and named; any other array is all body.

    Returns
    -------
    Bones
    """
    if isinstance(skeleton, Skeleton):
        parents, names = skeleton.parents, skeleton.names
    else:
        parents = _check_parents(skeleton)
    n = int(parents.size)
    names = _ted43_names(parents) if names is None else names
    groups = _joint_groups(names, n)
    child = np.flatnonzero(parents >= 0)
    pairs = np.stack([parents[child], child], axis=1) if child.size else np.zeros((0, 2), np.int64)
    return Bones(
        n_joints=n,
        pairs={g: pairs[groups[pairs[:, 1]] == g] for g in GROUPS},
        joints={g: np.flatnonzero(groups == g) for g in GROUPS},
        has_feet=names is not None and any(f in str(nm).lower() for nm in names for f in _FEET),
    )


def check_positions(positions: Any, n_joints: int | None = None, name: str = "positions") -> np.ndarray:
    """Validate joint positions and return them as ``(T, J, 3) float64``.

    Parameters
    ----------
    positions : array-like, (T, J, 3) or (J, 3)
        Joint positions in centimetres; a single ``(J, 3)`` frame becomes ``(1, J, 3)``.
    n_joints : int, optional
        Required J (from the skeleton).
    name : str
        Argument name used in error messages.

    Returns
    -------
    (T, J, 3) float64 ndarray, centimetres
    """
    try:
        arr = np.asarray(positions, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a numeric (T, J, 3) array, got {type(positions).__name__}") from exc
    if arr.ndim == 2:
        arr = arr[None]
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] == 0:
        raise ValueError(f"{name} must have shape (T, J, 3) with T >= 1, got {arr.shape}")
    if n_joints is not None and arr.shape[1] != n_joints:
        raise ValueError(
            f"{name} has {arr.shape[1]} joints but the skeleton has {n_joints}: shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values (shape {arr.shape})")
    return arr


def per_sequence(values: Any, n: int, name: str) -> list[Any]:
    """One skeleton per sequence: a list/tuple of skeletons is used as is, anything else is repeated."""
    is_per_sequence = (
        isinstance(values, list | tuple) and len(values) > 0 and not isinstance(values[0], int | np.integer)
    )
    if is_per_sequence:
        if len(values) != n:
            raise ValueError(f"{name}: {len(values)} given for {n} sequences")
        return list(values)
    return [values] * n


def checked_sequences(seqs: Sequence[Any], skeletons: Any, name: str) -> tuple[list[np.ndarray], list[Bones]]:
    """Several position sequences checked against their skeletons (one skeleton for all, or one each).

    Parameters
    ----------
    seqs : sequence of (T_i, J_i, 3) array-like, centimetres
        At least one sequence.
    skeletons : Skeleton or parents array, or a list/tuple of them (one per sequence)
        Hierarchies.
    name : str
        Argument name for error messages.

    Returns
    -------
    (list of (T_i, J_i, 3) float64, list of Bones)
    """
    if not len(seqs):
        raise ValueError(f"{name}: no sequence to draw")
    bones = [bone_groups(s) for s in per_sequence(skeletons, len(seqs), "skeleton")]
    return [
        check_positions(p, b.n_joints, f"{name}[{i}]") for i, (p, b) in enumerate(zip(seqs, bones))
    ], bones


def check_fps(fps: Any, name: str = "fps") -> float:
    """A positive finite frame rate as float (frames per second)."""
    try:
        value = float(fps)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a positive number, got {fps!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive number, got {fps!r}")
    return value


def frame_indices(n_frames: int, fps: float, out_fps: float | None) -> np.ndarray:
    """Frame indices that play ``n_frames`` recorded at ``fps`` at ``out_fps`` (never faster than recorded).

    Parameters
    ----------
    n_frames : int
        Frames available T.
    fps : float
        Frame rate of the data.
    out_fps : float or None
        Wanted playback rate; ``None`` or ``>= fps`` keeps every frame.

    Returns
    -------
    (K,) int64
        ``round(k * fps / out_fps)`` for every k whose time lies inside the clip.
    """
    if out_fps is None or out_fps >= fps:
        return np.arange(n_frames, dtype=np.int64)
    step = fps / out_fps
    idx = np.round(np.arange(0.0, n_frames - 0.5, step)).astype(np.int64)
    return np.unique(np.clip(idx, 0, n_frames - 1))


def check_words(words: Any) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Word timings as ``(starts (W,) float64 s, ends (W,) float64 s, words tuple of str)``.

    Accepts a 3-tuple or a ``beatlite.io`` ``WordIntervals`` (anything with
    ``starts``, ``ends`` and ``words`` attributes).
    """
    if all(hasattr(words, a) for a in ("starts", "ends", "words")):
        starts, ends, texts = words.starts, words.ends, words.words
    else:
        try:
            starts, ends, texts = words
        except (TypeError, ValueError):
            raise TypeError(
                f"words must be (starts, ends, words) or a WordIntervals, got {type(words).__name__}"
            ) from None
    starts = np.asarray(starts, dtype=np.float64).reshape(-1)
    ends = np.asarray(ends, dtype=np.float64).reshape(-1)
    texts = tuple(str(w) for w in texts)
    if not (starts.shape == ends.shape == (len(texts),)):
        raise ValueError(
            f"words: starts {starts.shape}, ends {ends.shape} and {len(texts)} words must have the same length"
        )
    if np.any(ends < starts):
        k = int(np.flatnonzero(ends < starts)[0])
        raise ValueError(
            f"words: word {k} ({texts[k]!r}) ends at {ends[k]} s before it starts at {starts[k]} s"
        )
    return starts, ends, texts


def word_at(t: float, starts: np.ndarray, ends: np.ndarray, texts: Sequence[str]) -> str:
    """The word spoken at time ``t`` seconds (``starts[k] <= t < ends[k]``), or ``""``."""
    k = int(np.searchsorted(starts, t, side="right")) - 1
    if 0 <= k < len(texts) and starts[k] <= t < ends[k]:
        return texts[k]
    hit = np.flatnonzero((starts <= t) & (t < ends))  # unsorted input
    return texts[int(hit[0])] if hit.size else ""


def to_plot_coords(positions: np.ndarray) -> np.ndarray:
    """Map Y-up data coordinates ``(x, y, z)`` to matplotlib's Z-up ``(x, -z, y)`` (a proper rotation).

    Parameters
    ----------
    positions : (..., 3) float64
        Positions with Y up, the character facing +Z.

    Returns
    -------
    (..., 3) float64
        Same points in plot axes: height on the plot's Z axis, the character facing
        the plot's -Y, so matplotlib's default front view (azim=-90) looks at its face.
    """
    return np.stack([positions[..., 0], -positions[..., 2], positions[..., 1]], axis=-1)
