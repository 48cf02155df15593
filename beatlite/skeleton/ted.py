"""A TED-Expressive-style 43-joint upper body for HA2G, built from the BEAT skeleton.

TED Expressive (HA2G, CVPR 2022) describes a pose by 43 joints and 42 unit bone vectors
(HA2G §4.1; docs/reference_code.md#ted-expressive). Joint ids::

    0 spine, 1 neck, 2/3 left/right shoulder, 4/5 left/right elbow, 6/7 left/right wrist,
    8-22  left fingers  index, middle, pinky, ring, thumb (3 joints each),
    23-37 right fingers in the same order,
    38 nose, 39/40 right/left eye, 41/42 right/left ear.

BEAT joints used: spine = ``Spine3`` (upper chest), neck = ``Neck``, shoulder/elbow/wrist =
``*Arm``/``*ForeArm``/``*Hand``, finger joints = ``*Hand<Finger>1..3`` (knuckle, middle and
distal joints; for the thumb ``Thumb1..3``).

**Face landmarks.** BEAT has no face joints, so the nose, eyes and ears are fixed offsets
(:data:`HEAD_LANDMARK_OFFSETS`, centimetres) in the frame of BEAT's ``Head`` joint: they move
and turn with the head. They need the head's world rotation, which :func:`beat_to_ted43` takes
from forward kinematics when given channels, or from ``rotations``; from positions alone the
head frame is estimated (see there).

**The common space of the results tables** (every model scored as TED-43 directions and positions):
:func:`euler_to_directions` (``spine_neck_141`` Euler degrees), :func:`channels_to_directions` (full BEAT channel
rows) and :func:`directions_to_ted_positions` (directions back to positions with :func:`rest_bone_lengths`).

Taught in notebooks/06_ha2g.ipynb, sections 1 (poses as unit bone directions), 2 (the body hierarchy) and 6 (the angle pairs of the physical constraint).
"""

from __future__ import annotations

import functools

import numpy as np

from beatlite.skeleton.beat import beat_skeleton, expand_subset
from beatlite.skeleton.core import Skeleton
from beatlite.skeleton.directions import directions_to_positions, positions_to_directions
from beatlite.skeleton.kinematics import forward_kinematics, global_transforms, rest_pose

__all__ = [
    "ANGLE_PAIRS",
    "HA2G_LEVELS",
    "HEAD_LANDMARK_OFFSETS",
    "TED43_FROM_BEAT",
    "TED43_JOINTS",
    "TED_BONES",
    "TED_VECTOR_NAMES",
    "beat_to_ted43",
    "channels_to_directions",
    "directions_to_ted_positions",
    "euler_to_directions",
    "pair_angles",
    "palm_normals",
    "rest_bone_lengths",
]

_FINGERS = ("index", "middle", "pinky", "ring", "thumb")  # HA2G's finger order
_BEAT_FINGER = {"index": "Index", "middle": "Middle", "pinky": "Pinky", "ring": "Ring", "thumb": "Thumb"}


def _hand_joints(side: str) -> tuple[str, ...]:
    return tuple(f"{side}_{f}{k}" for f in _FINGERS for k in (1, 2, 3))


#: The 43 joint names, in TED Expressive order.
TED43_JOINTS: tuple[str, ...] = (
    (
        "spine",
        "neck",
        "left_shoulder",
        "right_shoulder",
        "left_elbow",
        "right_elbow",
        "left_wrist",
        "right_wrist",
    )
    + _hand_joints("left")
    + _hand_joints("right")
    + ("nose", "right_eye", "left_eye", "right_ear", "left_ear")
)

_SIDE = {"left": "Left", "right": "Right"}
_LIMB = {"shoulder": "Arm", "elbow": "ForeArm", "wrist": "Hand"}


def _beat_name(ted: str) -> str | None:
    if ted == "spine":
        return "Spine3"
    if ted == "neck":
        return "Neck"
    side, _, part = ted.partition("_")
    if side not in _SIDE:
        return None
    if part in _LIMB:
        return f"{_SIDE[side]}{_LIMB[part]}"
    if part[:-1] in _BEAT_FINGER:
        return f"{_SIDE[side]}Hand{_BEAT_FINGER[part[:-1]]}{part[-1]}"
    return None  # eyes and ears


#: For each TED joint, the BEAT joint it is (``None`` for the five head landmarks).
TED43_FROM_BEAT: tuple[str | None, ...] = tuple(_beat_name(n) for n in TED43_JOINTS)

#: Face landmarks as offsets in the BEAT ``Head`` joint's frame, centimetres (Y up, face toward +Z,
#: the character's right at -X in the rest pose). Chosen for beatlite's ~175 cm skeleton whose
#: Head joint sits at the skull base, ~19.5 cm below the top of the head.
HEAD_LANDMARK_OFFSETS: dict[str, tuple[float, float, float]] = {
    "nose": (0.0, 4.0, 11.0),
    "right_eye": (-3.2, 7.5, 8.5),
    "left_eye": (3.2, 7.5, 8.5),
    "right_ear": (-7.5, 6.0, -1.0),
    "left_ear": (7.5, 6.0, -1.0),
}


def _bone_names() -> list[tuple[str, str]]:
    """The 42 (parent, child) joint-name pairs in HA2G's direction-vector order."""
    pairs = [("spine", "neck"), ("neck", "left_shoulder"), ("neck", "right_shoulder")]
    for side in ("left", "right"):
        pairs += [(f"{side}_shoulder", f"{side}_elbow"), (f"{side}_elbow", f"{side}_wrist")]
        for f in _FINGERS:
            pairs += [
                (f"{side}_wrist", f"{side}_{f}1"),
                (f"{side}_{f}1", f"{side}_{f}2"),
                (f"{side}_{f}2", f"{side}_{f}3"),
            ]
    pairs += [
        ("neck", "nose"),
        ("nose", "right_eye"),
        ("nose", "left_eye"),
        ("right_eye", "right_ear"),
        ("left_eye", "left_ear"),
    ]
    return pairs


_J = {n: i for i, n in enumerate(TED43_JOINTS)}
#: The 42 bones as (parent, child) indices into :data:`TED43_JOINTS`, in HA2G's vector order
#: (0 spine-neck, 1/2 neck-L/R shoulder, 3/4 left upper/lower arm, 5-19 left fingers,
#: 20/21 right arm, 22-36 right fingers, 37 neck-nose, 38/39 nose-R/L eye, 40/41 eye-ear).
TED_BONES: tuple[tuple[int, int], ...] = tuple((_J[p], _J[c]) for p, c in _bone_names())

#: Names of HA2G's 44 vectors: the 42 bones (``"parent>child"``) and the two palm normals.
TED_VECTOR_NAMES: tuple[str, ...] = tuple(f"{p}>{c}" for p, c in _bone_names()) + (
    "left_palm_normal",
    "right_palm_normal",
)


def _v(parent: str, child: str) -> int:
    return TED_VECTOR_NAMES.index(f"{parent}>{child}")


def _levels() -> tuple[tuple[int, ...], ...]:
    """HA2G's six cumulative levels of vector indices, built from names (docs/reference_code.md#ha2g-levels)."""
    head = [_v("neck", "nose"), _v("nose", "right_eye"), _v("nose", "left_eye")]
    head += [_v("right_eye", "right_ear"), _v("left_eye", "left_ear")]
    torso = [_v("spine", "neck"), _v("neck", "left_shoulder"), _v("neck", "right_shoulder")]
    sides = ("left", "right")
    upper = [_v(f"{s}_shoulder", f"{s}_elbow") for s in sides]
    lower = [_v(f"{s}_elbow", f"{s}_wrist") for s in sides]
    ph1 = [_v(f"{s}_wrist", f"{s}_{f}1") for s in sides for f in _FINGERS]
    ph2 = [_v(f"{s}_{f}1", f"{s}_{f}2") for s in sides for f in _FINGERS]
    ph3 = [_v(f"{s}_{f}2", f"{s}_{f}3") for s in sides for f in _FINGERS]
    adds = [torso + head, upper, lower, ph1, ph2, ph3]
    out, acc = [], []
    for add in adds:
        acc = sorted(acc + add)
        out.append(tuple(acc))
    return tuple(out)


#: HA2G's 6 hierarchy levels (cumulative lists of vector indices): 1 torso + head (8 vectors),
#: 2 + upper arms (10), 3 + forearms (12), 4 + first phalanges (22), 5 + second (32), 6 all (42).
HA2G_LEVELS: tuple[tuple[int, ...], ...] = _levels()


def _angle_pairs() -> tuple[tuple[int, int], ...]:
    """HA2G's 41 angle pairs over the 44 vectors, built from names in the reference order."""
    pairs: list[tuple[int, int]] = []
    for side in ("left", "right"):
        if side == "left":
            pairs += [
                (_v("spine", "neck"), _v("neck", "left_shoulder")),
                (_v("spine", "neck"), _v("neck", "right_shoulder")),
                (_v("neck", "left_shoulder"), _v("left_shoulder", "left_elbow")),
                (_v("left_shoulder", "left_elbow"), _v("left_elbow", "left_wrist")),
            ]
        else:
            pairs += [
                (_v("neck", "right_shoulder"), _v("right_shoulder", "right_elbow")),
                (_v("right_shoulder", "right_elbow"), _v("right_elbow", "right_wrist")),
            ]
        # consecutive phalanges of each finger
        for f in _FINGERS:
            pairs += [
                (_v(f"{side}_wrist", f"{side}_{f}1"), _v(f"{side}_{f}1", f"{side}_{f}2")),
                (_v(f"{side}_{f}1", f"{side}_{f}2"), _v(f"{side}_{f}2", f"{side}_{f}3")),
            ]
        # spread across neighbouring finger bases: thumb-index, index-middle, middle-ring, ring-pinky
        for a, b in (("thumb", "index"), ("index", "middle"), ("middle", "ring"), ("ring", "pinky")):
            pairs.append((_v(f"{side}_wrist", f"{side}_{a}1"), _v(f"{side}_wrist", f"{side}_{b}1")))
    pairs += [
        (_v("spine", "neck"), _v("neck", "nose")),
        (_v("neck", "nose"), _v("nose", "right_eye")),
        (_v("neck", "nose"), _v("nose", "left_eye")),
        (_v("nose", "right_eye"), _v("right_eye", "right_ear")),
        (_v("nose", "left_eye"), _v("left_eye", "left_ear")),
        # forearm x palm normal
        (_v("left_elbow", "left_wrist"), TED_VECTOR_NAMES.index("left_palm_normal")),
        (_v("right_elbow", "right_wrist"), TED_VECTOR_NAMES.index("right_palm_normal")),
    ]
    return tuple(pairs)


#: HA2G's 41 pairs of vectors (indices into :data:`TED_VECTOR_NAMES`) whose angles its physical
#: constraint loss and beat-consistency score use, in the reference order.
ANGLE_PAIRS: tuple[tuple[int, int], ...] = _angle_pairs()


# --------------------------------------------------------------------------------------------
def _check_dirs(dirs: np.ndarray) -> np.ndarray:
    d = np.asarray(dirs, dtype=np.float64)
    if d.ndim >= 1 and d.shape[-1] == 126:
        d = d.reshape(d.shape[:-1] + (42, 3))  # flat bone-major 126-d vectors
    if d.ndim < 2 or d.shape[-2:] != (42, 3):
        raise ValueError(f"dirs must have shape (..., 42, 3) or (..., 126), got {d.shape}")
    return d


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n < 1e-12, 1.0, n)


def palm_normals(dirs: np.ndarray) -> np.ndarray:
    """HA2G's palm normals: left = cross(v11, v17), right = cross(v28, v34), normalised.

    v11/v28 are wrist->pinky1 and v17/v34 wrist->thumb1 of the left/right hand.

    Parameters
    ----------
    dirs : (..., 42, 3) or (..., 126) float
        Bone directions in :data:`TED_BONES` order (need not be unit).

    Returns
    -------
    (..., 2, 3) float64 unit vectors ``[left, right]`` (zero where the two vectors are parallel).

    Examples
    --------
    >>> dirs = np.zeros((42, 3))
    >>> dirs[[11, 28]] = [1, 0, 0]  # wrist -> pinky along x
    >>> dirs[[17, 34]] = [0, 1, 0]  # wrist -> thumb along y
    >>> palm_normals(dirs)
    array([[0., 0., 1.],
           [0., 0., 1.]])
    """
    d = _check_dirs(dirs)
    left = np.cross(d[..., _v("left_wrist", "left_pinky1"), :], d[..., _v("left_wrist", "left_thumb1"), :])
    right = np.cross(
        d[..., _v("right_wrist", "right_pinky1"), :], d[..., _v("right_wrist", "right_thumb1"), :]
    )
    return _unit(np.stack([left, right], axis=-2))


def pair_angles(dirs: np.ndarray) -> np.ndarray:
    """Angles of the 41 :data:`ANGLE_PAIRS` (radians, in ``[0, π]``).

    Parameters
    ----------
    dirs : (..., 42, 3) or (..., 126) float
        Bone directions (normalised here); the palm normals are appended as vectors 42 and 43.

    Returns
    -------
    (..., 41) float64 radians (HA2G divides them by π).

    Examples
    --------
    >>> dirs = np.tile([1.0, 0, 0], (42, 1))
    >>> dirs[17] = [0, 1, 0]  # palm normals exist: left pinky (x) and thumb (y) are not parallel
    >>> dirs[34] = [0, 1, 0]
    >>> angles = pair_angles(dirs)
    >>> angles.shape, ANGLE_PAIRS[0], float(angles[0])  # bones 0 and 1 are parallel
    ((41,), (0, 1), 0.0)
    >>> ANGLE_PAIRS[12], round(float(angles[12]), 6)  # bone 17 (along y) against bone 18 (along x): pi / 2
    ((17, 18), 1.570796)
    """
    d = _unit(_check_dirs(dirs))
    vecs = np.concatenate([d, palm_normals(d)], axis=-2)
    idx = np.array(ANGLE_PAIRS)
    cos = np.sum(vecs[..., idx[:, 0], :] * vecs[..., idx[:, 1], :], axis=-1)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def _head_frame_from_positions(pos: np.ndarray, names: tuple[str, ...]) -> np.ndarray:
    """(T, 3, 3) estimated Head rotation: up = Head->HeadEnd, right-to-left = shoulder line."""
    ix = {n: names.index(n) for n in ("Head", "HeadEnd", "RightArm", "LeftArm")}
    up = _unit(pos[:, ix["HeadEnd"]] - pos[:, ix["Head"]])
    lateral = pos[:, ix["LeftArm"]] - pos[:, ix["RightArm"]]  # +X in the rest pose
    x = _unit(lateral - np.sum(lateral * up, axis=-1, keepdims=True) * up)
    z = np.cross(x, up)
    return np.stack([x, up, z], axis=-1)


def beat_to_ted43(
    source: Skeleton | np.ndarray | object,
    channels: np.ndarray | None = None,
    *,
    rotations: np.ndarray | None = None,
    skeleton: Skeleton | None = None,
) -> np.ndarray:
    """TED-Expressive 43-joint positions from BEAT motion.

    Call it as any of::

        beat_to_ted43(skeleton, channels)            # BVH channel rows (T, 228)
        beat_to_ted43(motion)                        # a beatlite.io.Motion
        beat_to_ted43(positions, rotations=rots)     # from global_transforms
        beat_to_ted43(positions)                     # positions only: head frame estimated

    Parameters
    ----------
    source : Skeleton, Motion or (T, J, 3) float array
        A skeleton (then ``channels`` is required), a ``Motion``, or world joint positions in
        centimetres on a BEAT-topology skeleton (joint order of ``skeleton``, default
        :func:`beat_skeleton`).
    channels : (T, C) float, optional
        Channel rows when ``source`` is a Skeleton.
    rotations : (T, J, 3, 3) float, optional
        World joint rotations matching ``positions``. Without them the head frame is estimated
        from positions (up = Head->HeadEnd, lateral = the shoulder line), which ignores head yaw
        relative to the shoulders.
    skeleton : Skeleton, optional
        Names for ``positions`` (default the BEAT joint order).

    Returns
    -------
    (T, 43, 3) float64, centimetres, in :data:`TED43_JOINTS` order.

    Examples
    --------
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> positions = beat_to_ted43(beat_skeleton(), np.zeros((2, 228)))
    >>> positions.shape  # (T, 43, 3), cm
    (2, 43, 3)
    """
    names, pos, rotations = _source_positions(source, channels, rotations, skeleton)
    _check_ted_joints(names)
    body = [names.index(n) for n in TED43_FROM_BEAT if n is not None]
    head = names.index("Head")
    head_rot = rotations[:, head] if rotations is not None else _head_frame_from_positions(pos, names)
    offsets = np.array([HEAD_LANDMARK_OFFSETS[n] for n in TED43_JOINTS[38:]])  # (5, 3)
    face = pos[:, head, None, :] + np.einsum("tkl,ml->tmk", head_rot, offsets)
    return np.concatenate([pos[:, body], face], axis=1)


def _source_positions(
    source: Skeleton | np.ndarray | object,
    channels: np.ndarray | None,
    rotations: np.ndarray | None,
    skeleton: Skeleton | None,
) -> tuple[tuple[str, ...], np.ndarray, np.ndarray | None]:
    """The joint names, world positions (T, J, 3) cm and world rotations (T, J, 3, 3) or None
    of each way of calling :func:`beat_to_ted43`."""
    if isinstance(source, Skeleton):
        if channels is None:
            raise ValueError("beat_to_ted43(skeleton, channels): channels (T, C) is required with a Skeleton")
        rotations, pos = global_transforms(source, channels)
        return source.names, pos, rotations
    if hasattr(source, "skeleton") and hasattr(source, "channels"):
        rotations, pos = global_transforms(source.skeleton, source.channels)  # type: ignore[attr-defined]
        return source.skeleton.names, pos, rotations  # type: ignore[attr-defined]
    names = (skeleton or beat_skeleton()).names
    pos = np.asarray(source, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[1:] != (len(names), 3):
        raise ValueError(f"positions must have shape (T, {len(names)}, 3), got {pos.shape}")
    if rotations is not None:
        rotations = np.asarray(rotations, dtype=np.float64)
        if rotations.shape != pos.shape + (3,):
            raise ValueError(f"rotations must have shape {pos.shape + (3,)}, got {rotations.shape}")
    return names, pos, rotations


def _check_ted_joints(names: tuple[str, ...]) -> None:
    """``ValueError`` unless ``names`` holds every BEAT joint the TED-43 mapping and the head frame use."""
    missing = [n for n in TED43_FROM_BEAT if n is not None and n not in names] + [
        n for n in ("Head", "HeadEnd", "RightArm", "LeftArm") if n not in names
    ]
    if missing:
        raise ValueError(f"the skeleton lacks the BEAT joints {missing[:5]} needed for the TED-43 mapping")


# ------------------------------------------------------------- the common space of the results tables
@functools.cache
def rest_bone_lengths() -> np.ndarray:
    """(42,) float64 cm: TED-43 bone lengths of the BEAT rest skeleton (the common positions space of the
    results tables)."""
    ted = beat_to_ted43(rest_pose(beat_skeleton())[None])[0]
    bones = np.asarray(TED_BONES)
    lengths = np.linalg.norm(ted[bones[:, 1]] - ted[bones[:, 0]], axis=-1)
    lengths.setflags(write=False)
    return lengths


def euler_to_directions(euler: np.ndarray) -> np.ndarray:
    """TED-43 unit bone directions of ``spine_neck_141`` Euler angles.

    Parameters
    ----------
    euler : (T, 141) float, degrees
        Denormalised CaMN-layout channels; every other BEAT channel is 0 (rest), root at the origin.

    Returns
    -------
    (T, 42, 3) float64 unit vectors (the construction of ``build_windows``' ``"dirvec"``).

    Examples
    --------
    >>> dirs = euler_to_directions(np.zeros((2, 141)))
    >>> dirs.shape, np.allclose(np.linalg.norm(dirs, axis=-1), 1.0)
    ((2, 42, 3), True)
    """
    euler = np.asarray(euler, dtype=np.float64)
    if euler.ndim != 2 or euler.shape[1] != 141:
        raise ValueError(f"euler must be (T, 141) degrees, got shape {euler.shape}")
    return channels_to_directions(expand_subset(euler, "spine_neck_141"))


def channels_to_directions(channels: np.ndarray) -> np.ndarray:
    """TED-43 unit bone directions of full BEAT motion rows on beatlite's BEAT skeleton.

    Parameters
    ----------
    channels : (T, 228) float
        :func:`beatlite.skeleton.beat.beat_skeleton` channel rows (root position cm, rotations degrees,
        ``Xrotation Yrotation Zrotation``).

    Returns
    -------
    (T, 42, 3) float64 unit vectors: forward kinematics -> ``beat_to_ted43`` -> bone directions.

    Examples
    --------
    >>> dirs = channels_to_directions(np.zeros((3, 228)))
    >>> dirs.shape, np.allclose(np.linalg.norm(dirs, axis=-1), 1.0)
    ((3, 42, 3), True)
    >>> np.allclose(dirs, euler_to_directions(np.zeros((3, 141))))  # rest pose either way
    True
    """
    positions = forward_kinematics(beat_skeleton(), np.asarray(channels, dtype=np.float64))
    return positions_to_directions(beat_to_ted43(positions), np.asarray(TED_BONES))


def directions_to_ted_positions(directions: np.ndarray, lengths: np.ndarray | None = None) -> np.ndarray:
    """(T, 42, 3) unit directions -> (T, 43, 3) cm TED-43 positions, root at the origin.

    ``lengths`` (42,) cm default to :func:`rest_bone_lengths` (the common positions space).

    Examples
    --------
    >>> dirs = euler_to_directions(np.zeros((1, 141)))
    >>> positions = directions_to_ted_positions(dirs)
    >>> positions.shape, positions[0, 0].tolist()  # root at the origin
    ((1, 43, 3), [0.0, 0.0, 0.0])
    >>> parent, child = np.asarray(TED_BONES).T
    >>> lengths = np.linalg.norm(positions[0, child] - positions[0, parent], axis=-1)
    >>> np.allclose(lengths, rest_bone_lengths())
    True
    """
    lengths = rest_bone_lengths() if lengths is None else lengths
    return directions_to_positions(directions, np.asarray(TED_BONES), lengths, np.zeros(3))
