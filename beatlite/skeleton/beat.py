"""The BEAT 75-joint skeleton, its named joint subsets and the CaMN 141-d assembly.

:func:`beat_skeleton` reproduces the *topology* of the real BEAT BVH header exactly (joint names,
depth-first order, parents, channels, the 13 End Sites), but the bone offsets are beatlite's own
anthropometric values for a ~175 cm adult, written by hand below (they are not BEAT's numbers).

Rest pose (all channels zero): Y up, the figure faces +Z, its right side is at -X, arms are
horizontal along ±X with palms down and the thumbs angled forward (+Z). Like real BEAT, the root
``Hips`` has a zero OFFSET, so in the rest pose the hips sit at the origin and the floor (the
toe joints) is at ``y = -HIPS_HEIGHT_CM``.

The BEAT Euler values are degrees with CHANNELS ``Xrotation Yrotation Zrotation`` (intrinsic,
``R = Rx @ Ry @ Rz``); ``Hips`` also has ``Xposition Yposition Zposition`` (centimetres) first.

Taught in notebooks/01_beat_formats.ipynb, sections 2 (the BVH skeleton) and 7 (joint subsets).
"""

from __future__ import annotations

import numpy as np

from beatlite.skeleton.core import POSITION_CHANNELS, ROTATION_CHANNELS, Skeleton

__all__ = [
    "BEAT_N_CHANNELS",
    "BEAT_N_JOINTS",
    "HIPS_HEIGHT_CM",
    "JOINT_SUBSETS",
    "beat_skeleton",
    "camn_assemble",
    "camn_split",
    "expand_subset",
    "subset_columns",
]

BEAT_N_JOINTS = 75
BEAT_N_CHANNELS = 228
#: Height of the hips joint above the floor (the lowest toe joints) in the rest pose, cm.
HIPS_HEIGHT_CM = 95.0

# --------------------------------------------------------------------------------------------
# The table: (joint, parent, offset in cm, End Site offset or None), depth-first, as in BEAT.
# Centre line and right side are written out; the left side is the mirror image (x -> -x).
# Right-side finger layout in the rest pose: fingers point along -X, palm faces -Y, the index
# finger is towards +Z (front), ring and pinky towards -Z, the thumb angles forward and down.
# --------------------------------------------------------------------------------------------
_Row = tuple[str, str | None, tuple[float, float, float], tuple[float, float, float] | None]

_SPINE_AND_HEAD: list[_Row] = [
    ("Hips", None, (0.0, 0.0, 0.0), None),
    ("Spine", "Hips", (0.0, 6.5, -2.0), None),  # lumbar, leaning back slightly
    ("Spine1", "Spine", (0.0, 11.0, -1.5), None),
    ("Spine2", "Spine1", (0.0, 11.0, -0.5), None),
    ("Spine3", "Spine2", (0.0, 11.0, 0.5), None),  # upper chest, y = 39.5
    ("Neck", "Spine3", (0.0, 14.0, 1.5), None),  # base of the skull column
    ("Neck1", "Neck", (0.0, 3.5, 0.3), None),
    ("Head", "Neck1", (0.0, 3.5, 0.5), None),  # y = 60.5
    ("HeadEnd", "Head", (0.0, 10.0, 0.0), (0.0, 9.5, 0.0)),  # End Site = top of the skull, y = 80
]

# Right arm: the chain from Spine3; the shoulders start at the upper chest.
_RIGHT_ARM: list[_Row] = [
    ("RightShoulder", "Spine3", (-3.0, 10.0, 3.0), None),  # clavicle root, y = 49.5
    ("RightArm", "RightShoulder", (-15.5, 0.0, 0.0), None),  # shoulder joint
    ("RightForeArm", "RightArm", (-28.5, 0.0, 0.0), None),  # elbow: upper arm 28.5 cm
    ("RightHand", "RightForeArm", (-25.0, 0.0, 0.0), None),  # wrist: forearm 25 cm
    # middle finger: metacarpal, proximal, middle, distal phalanx, tip
    ("RightHandMiddle1", "RightHand", (-9.0, 0.0, 0.0), None),
    ("RightHandMiddle2", "RightHandMiddle1", (-4.6, 0.0, 0.0), None),
    ("RightHandMiddle3", "RightHandMiddle2", (-3.0, 0.0, 0.0), None),
    ("RightHandMiddle4", "RightHandMiddle3", (-2.0, 0.0, 0.0), (-1.8, 0.0, 0.0)),
    # ring finger (its carpal joint also carries the pinky), spread slightly backwards
    ("RightHandRing", "RightHand", (-0.3, -0.2, -0.9), None),
    ("RightHandRing1", "RightHandRing", (-8.0, 0.0, -1.0), None),
    ("RightHandRing2", "RightHandRing1", (-4.3, 0.0, -0.5), None),
    ("RightHandRing3", "RightHandRing2", (-2.9, 0.0, -0.35), None),
    ("RightHandRing4", "RightHandRing3", (-1.9, 0.0, -0.2), (-1.7, 0.0, -0.2)),
    ("RightHandPinky", "RightHandRing", (-0.2, -0.2, -0.9), None),
    ("RightHandPinky1", "RightHandPinky", (-6.6, 0.0, -1.6), None),
    ("RightHandPinky2", "RightHandPinky1", (-3.5, 0.0, -0.8), None),
    ("RightHandPinky3", "RightHandPinky2", (-2.3, 0.0, -0.5), None),
    ("RightHandPinky4", "RightHandPinky3", (-1.7, 0.0, -0.4), (-1.5, 0.0, -0.35)),
    # index finger (its carpal joint also carries the thumb), spread slightly forwards
    ("RightHandIndex", "RightHand", (-0.3, -0.2, 0.9), None),
    ("RightHandIndex1", "RightHandIndex", (-8.7, 0.0, 1.0), None),
    ("RightHandIndex2", "RightHandIndex1", (-4.5, 0.0, 0.5), None),
    ("RightHandIndex3", "RightHandIndex2", (-2.8, 0.0, 0.3), None),
    ("RightHandIndex4", "RightHandIndex3", (-1.8, 0.0, 0.2), (-1.6, 0.0, 0.2)),
    # thumb: about 33 degrees forward of the finger direction, slightly below the palm
    ("RightHandThumb1", "RightHandIndex", (-0.5, -0.8, 1.2), None),
    ("RightHandThumb2", "RightHandThumb1", (-4.6, -0.6, 3.0), None),
    ("RightHandThumb3", "RightHandThumb2", (-2.9, -0.3, 2.0), None),
    ("RightHandThumb4", "RightHandThumb3", (-1.8, -0.2, 1.3), (-1.6, -0.1, 1.1)),
]

_RIGHT_LEG: list[_Row] = [
    ("RightUpLeg", "Hips", (-9.0, -2.0, 0.0), None),  # hip joint
    ("RightLeg", "RightUpLeg", (0.0, -43.5, 0.0), None),  # knee: thigh 43.5 cm
    ("RightFoot", "RightLeg", (0.0, -42.0, 0.0), None),  # ankle: shank 42 cm, y = -87.5
    ("RightForeFoot", "RightFoot", (0.0, -3.0, 0.5), None),
    ("RightToeBase", "RightForeFoot", (0.0, -4.5, 9.5), None),  # ball of the foot, y = -95 (floor)
    ("RightToeBaseEnd", "RightToeBase", (0.0, 0.0, 11.0), (0.0, 0.0, 3.0)),
]


def _mirror(rows: list[_Row]) -> list[_Row]:
    """The left-side rows: ``Right`` -> ``Left`` in names and x -> -x in offsets."""

    def flip(v: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
        return None if v is None else (-v[0], v[1], v[2])

    def rename(name: str | None) -> str | None:
        return None if name is None else name.replace("Right", "Left")

    return [(rename(n), rename(p), flip(o), flip(e)) for n, p, o, e in rows]  # type: ignore[misc]


_TABLE: list[_Row] = _SPINE_AND_HEAD + _RIGHT_ARM + _mirror(_RIGHT_ARM) + _RIGHT_LEG + _mirror(_RIGHT_LEG)


def beat_skeleton() -> Skeleton:
    """The 75-joint, 228-channel BEAT skeleton with beatlite's own offsets.

    Names, depth-first order, parents, channel layout and End Sites are identical to the real
    BEAT BVH header; offsets are hand-written anthropometric values (centimetres, see the module
    docstring). A new object is built on each call.

    Returns
    -------
    Skeleton
        ``n_joints == 75``, ``n_channels == 228``, 13 End Sites (HeadEnd, ten finger ``*4``
        tips, two ``*ToeBaseEnd``). Hips: ``Xposition Yposition Zposition Xrotation Yrotation
        Zrotation``; every other joint ``Xrotation Yrotation Zrotation``.

    Examples
    --------
    >>> skel = beat_skeleton()
    >>> skel.n_joints, skel.n_channels, len(skel.end_sites)
    (75, 228, 13)
    >>> skel.names[0], skel.channels[0][:3]
    ('Hips', ('Xposition', 'Yposition', 'Zposition'))
    """
    names = [row[0] for row in _TABLE]
    index = {n: i for i, n in enumerate(names)}
    parents = np.array([-1 if p is None else index[p] for _, p, _, _ in _TABLE], dtype=np.int64)
    offsets = np.array([o for _, _, o, _ in _TABLE], dtype=np.float64)
    channels = [
        POSITION_CHANNELS + ROTATION_CHANNELS if p is None else ROTATION_CHANNELS for _, p, _, _ in _TABLE
    ]
    end_sites = {i: np.array(e, dtype=np.float64) for i, (_, _, _, e) in enumerate(_TABLE) if e is not None}
    return Skeleton(
        names=tuple(names), parents=parents, offsets=offsets, channels=channels, end_sites=end_sites
    )


# --------------------------------------------------------------------------------------------
# Named subsets (built from names; never magic indices)
# --------------------------------------------------------------------------------------------
_FINGERS = ("Middle", "Ring", "Pinky", "Index")


def _hand_19(side: str) -> tuple[str, ...]:
    """The wrist and 18 finger joints of one side, in the reference (depth-first) order.

    ``Hand, Middle1-3, Ring, Ring1-3, Pinky, Pinky1-3, Index, Index1-3, Thumb1-3``: the
    ``*4`` tip joints are excluded.
    """
    out = [f"{side}Hand", f"{side}HandMiddle1", f"{side}HandMiddle2", f"{side}HandMiddle3"]
    for finger in ("Ring", "Pinky", "Index"):
        out += [f"{side}Hand{finger}"] + [f"{side}Hand{finger}{k}" for k in (1, 2, 3)]
    out += [f"{side}HandThumb{k}" for k in (1, 2, 3)]
    return tuple(out)


def _arm_3(side: str) -> tuple[str, ...]:
    return (f"{side}Shoulder", f"{side}Arm", f"{side}ForeArm")


_SPINE_NECK = ("Spine", "Neck", "Neck1")
_LEG_WORDS = ("UpLeg", "Leg", "Foot", "Toe")
_ALL_NAMES = tuple(row[0] for row in _TABLE)

#: Joint subsets of the BEAT skeleton, each a tuple of joint names in a fixed order.
#:
#: - ``"body27"``: the 9 CaMN body joints (27 values): Spine, Neck, Neck1, then the right and
#:   left Shoulder, Arm, ForeArm (reference ``beat_27``).
#: - ``"hands114"``: the 38 CaMN hand joints (114 values): right wrist + 18 finger joints, then
#:   the left ones, each in the order of ``spine_neck_141``.
#: - ``"spine_neck_141"``: the 47 joints (141 values) of the reference ``spine_neck_141``:
#:   spine/neck (3), right arm (3), right hand (19), left arm (3), left hand (19).
#: - ``"upper_body"``: every joint except the legs (Hips included), 63 joints.
#: - ``"fingers"``: every finger joint, tips included, wrists excluded, 46 joints.
JOINT_SUBSETS: dict[str, tuple[str, ...]] = {
    "body27": _SPINE_NECK + _arm_3("Right") + _arm_3("Left"),
    "hands114": _hand_19("Right") + _hand_19("Left"),
    "spine_neck_141": _SPINE_NECK + _arm_3("Right") + _hand_19("Right") + _arm_3("Left") + _hand_19("Left"),
    "upper_body": tuple(n for n in _ALL_NAMES if not any(w in n for w in _LEG_WORDS)),
    "fingers": tuple(n for n in _ALL_NAMES if "Hand" in n and not n.endswith("Hand")),
}


def _subset_names(subset_name: str) -> tuple[str, ...]:
    if not isinstance(subset_name, str) or subset_name not in JOINT_SUBSETS:
        raise ValueError(f"subset_name must be one of {sorted(JOINT_SUBSETS)}, got {subset_name!r}")
    return JOINT_SUBSETS[subset_name]


def subset_columns(skeleton: Skeleton, subset_name: str) -> np.ndarray:
    """Channel columns of a named subset's rotation channels.

    Parameters
    ----------
    skeleton : Skeleton
        A skeleton that has every joint of the subset (e.g. :func:`beat_skeleton` or one read
        from a BEAT BVH file).
    subset_name : str
        A key of :data:`JOINT_SUBSETS`.

    Returns
    -------
    (3K,) int64
        For each of the K joints in subset order, the columns of its three rotation channels
        in file order (``X, Y, Z`` for BEAT). ``motion.channels[:, cols]`` is the subset's
        (T, 3K) Euler-degree array, e.g. the 141-d CaMN pose for ``"spine_neck_141"``.

    Examples
    --------
    >>> cols = subset_columns(beat_skeleton(), "spine_neck_141")
    >>> cols.shape  # 47 joints, 3 rotation channels each
    (141,)
    """
    names = _subset_names(subset_name)
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    return skeleton.subset_channels(names)


def expand_subset(
    values: np.ndarray,
    subset_name: str,
    skeleton: Skeleton | None = None,
    fill: np.ndarray | None = None,
) -> np.ndarray:
    """Put a subset's Euler values back into full channel rows.

    Turns, e.g., a (T, 141) model output into a (T, 228) BEAT motion that a BVH writer or a
    plot can use: the subset's rotation columns get ``values``, every other channel comes
    from ``fill`` (or is 0: rest pose, root at the origin).

    Parameters
    ----------
    values : (T, 3K) or (3K,) float, degrees
        The subset's channels in :func:`subset_columns` order.
    subset_name : str
        A key of :data:`JOINT_SUBSETS`.
    skeleton : Skeleton, optional
        Channel layout (default :func:`beat_skeleton`).
    fill : (T, C) or (C,) float, optional
        Values for the other channels (broadcast over frames if 1-D); not modified.

    Returns
    -------
    (T, C) float64 (C = 228 for BEAT); (1, C) for 1-D ``values``.

    Examples
    --------
    >>> rows = expand_subset(np.ones((2, 141)), "spine_neck_141")
    >>> rows.shape
    (2, 228)
    >>> int(rows.sum())  # the 141 subset channels are 1, every other channel 0
    282
    """
    skel = beat_skeleton() if skeleton is None else skeleton
    cols = subset_columns(skel, subset_name)
    vals = np.asarray(values, dtype=np.float64)
    if vals.ndim == 1:
        vals = vals[None]
    if vals.ndim != 2 or vals.shape[1] != cols.size:
        raise ValueError(
            f"values must be (T, {cols.size}) for subset {subset_name!r}, got {np.shape(values)}"
        )
    n_frames, n_ch = vals.shape[0], skel.n_channels
    if fill is None:
        out = np.zeros((n_frames, n_ch))
    else:
        f = np.asarray(fill, dtype=np.float64)
        if f.shape not in ((n_ch,), (n_frames, n_ch)):
            raise ValueError(f"fill must be ({n_ch},) or ({n_frames}, {n_ch}), got {f.shape}")
        out = np.array(np.broadcast_to(f, (n_frames, n_ch)))
    out[:, cols] = vals
    return out


# --------------------------------------------------------------------------------------------
# CaMN output assembly (reference camn.py: body 27 + hands 114 -> 141)
# --------------------------------------------------------------------------------------------
def _check_last(x: np.ndarray, n: int, name: str) -> np.ndarray:
    arr = np.asarray(x)
    if arr.ndim < 1 or arr.shape[-1] != n:
        raise ValueError(f"{name} must have shape (..., {n}), got {np.shape(x)}")
    return arr


def camn_assemble(body27: np.ndarray, hands114: np.ndarray) -> np.ndarray:
    """Assemble CaMN's body and hands outputs into the 141-d ``spine_neck_141`` vector.

    Implements the reference: ``out[0:18] = body[0:18]`` (spine, neck, right arm),
    ``out[18:75] = hands[0:57]`` (right hand), ``out[75:84] = body[18:27]`` (left arm),
    ``out[84:141] = hands[57:114]`` (left hand).

    Parameters
    ----------
    body27 : (..., 27) array
        Values of ``JOINT_SUBSETS["body27"]``.
    hands114 : (..., 114) array
        Values of ``JOINT_SUBSETS["hands114"]``; same leading shape as ``body27``.

    Returns
    -------
    (..., 141) array in ``JOINT_SUBSETS["spine_neck_141"]`` order (dtype of the inputs' result type).

    Examples
    --------
    >>> body, hands = np.zeros(27), np.ones(114)
    >>> pose = camn_assemble(body, hands)
    >>> pose.shape, int(pose[:18].sum()), int(pose[18:75].sum())
    ((141,), 0, 57)
    """
    body = _check_last(body27, 27, "body27")
    hands = _check_last(hands114, 114, "hands114")
    if body.shape[:-1] != hands.shape[:-1]:
        raise ValueError(f"body27 {body.shape} and hands114 {hands.shape} have different leading shapes")
    return np.concatenate([body[..., 0:18], hands[..., 0:57], body[..., 18:27], hands[..., 57:114]], axis=-1)


def camn_split(pose141: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`camn_assemble`.

    Parameters
    ----------
    pose141 : (..., 141) array in ``spine_neck_141`` order.

    Returns
    -------
    body27 : (..., 27) array
    hands114 : (..., 114) array

    Examples
    --------
    >>> pose = np.arange(141.0)
    >>> body, hands = camn_split(pose)
    >>> body.shape, hands.shape
    ((27,), (114,))
    >>> bool(np.array_equal(camn_assemble(body, hands), pose))
    True
    """
    x = _check_last(pose141, 141, "pose141")
    body = np.concatenate([x[..., 0:18], x[..., 75:84]], axis=-1)
    hands = np.concatenate([x[..., 18:75], x[..., 84:141]], axis=-1)
    return body, hands
