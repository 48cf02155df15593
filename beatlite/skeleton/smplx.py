"""The SMPL-X body of BEAT2: its 55 joints, a rest skeleton, forward kinematics, and retargeting to and from BEAT.

BEAT2 (Liu et al., EMAGE, CVPR 2024) re-released BEAT's speakers as SMPL-X parameters (Pavlakos et al., CVPR
2019): per frame, the axis-angle rotation of each of 55 joints relative to its parent (:data:`SMPLX_JOINTS`:
pelvis and 21 body joints, jaw, two eyes, 15 + 15 hand joints), a root translation in metres, and body-shape
and face parameters that only the SMPL-X *body model* turns into a mesh (read by :mod:`beatlite.io.smplx`).
Rotations alone need no body model (:func:`rot6d_features`, :func:`angular_speed`); joint positions need the
rest skeleton, an :class:`SMPLXRest`:

* :func:`rest_from_model`: the user's own SMPL-X model file (``SMPLX_NEUTRAL.npz`` etc., read with
  ``allow_pickle=False``): ``J = J_regressor @ (v_template + shapedirs @ [betas, expressions])``, the joints
  the ``smplx`` package computes (checked against it in ``tests/test_smplx.py`` when it is installed).
* :func:`approximate_rest`: shipped with beatlite. It is **not** SMPL-X's skeleton: every joint that has a
  BEAT counterpart (:data:`BEAT_COUNTERPARTS`) sits where beatlite's BEAT skeleton
  (:func:`beatlite.skeleton.beat.beat_skeleton`, a ~175 cm adult) has it, in metres; jaw and eyes are placed by
  hand from the head. Bone *directions* at rest therefore equal BEAT's, so rotations move between the worlds
  without rest alignment, and proportions are a generic adult's. How far its joints are from a real SMPL-X
  model's was not measured (beatlite has no SMPL-X model file); use :func:`rest_from_model` where it matters.

Retargeting (:func:`smplx_to_beat`, :func:`beat_to_smplx`) maps each SMPL-X joint to a BEAT joint. A joint's
world rotation is carried over through a rest alignment ``M`` (the smallest rotation taking the SMPL-X rest
bone onto the BEAT rest bone; the identity for :func:`approximate_rest`); from BEAT to SMPL-X, it is then turned
so that its bone points exactly where BEAT's chain of joints points (SMPL-X has fewer spine, neck and foot
joints; BEAT's in-between joints are folded into the bone). Joints without a counterpart keep their parent's
world rotation. :func:`bone_direction_errors` measures what is lost, in degrees per bone.

Coordinates are shared: Y up, the body facing +Z, its left side at +X (BEAT's and SMPL-X's convention).

Taught in notebooks/01_beat_formats.ipynb, section 12 (BEAT and BEAT2 side by side: 12.2 the 55 joints, 12.3 rot6d,
12.5 the rest skeleton, 12.6 retargeting and its bone-direction errors).
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np

from beatlite.skeleton.core import POSITION_CHANNELS, ROTATION_CHANNELS, Skeleton
from beatlite.skeleton.rotations import axis_angle_to_matrix, matrix_to_6d, matrix_to_axis_angle

__all__ = [
    "BEAT_COUNTERPARTS",
    "DEPTH_FIRST",
    "SMPLX_JOINTS",
    "SMPLX_N_JOINTS",
    "SMPLX_PARENTS",
    "SMPLXRest",
    "angular_speed",
    "approximate_rest",
    "beat_to_smplx",
    "bone_direction_errors",
    "local_to_global",
    "rest_from_model",
    "rot6d_features",
    "smplx_forward_kinematics",
    "smplx_skeleton_motion",
    "smplx_to_beat",
]

_FINGERS = ("index", "middle", "pinky", "ring", "thumb")  # SMPL-X's finger order
SMPLX_JOINTS: tuple[str, ...] = (
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2", "left_ankle",
    "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar", "right_collar", "head",
    "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    "jaw", "left_eye_smplhf", "right_eye_smplhf",
    *(f"{side}_{finger}{k}" for side in ("left", "right") for finger in _FINGERS for k in (1, 2, 3)),
)  # fmt: skip
"""The 55 joints of SMPL-X in the order of BEAT2's ``poses`` (``poses[:, 3*j:3*j+3]`` is joint ``j``)."""

SMPLX_N_JOINTS = 55

SMPLX_PARENTS: np.ndarray = np.array(
    [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 15, 15, 15]
    + [wrist if k == 0 else -2 for wrist in (20, 21) for _ in _FINGERS for k in range(3)],
    dtype=np.int64,
)
_fill = np.flatnonzero(SMPLX_PARENTS == -2)
SMPLX_PARENTS[_fill] = _fill - 1  # a finger's 2nd and 3rd joints hang from the joint before them
SMPLX_PARENTS.setflags(write=False)
"""(55,) int64: each joint's parent (the SMPL-X ``kintree_table``), ``-1`` for the pelvis."""


def _depth_first() -> np.ndarray:
    order, stack = [], [0]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(np.flatnonzero(SMPLX_PARENTS == j).tolist()))
    return np.array(order, dtype=np.int64)


DEPTH_FIRST: np.ndarray = _depth_first()
"""(55,) int64: SMPL-X's joints in depth-first order (children in index order), the order a BVH file needs."""

_BEAT_FINGER = {"index": "Index", "middle": "Middle", "pinky": "Pinky", "ring": "Ring", "thumb": "Thumb"}
BEAT_COUNTERPARTS: dict[str, str] = {
    "pelvis": "Hips", "spine1": "Spine", "spine2": "Spine2", "spine3": "Spine3", "neck": "Neck", "head": "Head",
    **{f"{s}_{k}": f"{S}{v}" for s, S in (("left", "Left"), ("right", "Right")) for k, v in (
        ("hip", "UpLeg"), ("knee", "Leg"), ("ankle", "Foot"), ("foot", "ToeBase"), ("collar", "Shoulder"),
        ("shoulder", "Arm"), ("elbow", "ForeArm"), ("wrist", "Hand"))},
    **{f"{s}_{f}{k}": f"{S}Hand{_BEAT_FINGER[f]}{k}" for s, S in (("left", "Left"), ("right", "Right"))
       for f in _FINGERS for k in (1, 2, 3)},
}  # fmt: skip
"""SMPL-X joint -> BEAT joint (52 of 55: jaw and eyes have none; BEAT's Spine1, Neck1, finger bases, ForeFoot
and end joints have no SMPL-X counterpart)."""

#: The child whose bone a joint's rotation is aligned to when it has several (the others: see bone errors).
_PRIMARY_CHILD = {
    "pelvis": "spine1",
    "spine3": "neck",
    "left_wrist": "left_middle1",
    "right_wrist": "right_middle1",
}


@dataclasses.dataclass(frozen=True)
class SMPLXRest:
    """Rest (zero-pose) joint positions of an SMPL-X body: all that forward kinematics needs.

    Attributes
    ----------
    joints : (55, 3) float64, metres
        Joint positions with every rotation zero and no translation (the pelvis is where the model puts it).
    source : str
        Where they come from (``"approximate: ..."`` or the model file and its shape parameters).
    hand_mean : (2, 15, 3) float64 or None
        The model's mean hand pose (left, right; axis-angle), added to BEAT2's finger rotations as the
        ``smplx`` package does by default (``flat_hand_mean=False``); None: finger rotations are absolute.

    Examples
    --------
    >>> rest = approximate_rest()
    >>> rest.joints.shape, rest.offsets()[SMPLX_JOINTS.index("left_knee")].round(3).tolist()
    ((55, 3), [0.0, -0.435, 0.0])
    """

    joints: np.ndarray
    source: str
    hand_mean: np.ndarray | None = None

    def __post_init__(self) -> None:
        joints = np.asarray(self.joints, dtype=np.float64)
        if joints.shape != (SMPLX_N_JOINTS, 3) or not np.isfinite(joints).all():
            raise ValueError(f"SMPLXRest: joints must be finite (55, 3) metres, got {joints.shape}")
        object.__setattr__(self, "joints", joints)
        if self.hand_mean is not None:
            object.__setattr__(
                self, "hand_mean", np.asarray(self.hand_mean, dtype=np.float64).reshape(2, 15, 3)
            )

    def offsets(self) -> np.ndarray:
        """(55, 3) float64 metres: each joint's position relative to its parent (the pelvis's own position)."""
        parent = np.where(SMPLX_PARENTS >= 0, SMPLX_PARENTS, 0)
        return self.joints - np.where((SMPLX_PARENTS >= 0)[:, None], self.joints[parent], 0.0)

    def skeleton(self) -> Skeleton:
        """A BVH :class:`~beatlite.skeleton.core.Skeleton` of this body (offsets in cm, ``XYZ`` Euler channels,
        root position channels), for :func:`beatlite.io.write_bvh` (e.g. to open an SMPL-X motion in Blender).

        Its joints are in depth-first order, as BVH requires (``skeleton.names[k]`` is
        ``SMPLX_JOINTS[DEPTH_FIRST[k]]``), not in SMPL-X's order."""
        inverse = np.argsort(DEPTH_FIRST)
        parents = np.array([-1 if p < 0 else inverse[p] for p in SMPLX_PARENTS[DEPTH_FIRST]], dtype=np.int64)
        channels = ((*POSITION_CHANNELS, *ROTATION_CHANNELS),) + (ROTATION_CHANNELS,) * (SMPLX_N_JOINTS - 1)
        names = tuple(SMPLX_JOINTS[j] for j in DEPTH_FIRST)
        return Skeleton(names, parents, 100.0 * self.offsets()[DEPTH_FIRST], channels)


def _beat_rest_m(beat: Skeleton | None = None) -> tuple[Skeleton, np.ndarray]:
    """A BEAT skeleton (default beatlite's) and its rest joint positions in metres."""
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.kinematics import rest_pose

    beat = beat_skeleton() if beat is None else beat
    return beat, rest_pose(beat) / 100.0


def approximate_rest() -> SMPLXRest:
    """The rest skeleton beatlite ships: BEAT's joint positions under SMPL-X's names (see the module docstring).

    Returns
    -------
    SMPLXRest
        Joints in metres, pelvis at the origin, floor at ``-HIPS_HEIGHT_CM / 100``; ``hand_mean`` None.

    Examples
    --------
    >>> rest = approximate_rest()
    >>> rest.joints[SMPLX_JOINTS.index("pelvis")].tolist(), rest.source.split(":")[0]
    ([0.0, 0.0, 0.0], 'approximate')
    """
    beat, pos = _beat_rest_m()
    joints = np.zeros((SMPLX_N_JOINTS, 3))
    for j, name in enumerate(SMPLX_JOINTS):
        if name in BEAT_COUNTERPARTS:
            joints[j] = pos[beat.index(BEAT_COUNTERPARTS[name])]
    head = joints[SMPLX_JOINTS.index("head")]
    joints[SMPLX_JOINTS.index("jaw")] = head + (0.0, -0.02, 0.03)  # beatlite's own placement (no BEAT joint)
    joints[SMPLX_JOINTS.index("left_eye_smplhf")] = head + (0.032, 0.045, 0.075)
    joints[SMPLX_JOINTS.index("right_eye_smplhf")] = head + (-0.032, 0.045, 0.075)
    return SMPLXRest(joints, "approximate: beatlite's BEAT skeleton under SMPL-X joint names (not SMPL-X's)")


def rest_from_model(
    model_path: str | os.PathLike[str], betas: np.ndarray | None = None, expressions: np.ndarray | None = None
) -> SMPLXRest:
    """The rest joints of the user's SMPL-X model file for a body shape, as the ``smplx`` package computes them.

    Parameters
    ----------
    model_path : str or PathLike
        An SMPL-X model ``.npz`` (e.g. ``SMPLX_NEUTRAL_2020.npz``, from https://smpl-x.is.tue.mpg.de after
        accepting its licence; beatlite ships none). Read with ``allow_pickle=False``: only ``v_template``,
        ``shapedirs``, ``J_regressor`` (dense), ``kintree_table`` and, if present, ``hands_meanl``/``hands_meanr``.
    betas : (B,) float, optional
        Shape parameters (BEAT2's ``betas``, B <= 300); default zeros.
    expressions : (E,) float, optional
        Expression parameters of the frame (E <= 100; they move the joints by millimetres); default zeros.

    Returns
    -------
    SMPLXRest
        ``J_regressor @ (v_template + shapedirs[..., :B] @ betas + shapedirs[..., 300:300+E] @ expressions)``.

    Raises
    ------
    FormatError
        Not an npz, a missing or pickled key, shapes that do not fit, or a kintree other than SMPL-X's.

    Examples
    --------
    A toy "model" whose 55 vertices are the joints of :func:`approximate_rest` (a real file has 10,475):

    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "SMPLX_TOY.npz"
    >>> joints = approximate_rest().joints
    >>> np.savez(path, v_template=joints, shapedirs=np.zeros((55, 3, 400)), J_regressor=np.eye(55),
    ...          kintree_table=np.stack([SMPLX_PARENTS, np.arange(55)]))
    >>> rest = rest_from_model(path)
    >>> bool(np.allclose(rest.joints, joints)), rest.source, rest.hand_mean is None
    (True, 'model file SMPLX_TOY.npz (betas zero)', True)
    >>> tmp.cleanup()
    """
    from beatlite.io.errors import FormatError

    path = Path(model_path)
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {
                k: z[k] for k in ("v_template", "shapedirs", "J_regressor", "kintree_table") if k in z.files
            }
            hands = [z[k] for k in ("hands_meanl", "hands_meanr") if k in z.files]
    except (ValueError, OSError, EOFError) as exc:
        raise FormatError(path, f"not a readable SMPL-X model npz without pickles ({exc})") from None
    missing = [k for k in ("v_template", "shapedirs", "J_regressor", "kintree_table") if k not in data]
    if missing:
        raise FormatError(path, f"not an SMPL-X model: no {', '.join(missing)}", field=missing[0])
    v, dirs, reg = (np.asarray(data[k], dtype=np.float64) for k in ("v_template", "shapedirs", "J_regressor"))
    if (
        v.ndim != 2
        or v.shape[1] != 3
        or dirs.shape[:2] != v.shape
        or reg.shape != (SMPLX_N_JOINTS, v.shape[0])
    ):
        raise FormatError(path, f"shapes do not fit SMPL-X: v_template {v.shape}, shapedirs {dirs.shape}, "
                                f"J_regressor {reg.shape}", field="J_regressor")  # fmt: skip
    parents = np.asarray(data["kintree_table"])[0, :SMPLX_N_JOINTS].astype(np.int64)
    parents[0] = -1
    if not np.array_equal(parents, SMPLX_PARENTS):
        raise FormatError(path, "kintree_table is not SMPL-X's 55-joint tree", field="kintree_table")
    coeffs = np.zeros(dirs.shape[2])
    for values, start, name in ((betas, 0, "betas"), (expressions, 300, "expressions")):
        if values is None:
            continue
        values = np.asarray(values, dtype=np.float64).ravel()
        if start + values.size > dirs.shape[2] or (start == 0 and values.size > 300):
            raise ValueError(f"rest_from_model: {values.size} {name} do not fit shapedirs {dirs.shape}")
        coeffs[start : start + values.size] = values
    joints = reg @ (v + dirs @ coeffs)
    mean = np.stack(hands).reshape(2, 15, 3) if len(hands) == 2 else None
    return SMPLXRest(
        joints, f"model file {path.name} (betas {'given' if betas is not None else 'zero'})", mean
    )


def _full_local(poses: np.ndarray, rest: SMPLXRest) -> np.ndarray:
    """(T, 55, 3, 3) local rotations, the model's mean hand pose added to the fingers."""
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (SMPLX_N_JOINTS, 3):
        raise ValueError(f"poses must be (T, 55, 3) axis-angle radians, got {p.shape}")
    if rest.hand_mean is not None:
        p = p.copy()
        p[:, 25:40] += rest.hand_mean[0]
        p[:, 40:55] += rest.hand_mean[1]
    return axis_angle_to_matrix(p)


def local_to_global(local: np.ndarray, parents: np.ndarray = SMPLX_PARENTS) -> np.ndarray:
    """World rotations from rotations relative to each parent (parents before children).

    Parameters
    ----------
    local : (T, J, 3, 3) float
    parents : (J,) int, default :data:`SMPLX_PARENTS`

    Returns
    -------
    (T, J, 3, 3) float64

    Examples
    --------
    >>> from beatlite.skeleton.rotations import axis_angle_to_matrix
    >>> local = axis_angle_to_matrix(np.array([[[0, 0, 0.5], [0, 0, 0.25]]]))
    >>> g = local_to_global(local, np.array([-1, 0]))
    >>> bool(np.allclose(g[0, 1], axis_angle_to_matrix([0, 0, 0.75])))
    True
    """
    out = np.empty_like(np.asarray(local, dtype=np.float64))
    for j, p in enumerate(parents):
        out[:, j] = local[:, j] if p < 0 else out[:, p] @ local[:, j]
    return out


def smplx_forward_kinematics(
    poses: np.ndarray, trans: np.ndarray | None = None, rest: SMPLXRest | None = None
) -> np.ndarray:
    """World joint positions of an SMPL-X motion.

    Parameters
    ----------
    poses : (T, 55, 3) float
        Axis-angle rotations in radians, each relative to the parent joint (BEAT2's ``poses`` reshaped).
    trans : (T, 3) float, metres, optional
        Root translation (default zero).
    rest : SMPLXRest, optional
        Default :func:`approximate_rest`.

    Returns
    -------
    (T, 55, 3) float64, metres
        ``x_j = x_parent + R_parent @ offset_j``, the pelvis at ``rest.joints[0] + trans``: the 55 joints of
        ``smplx.SMPLX(...).joints`` (``flat_hand_mean`` as ``rest.hand_mean`` says).

    Examples
    --------
    >>> poses = np.zeros((1, 55, 3))
    >>> poses[0, SMPLX_JOINTS.index("left_knee")] = [np.pi / 2, 0, 0]  # 90 degrees about X
    >>> x = smplx_forward_kinematics(poses)
    >>> knee, ankle = SMPLX_JOINTS.index("left_knee"), SMPLX_JOINTS.index("left_ankle")
    >>> ((x[0, ankle] - x[0, knee]).round(3) + 0.0).tolist()  # the shin now points back (-Z): a flexed knee
    [0.0, 0.0, -0.42]
    """
    rest = approximate_rest() if rest is None else rest
    glob = local_to_global(_full_local(poses, rest))
    off = rest.offsets()
    out = np.empty(glob.shape[:2] + (3,))
    out[:, 0] = rest.joints[0]
    for j in range(1, SMPLX_N_JOINTS):
        p = SMPLX_PARENTS[j]
        out[:, j] = out[:, p] + glob[:, p] @ off[j]
    if trans is not None:
        out += np.asarray(trans, dtype=np.float64)[:, None, :]
    return out


def rot6d_features(poses: np.ndarray) -> np.ndarray:
    """The 6D rotation features of every joint (Zhou et al., CVPR 2019), as EMAGE's models and FGD use.

    Parameters
    ----------
    poses : (T, 55, 3) float, axis-angle radians

    Returns
    -------
    (T, 330) float64
        Per joint the first two *columns* of its rotation matrix (:func:`beatlite.skeleton.rotations.matrix_to_6d`;
        PyTorch3D and EMAGE's code take the first two rows: the same numbers of the transposed matrix).

    Examples
    --------
    >>> rot6d_features(np.zeros((2, 55, 3)))[0, :6].tolist()  # the identity
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    """
    p = np.asarray(poses, dtype=np.float64)
    return matrix_to_6d(axis_angle_to_matrix(p)).reshape(p.shape[0], -1)


def angular_speed(poses: np.ndarray, fps: float) -> np.ndarray:
    """How fast each joint turns relative to its parent, no body model needed.

    Parameters
    ----------
    poses : (T, 55, 3) float, axis-angle radians
    fps : float, frames per second

    Returns
    -------
    (T - 1, 55) float64, radians per second
        The angle of ``R_t^T R_{t+1}`` times ``fps``.

    Examples
    --------
    >>> poses = np.zeros((3, 55, 3))
    >>> poses[:, 0, 1] = [0.0, 0.1, 0.3]  # the pelvis turns about Y by 0.1 then 0.2 rad per frame
    >>> angular_speed(poses, fps=30)[:, 0].round(6).tolist()
    [3.0, 6.0]
    """
    r = axis_angle_to_matrix(np.asarray(poses, dtype=np.float64))
    step = np.swapaxes(r[:-1], -1, -2) @ r[1:]
    return np.linalg.norm(matrix_to_axis_angle(step), axis=-1) * float(fps)


# ------------------------------------------------------------------------------------------ retargeting
def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 1e-12, n, 1.0)


def _turn(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(..., 3, 3): the smallest rotation taking unit ``u`` onto unit ``v`` (half turn about a normal if opposite)."""
    axis = np.cross(u, v)
    s, c = np.linalg.norm(axis, axis=-1), np.sum(u * v, axis=-1)
    angle = np.arctan2(s, c)
    normal = np.cross(u, np.where(np.abs(u[..., :1]) < 0.9, [1.0, 0, 0], [0, 1.0, 0]))
    axis = np.where((s > 1e-9)[..., None], axis, normal)
    return axis_angle_to_matrix(_unit(axis) * angle[..., None])


def _bones(beat: Skeleton) -> list[tuple[int, int, int] | None]:
    """Per SMPL-X joint: (child, BEAT joint, BEAT child) of the bone its rotation aligns, or None."""
    out: list = []
    for j, name in enumerate(SMPLX_JOINTS):
        kids = [c for c in np.flatnonzero(SMPLX_PARENTS == j) if SMPLX_JOINTS[c] in BEAT_COUNTERPARTS]
        if name in _PRIMARY_CHILD:
            kids = [SMPLX_JOINTS.index(_PRIMARY_CHILD[name])]
        if name not in BEAT_COUNTERPARTS or len(kids) != 1:
            out.append(None)
            continue
        c = int(kids[0])
        out.append((c, beat.index(BEAT_COUNTERPARTS[name]), beat.index(BEAT_COUNTERPARTS[SMPLX_JOINTS[c]])))
    return out


def _alignment(rest: SMPLXRest, beat: Skeleton) -> np.ndarray:
    """(55, 3, 3) rest alignment M: SMPL-X rest bone -> BEAT rest bone (identity for the approximate rest and
    beatlite's BEAT skeleton)."""
    beat, pos = _beat_rest_m(beat)
    m = np.broadcast_to(np.eye(3), (SMPLX_N_JOINTS, 3, 3)).copy()
    for j, bone in enumerate(_bones(beat)):
        if bone is None:
            m[j] = m[SMPLX_PARENTS[j]] if j else np.eye(3)
            continue
        c, b, bc = bone
        m[j] = _turn(_unit(rest.joints[c] - rest.joints[j]), _unit(pos[bc] - pos[b]))
    return m


def beat_to_smplx(motion: object, rest: SMPLXRest | None = None) -> tuple[np.ndarray, np.ndarray]:
    """SMPL-X poses and translation from a motion on BEAT's skeleton (any frame rate, kept).

    Parameters
    ----------
    motion : Motion
        On :func:`beatlite.skeleton.beat.beat_skeleton`'s joints (centimetres, degrees).
    rest : SMPLXRest, optional
        The target body (default :func:`approximate_rest`).

    Returns
    -------
    poses : (T, 55, 3) float64, axis-angle radians (relative to each parent; jaw and eyes zero; fingers
        relative to ``rest.hand_mean`` when the model has one)
    trans : (T, 3) float64, metres (the pelvis lands on BEAT's Hips)

    Examples
    --------
    >>> from beatlite.io.motion import Motion
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> poses, trans = beat_to_smplx(Motion(beat_skeleton(), np.zeros((4, 228)), fps=120))
    >>> poses.shape, bool(np.abs(poses).max() < 1e-12), trans.shape  # BEAT's rest pose is SMPL-X's rest pose
    ((4, 55, 3), True, (4, 3))
    """
    from beatlite.skeleton.kinematics import global_transforms

    rest = approximate_rest() if rest is None else rest
    beat_rot, beat_pos = global_transforms(motion.skeleton, motion.channels)  # type: ignore[attr-defined]
    names = motion.skeleton.names  # type: ignore[attr-defined]
    m, bones = _alignment(rest, motion.skeleton), _bones(motion.skeleton)  # type: ignore[attr-defined]
    glob = np.empty(beat_rot.shape[:1] + (SMPLX_N_JOINTS, 3, 3))
    for j, name in enumerate(SMPLX_JOINTS):
        if name not in BEAT_COUNTERPARTS:
            glob[:, j] = glob[:, SMPLX_PARENTS[j]]
            continue
        g = beat_rot[:, names.index(BEAT_COUNTERPARTS[name])] @ m[j]
        if bones[j] is not None:  # point the bone where BEAT's chain points (in-between joints folded in)
            c, b, bc = bones[j]
            u = g @ _unit(rest.joints[c] - rest.joints[j])
            g = _turn(u, _unit(beat_pos[:, bc] - beat_pos[:, b])) @ g
        glob[:, j] = g
    local = glob.copy()
    local[:, 1:] = np.swapaxes(glob[:, SMPLX_PARENTS[1:]], -1, -2) @ glob[:, 1:]
    poses = matrix_to_axis_angle(local)
    if rest.hand_mean is not None:
        poses[:, 25:40] -= rest.hand_mean[0]
        poses[:, 40:55] -= rest.hand_mean[1]
    trans = beat_pos[:, names.index("Hips")] / 100.0 - rest.joints[0]
    return poses, trans


def smplx_to_beat(poses: np.ndarray, trans: np.ndarray, fps: float, rest: SMPLXRest | None = None) -> object:
    """A motion on BEAT's skeleton from SMPL-X poses: what the rest of beatlite reads a BEAT2 take as.

    Parameters
    ----------
    poses : (T, 55, 3) float, axis-angle radians
    trans : (T, 3) float, metres
    fps : float
    rest : SMPLXRest, optional
        The source body (default :func:`approximate_rest`).

    Returns
    -------
    Motion
        :func:`beatlite.skeleton.beat.beat_skeleton` rows (cm, degrees, ``XYZ`` Euler kept continuous over time);
        BEAT joints without an SMPL-X counterpart at zero (they follow their parent).

    Examples
    --------
    >>> poses = np.zeros((2, 55, 3))
    >>> poses[:, SMPLX_JOINTS.index("right_elbow")] = [0, 0.5, 0]
    >>> motion = smplx_to_beat(poses, np.zeros((2, 3)), fps=30)
    >>> col = motion.skeleton.rotation_channel_indices(motion.skeleton.index("RightForeArm"))
    >>> motion.channels[0, col].round(5) + 0.0  # 0.5 rad about Y, in degrees
    array([ 0.     , 28.64789,  0.     ])
    """
    from beatlite.io.motion import Motion
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.rotations import matrix_to_euler
    from beatlite.synth.motion import continuous_euler

    rest = approximate_rest() if rest is None else rest
    glob = local_to_global(_full_local(poses, rest))
    beat = beat_skeleton()
    m = _alignment(rest, beat)
    back = {b: SMPLX_JOINTS.index(s) for s, b in BEAT_COUNTERPARTS.items()}
    bglob = np.empty(glob.shape[:1] + (beat.n_joints, 3, 3))
    channels = np.zeros((glob.shape[0], beat.n_channels))
    for k, name in enumerate(beat.names):
        p = beat.parents[k]
        bglob[:, k] = glob[:, back[name]] @ m[back[name]].T if name in back else bglob[:, p]
        local = bglob[:, k] if p < 0 else np.swapaxes(bglob[:, p], -1, -2) @ bglob[:, k]
        channels[:, beat.rotation_channel_indices(k)] = continuous_euler(
            matrix_to_euler(local, beat.rotation_order(k), degrees=True)
        )
    hips = 100.0 * (np.asarray(trans, dtype=np.float64) + rest.joints[0])
    channels[:, beat.position_channel_indices(0)] = hips
    return Motion(beat, channels, fps)


def smplx_skeleton_motion(
    poses: np.ndarray, trans: np.ndarray, fps: float, rest: SMPLXRest | None = None
) -> object:
    """An SMPL-X motion as BVH rows of its own skeleton (:meth:`SMPLXRest.skeleton`): no retargeting, e.g. to open
    a BEAT2 file in Blender (PantoMatrix#83, #178) with :func:`beatlite.io.write_bvh`.

    Parameters
    ----------
    poses : (T, 55, 3) float, axis-angle radians
    trans : (T, 3) float, metres
    fps : float
    rest : SMPLXRest, optional
        Default :func:`approximate_rest`.

    Returns
    -------
    Motion
        ``XYZ`` Euler degrees per joint (continuous over time), the pelvis position in cm, joints in
        :data:`DEPTH_FIRST` order; its forward kinematics equals ``100 * smplx_forward_kinematics(...)[:, DEPTH_FIRST]``.

    Examples
    --------
    >>> poses = np.random.default_rng(0).normal(scale=0.3, size=(3, 55, 3))
    >>> motion = smplx_skeleton_motion(poses, np.zeros((3, 3)), fps=30)
    >>> x = 100 * smplx_forward_kinematics(poses)[:, DEPTH_FIRST]  # the BVH's joints are in depth-first order
    >>> motion.channels.shape, bool(np.allclose(motion.positions(), x))
    ((3, 168), True)
    """
    from beatlite.io.motion import Motion
    from beatlite.skeleton.rotations import matrix_to_euler
    from beatlite.synth.motion import continuous_euler

    rest = approximate_rest() if rest is None else rest
    local = _full_local(poses, rest)
    skeleton = rest.skeleton()
    channels = np.zeros((local.shape[0], skeleton.n_channels))
    channels[:, skeleton.position_channel_indices(0)] = 100.0 * (
        np.asarray(trans, np.float64) + rest.joints[0]
    )
    for k, j in enumerate(DEPTH_FIRST):
        euler = matrix_to_euler(local[:, j], "XYZ", degrees=True)
        channels[:, skeleton.rotation_channel_indices(k)] = continuous_euler(euler)
    return Motion(skeleton, channels, fps)


def bone_direction_errors(motion: object, poses: np.ndarray, trans: np.ndarray, rest: SMPLXRest | None = None
                          ) -> dict[str, np.ndarray]:  # fmt: skip
    """Per bone, the angle between a BEAT motion's bone and the same bone of its SMPL-X version.

    A bone is an SMPL-X joint and one of its children that both have BEAT counterparts; BEAT's bone runs between
    the counterparts (over BEAT's in-between joints).

    Parameters
    ----------
    motion : Motion
        On BEAT's skeleton.
    poses, trans : (T, 55, 3) radians, (T, 3) metres
        The SMPL-X version (e.g. from :func:`beat_to_smplx`).
    rest : SMPLXRest, optional

    Returns
    -------
    dict ``"parent->child"`` (SMPL-X names) -> (T,) float64 degrees

    Examples
    --------
    >>> from beatlite.io.motion import Motion
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> motion = Motion(beat_skeleton(), np.zeros((1, 228)), fps=120)
    >>> errors = bone_direction_errors(motion, *beat_to_smplx(motion))
    >>> len(errors), max(float(e.max()) for e in errors.values()) < 1e-6
    (51, True)
    """
    rest = approximate_rest() if rest is None else rest
    bp = motion.positions()  # type: ignore[attr-defined]
    names = motion.skeleton.names  # type: ignore[attr-defined]
    sp = smplx_forward_kinematics(poses, trans, rest)
    out = {}
    for c in range(1, SMPLX_N_JOINTS):
        j = int(SMPLX_PARENTS[c])
        a, b = SMPLX_JOINTS[j], SMPLX_JOINTS[c]
        if a not in BEAT_COUNTERPARTS or b not in BEAT_COUNTERPARTS:
            continue
        u = _unit(bp[:, names.index(BEAT_COUNTERPARTS[b])] - bp[:, names.index(BEAT_COUNTERPARTS[a])])
        v = _unit(sp[:, c] - sp[:, j])
        out[f"{a}->{b}"] = np.degrees(
            np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))
        )
    return out
