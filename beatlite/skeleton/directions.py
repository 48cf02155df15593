"""Bone direction vectors (the HA2G / Trimodal pose representation) and back to positions.

Taught in notebooks/06_ha2g.ipynb, section 1 (poses as unit bone directions).
"""

from __future__ import annotations

import numpy as np

from beatlite.skeleton.core import Skeleton

__all__ = ["directions_to_positions", "positions_to_directions", "skeleton_bones"]


def _as_bones(bones: np.ndarray) -> np.ndarray:
    b = np.asarray(bones)
    if b.ndim != 2 or b.shape[1] != 2 or not np.issubdtype(b.dtype, np.integer):
        raise ValueError(
            f"bones must be a (B, 2) integer array of (parent, child) joints, got {b.shape} {b.dtype}"
        )
    if b.size and b.min() < 0:
        raise ValueError("bones must hold non-negative joint indices")
    return b.astype(np.int64)


def skeleton_bones(skeleton: Skeleton) -> np.ndarray:
    """(J - 1, 2) int64 ``(parent, child)`` pairs of every non-root joint, in joint order.

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> chain = Skeleton(("A", "B", "C"), [-1, 0, 1], np.zeros((3, 3)), (("Xrotation",),) * 3)
    >>> skeleton_bones(chain)
    array([[0, 1],
           [1, 2]])
    """
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    child = np.arange(1, skeleton.n_joints, dtype=np.int64)
    return np.stack([skeleton.parents[child], child], axis=1)


def positions_to_directions(
    positions: np.ndarray, bones: np.ndarray, *, allow_zero: bool = False
) -> np.ndarray:
    """Unit direction of each bone, child minus parent.

    Parameters
    ----------
    positions : (..., J, 3) float
        Joint positions (any unit), e.g. (T, J, 3).
    bones : (B, 2) int
        ``(parent, child)`` joint indices.
    allow_zero : bool
        Zero-length bones raise ``ValueError`` (default) or give zero vectors.

    Returns
    -------
    (..., B, 3) float64 unit vectors.

    Examples
    --------
    >>> positions = np.array([[0.0, 0, 0], [0, 2, 0], [3, 2, 0]])
    >>> positions_to_directions(positions, np.array([[0, 1], [1, 2]]))
    array([[0., 1., 0.],
           [1., 0., 0.]])
    """
    pos = np.asarray(positions, dtype=np.float64)
    b = _as_bones(bones)
    if pos.ndim < 2 or pos.shape[-1] != 3:
        raise ValueError(f"positions must have shape (..., J, 3), got {pos.shape}")
    if b.size and b.max() >= pos.shape[-2]:
        raise ValueError(f"bones refer to joint {int(b.max())} but positions has only {pos.shape[-2]} joints")
    vec = pos[..., b[:, 1], :] - pos[..., b[:, 0], :]
    length = np.linalg.norm(vec, axis=-1, keepdims=True)
    zero = length[..., 0] < 1e-12
    if zero.any():
        if not allow_zero:
            which = sorted(set(np.nonzero(zero)[-1].tolist()))[:5]
            raise ValueError(
                f"zero-length bones {[tuple(b[k].tolist()) for k in which]} (bone indices {which}); "
                "pass allow_zero=True to get zero vectors"
            )
        length = np.where(zero[..., None], 1.0, length)
    return vec / length


def directions_to_positions(
    dirs: np.ndarray,
    bones: np.ndarray,
    lengths: np.ndarray,
    root: np.ndarray,
    *,
    normalize: bool = True,
) -> np.ndarray:
    """Rebuild joint positions from bone directions and lengths.

    Parameters
    ----------
    dirs : (..., B, 3) or (..., 3B) float
        Bone directions (normalised here unless ``normalize=False``); a flat last axis is read
        bone-major (x, y, z of bone 0, then bone 1, ...), like HA2G's 126-d vectors.
    bones : (B, 2) int
        ``(parent, child)`` pairs ordered so that each bone's parent is the root or the child of
        an earlier bone; every joint ``0 .. J-1`` must be reached.
    lengths : (B,) float
        Bone lengths (the output has their unit).
    root : (..., 3) or (3,) float
        Position of the root joint (the one parent that is nobody's child).

    Returns
    -------
    (..., J, 3) float64 with ``J = bones.max() + 1``.

    Examples
    --------
    >>> dirs = np.array([[0.0, 1, 0], [1, 0, 0]])
    >>> directions_to_positions(dirs, np.array([[0, 1], [1, 2]]), np.array([2.0, 3.0]), np.zeros(3))
    array([[0., 0., 0.],
           [0., 2., 0.],
           [3., 2., 0.]])
    """
    b = _as_bones(bones)
    n_bones = b.shape[0]
    d = _as_bone_vectors(dirs, n_bones)
    ln = np.asarray(lengths, dtype=np.float64)
    if ln.shape != (n_bones,):
        raise ValueError(f"lengths must have shape ({n_bones},), got {ln.shape}")
    r = np.asarray(root, dtype=np.float64)
    lead = d.shape[:-2]
    if r.shape not in ((3,), lead + (3,)):
        raise ValueError(f"root must have shape (3,) or {lead + (3,)}, got {r.shape}")
    if normalize:
        norm = np.linalg.norm(d, axis=-1, keepdims=True)
        if np.any(norm < 1e-12):
            raise ValueError("dirs contains zero vectors, which have no direction")
        d = d / norm
    root_joint, n_joints = _tree_root(b)
    out = np.full(lead + (n_joints, 3), np.nan)
    out[..., root_joint, :] = r
    placed = {root_joint}
    for k, (p, c) in enumerate(b.tolist()):
        if p not in placed:
            raise ValueError(f"bone {k} ({p}, {c}): parent joint {p} is not placed before it; reorder bones")
        out[..., c, :] = out[..., p, :] + ln[k] * d[..., k, :]
        placed.add(c)
    return out


def _as_bone_vectors(dirs: np.ndarray, n_bones: int) -> np.ndarray:
    """``dirs`` as (..., B, 3) float64; a flat (..., 3B) last axis is read bone-major."""
    d = np.asarray(dirs, dtype=np.float64)
    if d.ndim >= 1 and d.shape[-1] == 3 * n_bones and n_bones != 1:
        d = d.reshape(d.shape[:-1] + (n_bones, 3))  # flat (..., 3B) bone-major vectors
    if d.ndim < 2 or d.shape[-2:] != (n_bones, 3):
        raise ValueError(f"dirs must have shape (..., {n_bones}, 3) for {n_bones} bones, got {d.shape}")
    return d


def _tree_root(b: np.ndarray) -> tuple[int, int]:
    """The root joint and the joint count J of bones ``b`` (B, 2); ``ValueError`` unless they form
    one tree over joints ``0 .. J-1`` in which every joint but the root is the child of one bone."""
    n_bones = b.shape[0]
    n_joints = int(b.max()) + 1
    children = set(b[:, 1].tolist())
    roots = {int(p) for p in b[:, 0] if int(p) not in children}
    if len(roots) != 1 or len(children) != n_bones or len(children | roots) != n_joints:
        raise ValueError(
            f"bones must form one tree over joints 0..{n_joints - 1} with a single root and each joint "
            f"the child of one bone; roots found: {sorted(roots)}"
        )
    (root_joint,) = roots
    return root_joint, n_joints
