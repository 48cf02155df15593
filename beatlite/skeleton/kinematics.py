"""Forward kinematics: BVH channel rows -> world joint rotations and positions.

For joint ``j`` with parent ``p``::

    R_world[j] = R_world[p] @ R_local[j]
    x_world[j] = x_world[p] + R_world[p] @ (offset[j] + t[j])

where ``R_local[j]`` is built from the joint's rotation channels in the Euler order its CHANNELS
line gives (intrinsic, degrees) and ``t[j]`` is its ``X/Y/Zposition`` channels (0 if it has none).
For the root ``R_world[p] = I`` and ``x_world[p] = 0``.

Position channels (``position_mode``): by default (``"replace"``) a joint with position channels
is placed at those channels alone, ignoring its OFFSET (as Blender and MotionBuilder read BVH).
``"add"`` places a non-root joint at ``OFFSET + channels``; the root is always placed at its
channels alone, because exporters (ZEGGS, LAFAN1, PyMO) write the root OFFSET as the start
position that the root channels already contain -- adding it would count it twice.

Implementation: the loop runs over joints only. Frames are processed in blocks of
``_BLOCK`` with the frame axis last, so every NumPy call works on contiguous rows that stay
in cache, and the local rotations of all joints of one Euler order are built at once.

Taught in notebooks/01_beat_formats.ipynb, section 5 (forward kinematics, by hand for one arm).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from beatlite.skeleton.core import Skeleton
from beatlite.skeleton.rotations import _AXIS, _euler_fill

__all__ = ["forward_kinematics", "global_transforms", "local_rotations", "rest_pose", "skeleton_extent"]

_POSITION_MODES = ("add", "replace")
_BLOCK = 384  # frames per block (small enough for the working set to stay in cache)


# ----------------------------------------------------------------------------- helpers
def _check_inputs(skeleton: Skeleton, channels: np.ndarray, position_mode: str = "replace") -> np.ndarray:
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    if position_mode not in _POSITION_MODES:
        raise ValueError(f"position_mode must be one of {_POSITION_MODES}, got {position_mode!r}")
    try:
        ch = np.asarray(channels, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"channels must be a numeric array, got {type(channels).__name__}") from exc
    if ch.ndim != 2 or ch.shape[1] != skeleton.n_channels:
        raise ValueError(f"channels must have shape (T, {skeleton.n_channels}), got {ch.shape}")
    return ch


def _order_groups(
    skeleton: Skeleton,
) -> tuple[list[tuple[str, slice | None, list[int], np.ndarray]], list[int]]:
    """Joints grouped by Euler order: ``(order, slice or None, joints, (G, 3) rotation columns)``;
    and the joints without rotation channels. The slice is set when the group's joints are
    consecutive (true for BEAT and most files), which lets the block code write in place."""
    groups: dict[str, list[int]] = {}
    no_rotation: list[int] = []
    for j in range(skeleton.n_joints):
        order = skeleton.rotation_order(j)
        if not order:
            no_rotation.append(j)
            continue
        if len(order) != 3 or sorted(order) != ["X", "Y", "Z"]:
            raise ValueError(
                f"joint {skeleton.names[j]!r} has rotation channels {skeleton.channels[j]}, "
                "need exactly one each of Xrotation, Yrotation, Zrotation"
            )
        groups.setdefault(order, []).append(j)
    out = []
    for order, joints in groups.items():
        contiguous = joints == list(range(joints[0], joints[-1] + 1))
        sel = slice(joints[0], joints[-1] + 1) if contiguous else None
        out.append((order, sel, joints, np.stack([skeleton.rotation_channel_indices(j) for j in joints])))
    return out, no_rotation


class _Workspace:
    """Scratch arrays for one block of ``n`` frames, allocated once per call and reused by
    every block (large temporaries would otherwise be page-faulted in again for each block)."""

    def __init__(self, skeleton: Skeleton, n: int) -> None:
        n_joints = skeleton.n_joints
        self.local = np.empty((n_joints, 3, 3, n))
        self.rot = np.empty((n_joints, 3, 3, n))
        self.pos = np.empty((n_joints, 3, n))
        self.ang = np.empty((n_joints, 3, n))  # angles, then half-angle tangents
        self.t2 = np.empty((n_joints, 3, n))
        self.cos = np.empty((n_joints, 3, n))
        self.sin = np.empty((n_joints, 3, n))
        self.scratch = np.empty((3, n_joints, n))


def _local_block(
    skeleton: Skeleton, ch_t: np.ndarray, groups: list, no_rotation: list[int], ws: _Workspace
) -> np.ndarray:
    """(J, 3, 3, n) local rotations of one block (a view of ``ws.local``); ``ch_t`` is (C, n)."""
    n = ch_t.shape[1]
    local = ws.local[..., :n]
    for j in no_rotation:
        local[j] = np.eye(3)[:, :, None]
    for order, sel, joints, cols in groups:
        g = len(joints)
        ang, t2, cos, sin = ws.ang[:g, :, :n], ws.t2[:g, :, :n], ws.cos[:g, :, :n], ws.sin[:g, :, :n]
        np.take(ch_t, cols, axis=0, out=ang)  # (G, 3, n) degrees
        # half-angle tangent t = tan(angle / 2); cos = (1 - t^2) / (1 + t^2), sin = 2 t / (1 + t^2)
        np.multiply(ang, np.pi / 360.0, out=ang)
        np.tan(ang, out=ang)
        np.multiply(ang, ang, out=t2)
        np.subtract(1.0, t2, out=cos)
        np.add(t2, 1.0, out=t2)
        np.divide(cos, t2, out=cos)
        sign = 2.0 if (_AXIS[order[1]] - _AXIS[order[0]]) % 3 == 1 else -2.0  # parity-signed sines
        np.multiply(ang, sign, out=sin)
        np.divide(sin, t2, out=sin)
        target = local[sel] if sel is not None else np.empty((g, 3, 3, n))
        scratch = (ws.scratch[0, :g, :n], ws.scratch[1, :g, :n], ws.scratch[2, :g, :n])
        _euler_fill(
            (cos[:, 0], cos[:, 1], cos[:, 2]),
            (sin[:, 0], sin[:, 1], sin[:, 2]),
            order,
            np.moveaxis(target, (1, 2), (0, 1)),
            scratch,
        )
        if sel is None:
            local[joints] = target
    return local


def _blocks(
    skeleton: Skeleton, ch: np.ndarray, position_mode: str, need_rot: np.ndarray
) -> Iterator[tuple[slice, np.ndarray, np.ndarray]]:
    """Yield ``(frames, rot (J, 3, 3, n), pos (J, 3, n))`` world transforms block by block.

    The arrays are views of one workspace, overwritten by the next block. ``rot[j]`` is
    only computed where ``need_rot[j]`` (joints with children always need it).
    """
    groups, no_rotation = _order_groups(skeleton)
    pos_cols = [skeleton.position_channel_indices(j) for j in range(skeleton.n_joints)]
    offsets = skeleton.offsets
    parents = skeleton.parents.tolist()
    need = need_rot.copy()
    need[[p for p in parents if p >= 0]] = True
    ws = _Workspace(skeleton, min(_BLOCK, max(ch.shape[0], 1)))
    for start in range(0, ch.shape[0], _BLOCK):
        frames = slice(start, min(start + _BLOCK, ch.shape[0]))
        ch_t = np.ascontiguousarray(ch[frames].T)  # (C, n)
        n = ch_t.shape[1]
        local = _local_block(skeleton, ch_t, groups, no_rotation, ws)
        rot, pos = ws.rot[..., :n], ws.pos[..., :n]
        for j, p in enumerate(parents):
            # translation from the parent: the offset (3,) and/or the position channels (3, n)
            tj: np.ndarray = offsets[j]
            if pos_cols[j].size:
                add = position_mode == "add" and p >= 0  # the root's channels are absolute
                tj = offsets[j][:, None] + ch_t[pos_cols[j]] if add else ch_t[pos_cols[j]]
            if p < 0:
                rot[j] = local[j]
                pos[j] = tj if tj.ndim == 2 else tj[:, None]
                continue
            rp = rot[p]
            # pos[j] = pos[p] + rot[p] @ t[j];  rot[j] = rot[p] @ local[j]  (frames last)
            np.einsum("ikn,k->in" if tj.ndim == 1 else "ikn,kn->in", rp, tj, out=pos[j])
            pos[j] += pos[p]
            if need[j]:
                np.einsum("ikn,kjn->ijn", rp, local[j], out=rot[j])
        yield frames, rot, pos


# ----------------------------------------------------------------------------- public API
def local_rotations(skeleton: Skeleton, channels: np.ndarray) -> np.ndarray:
    """Each joint's rotation relative to its parent, from its Euler channels.

    Parameters
    ----------
    skeleton : Skeleton
    channels : (T, C) float, degrees for rotation channels

    Returns
    -------
    (T, J, 3, 3) float64
        Identity for joints without rotation channels.

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> zxy = ("Zrotation", "Xrotation", "Yrotation")
    >>> arm = Skeleton(("Shoulder", "Elbow"), [-1, 0], [[0, 0, 0], [30, 0, 0]], (zxy, ()))
    >>> rot = local_rotations(arm, np.array([[90.0, 0, 0]]))
    >>> rot.shape
    (1, 2, 3, 3)
    >>> rot[0, 0].round(6) + 0.0  # 90 degrees about z
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    ch = _check_inputs(skeleton, channels)
    groups, no_rotation = _order_groups(skeleton)
    out = np.empty((ch.shape[0], skeleton.n_joints, 3, 3))
    ws = _Workspace(skeleton, min(_BLOCK, max(ch.shape[0], 1)))
    for start in range(0, ch.shape[0], _BLOCK):
        frames = slice(start, min(start + _BLOCK, ch.shape[0]))
        local = _local_block(skeleton, np.ascontiguousarray(ch[frames].T), groups, no_rotation, ws)
        out[frames] = np.moveaxis(local, 3, 0)
    return out


def global_transforms(
    skeleton: Skeleton, channels: np.ndarray, *, position_mode: str = "replace"
) -> tuple[np.ndarray, np.ndarray]:
    """World rotations and positions of every joint.

    Parameters
    ----------
    skeleton : Skeleton
        Hierarchy, offsets (cm) and channel layout.
    channels : (T, C) float
        Motion rows as in a BVH file: positions in cm, rotations in degrees.
    position_mode : {"add", "replace"}
        How a joint's ``X/Y/Zposition`` channels combine with its OFFSET: ``"replace"`` (default:
        ``t`` alone, as Blender and MotionBuilder read BVH; right for files such as the
        Bandai-Namco set whose non-root position channels repeat the offsets) or ``"add"``
        (``offset + t`` for non-root joints; the root always uses its channels alone, so a
        non-zero root OFFSET is not counted twice). Both give the same answer for BEAT.

    Returns
    -------
    rotations : (T, J, 3, 3) float64
        World orientation of each joint's frame (``v_world = R @ v_joint``).
    positions : (T, J, 3) float64, centimetres
        World position of each joint.

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> zxy = ("Zrotation", "Xrotation", "Yrotation")
    >>> arm = Skeleton(("Shoulder", "Elbow"), [-1, 0], [[0, 0, 0], [30, 0, 0]], (zxy, ()))
    >>> rotations, positions = global_transforms(arm, np.array([[90.0, 0, 0]]))
    >>> rotations.shape, positions.shape
    ((1, 2, 3, 3), (1, 2, 3))
    >>> positions[0, 1].round(6) + 0.0  # the elbow swung from +x to +y
    array([ 0., 30.,  0.])
    """
    ch = _check_inputs(skeleton, channels, position_mode)
    n_frames, n_joints = ch.shape[0], skeleton.n_joints
    rotations = np.empty((n_frames, n_joints, 3, 3))
    positions = np.empty((n_frames, n_joints, 3))
    need_rot = np.ones(n_joints, dtype=bool)
    for frames, rot, pos in _blocks(skeleton, ch, position_mode, need_rot):
        rotations[frames] = np.moveaxis(rot, 3, 0)
        positions[frames] = np.moveaxis(pos, 2, 0)
    return rotations, positions


def forward_kinematics(
    skeleton: Skeleton, channels: np.ndarray, *, end_sites: bool = False, position_mode: str = "replace"
) -> np.ndarray:
    """World joint positions from BVH channel rows.

    Parameters
    ----------
    skeleton : Skeleton
    channels : (T, C) float
        Motion rows (positions cm, rotations degrees, each joint's Euler order from its CHANNELS).
    end_sites : bool
        Also return the End Site positions, appended after the J joints in the order of their
        owning joints (``sorted(skeleton.end_sites)``).
    position_mode : {"add", "replace"}
        See :func:`global_transforms`.

    Returns
    -------
    (T, J, 3) float64, centimetres; (T, J + E, 3) with ``end_sites=True``.

    Examples
    --------
    A shoulder-elbow-wrist chain along +x (upper arm 30 cm, forearm 25 cm). Turning the
    shoulder 90 degrees about z swings the whole arm onto +y; turning only the elbow
    swings the forearm.

    >>> import numpy as np
    >>> from beatlite.skeleton.core import Skeleton
    >>> from beatlite.skeleton.kinematics import forward_kinematics
    >>> zxy = ("Zrotation", "Xrotation", "Yrotation")
    >>> arm = Skeleton(
    ...     names=("Shoulder", "Elbow", "Wrist"), parents=[-1, 0, 1],
    ...     offsets=[[0, 0, 0], [30, 0, 0], [25, 0, 0]], channels=(zxy, zxy, ()))
    >>> channels = np.array([[0.0, 0, 0, 0, 0, 0], [90, 0, 0, 0, 0, 0], [0, 0, 0, 90, 0, 0]])
    >>> positions = forward_kinematics(arm, channels)  # (T, J, 3) cm
    >>> positions.shape
    (3, 3, 3)
    >>> positions[0]
    array([[ 0.,  0.,  0.],
           [30.,  0.,  0.],
           [55.,  0.,  0.]])
    >>> positions[1].round(6) + 0.0  # shoulder at 90 degrees
    array([[ 0.,  0.,  0.],
           [ 0., 30.,  0.],
           [ 0., 55.,  0.]])
    >>> positions[2].round(6) + 0.0  # elbow at 90 degrees
    array([[ 0.,  0.,  0.],
           [30.,  0.,  0.],
           [30., 25.,  0.]])
    """
    ch = _check_inputs(skeleton, channels, position_mode)
    n_joints = skeleton.n_joints
    owners = np.array(sorted(skeleton.end_sites) if end_sites else [], dtype=np.int64)
    offs = np.stack([skeleton.end_sites[int(j)] for j in owners]) if owners.size else np.zeros((0, 3))
    out = np.empty((ch.shape[0], n_joints + owners.size, 3))
    need_rot = np.zeros(n_joints, dtype=bool)
    need_rot[owners] = True
    for frames, rot, pos in _blocks(skeleton, ch, position_mode, need_rot):
        out[frames, :n_joints] = np.moveaxis(pos, 2, 0)
        if owners.size:
            tips = pos[owners] + np.sum(rot[owners] * offs[:, None, :, None], axis=2)  # (E, 3, n)
            out[frames, n_joints:] = np.moveaxis(tips, 2, 0)
    return out


def rest_pose(skeleton: Skeleton, *, end_sites: bool = False) -> np.ndarray:
    """Joint positions with every channel zero: the summed offsets along each chain.

    Parameters
    ----------
    skeleton : Skeleton
    end_sites : bool
        Append End Site positions after the joints, as in :func:`forward_kinematics`.

    Returns
    -------
    (J, 3) float64, centimetres; (J + E, 3) with ``end_sites=True``.

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> chain = Skeleton(("A", "B", "C"), [-1, 0, 1], [[0, 0, 0], [0, 10, 0], [5, 0, 0]], (("Xrotation",),) * 3)
    >>> rest_pose(chain)
    array([[ 0.,  0.,  0.],
           [ 0., 10.,  0.],
           [ 5., 10.,  0.]])
    """
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    pos = np.zeros((skeleton.n_joints, 3))
    for j, p in enumerate(skeleton.parents):
        pos[j] = skeleton.offsets[j] + (pos[p] if p >= 0 else 0.0)
    if end_sites and skeleton.end_sites:
        owners = sorted(skeleton.end_sites)
        tips = np.stack([pos[j] + skeleton.end_sites[j] for j in owners])
        pos = np.concatenate([pos, tips], axis=0)
    return pos


def skeleton_extent(skeleton: Skeleton) -> float:
    """Size of the rest pose: the largest extent along x, y or z of its joints and End Sites.

    In the file's length unit: about 100-200 for a person in centimetres, 1-2 in metres.

    Examples
    --------
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> 100 < skeleton_extent(beat_skeleton()) < 250
    True
    """
    pos = rest_pose(skeleton, end_sites=True)
    return float(np.max(np.ptp(pos, axis=0))) if len(pos) else 0.0
