"""Vectorised rotation conversions: Euler angles, matrices, quaternions, axis-angle and 6D.

Every function works on arbitrary leading shapes ``(...)`` and uses plain NumPy.

Conventions
-----------
- **Matrices** ``(..., 3, 3)`` rotate column vectors: ``v_world = R @ v_local``.
- **Euler orders** are strings of the three axes. Upper case (``"XYZ"``, ``"ZXY"``, ...) is
  *intrinsic*, as in BVH files: CHANNELS ``Zrotation Xrotation Yrotation`` with angles
  ``(a, b, c)`` means ``R = Rz(a) @ Rx(b) @ Ry(c)``. Lower case (``"zxy"``) is *extrinsic*
  (rotations about the fixed axes, in that order), exactly like
  ``scipy.spatial.transform.Rotation.from_euler``.
- **Quaternions** are ``(..., 4)`` in ``(w, x, y, z)`` order (scalar first), unit norm, returned
  with ``w >= 0``.
- **Axis-angle** is a rotation vector ``(..., 3)``: unit axis times angle in **radians**.
- **6D** (Zhou et al., CVPR 2019) is the first two *columns* of the matrix, ``(..., 6)`` =
  ``[R[:, 0], R[:, 1]]``; :func:`sixd_to_matrix` re-orthonormalises with Gram-Schmidt.

Taught in notebooks/01_beat_formats.ipynb, sections 4 (Euler angles: many numbers for one rotation) and 12.1-12.3
(axis-angle, and why rot6d), and its Exercise 4 (axis-angle to a matrix).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "EULER_ORDERS",
    "axis_angle_to_matrix",
    "euler_entries",
    "euler_to_6d",
    "euler_to_matrix",
    "matrix_to_6d",
    "matrix_to_axis_angle",
    "matrix_to_euler",
    "matrix_to_quat",
    "nearest_euler",
    "quat_to_matrix",
    "sixd_to_matrix",
    "unwrap_degrees",
]

#: The six Tait-Bryan orders (intrinsic). Lower-case versions are the extrinsic ones.
EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")

_AXIS = {"X": 0, "Y": 1, "Z": 2}
# Below this value of cos(middle angle) matrix_to_euler treats the matrix as gimbal-locked.
_GIMBAL_EPS = 1e-7


# ----------------------------------------------------------------------------- validation
def _as_float_array(x: object, name: str, last: tuple[int, ...]) -> np.ndarray:
    """``x`` as a float64 array whose trailing dimensions are ``last``; ``ValueError`` otherwise."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a numeric array, got {type(x).__name__}") from exc
    k = len(last)
    if arr.ndim < k or arr.shape[arr.ndim - k :] != last:
        want = "(..., " + ", ".join(str(n) for n in last) + ")"
        raise ValueError(f"{name} must have shape {want}, got {arr.shape}")
    return arr


def _parse_order(order: str) -> tuple[str, bool]:
    """Return ``(intrinsic upper-case order, was_extrinsic)``; ``ValueError`` for anything else."""
    if not isinstance(order, str) or len(order) != 3:
        raise ValueError(f"order must be one of {EULER_ORDERS} (or lower case for extrinsic), got {order!r}")
    if order.isupper() and order in EULER_ORDERS:
        return order, False
    if order.islower() and order.upper() in EULER_ORDERS:
        # extrinsic "abc" with angles (p, q, r) == intrinsic "CBA" with angles (r, q, p)
        return order.upper()[::-1], True
    raise ValueError(
        f"order must be one of {EULER_ORDERS} (intrinsic, as in BVH) or their lower-case extrinsic "
        f"forms, got {order!r}"
    )


# ----------------------------------------------------------------------------- Euler
def _order_parity(intrinsic: str) -> tuple[tuple[int, int, int], float]:
    """Axis indices of an intrinsic order and its parity (+1 for XYZ, YZX, ZXY; -1 otherwise)."""
    i, j, k = (_AXIS[a] for a in intrinsic)
    return (i, j, k), (1.0 if (j - i) % 3 == 1 else -1.0)


def _cos_sin(x: np.ndarray, sign: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``cos(x), sign * sin(x)`` from one half-angle tangent.

    NumPy 2 vectorises float64 ``np.tan`` with SIMD but not ``np.cos``/``np.sin``, so this is
    several times faster; it is accurate to a few ulps.
    """
    t = np.tan(0.5 * x)
    t2 = t * t
    d = 1.0 / (1.0 + t2)
    return (1.0 - t2) * d, (2.0 * sign) * t * d


def _euler_fill(
    cos3: tuple[np.ndarray, np.ndarray, np.ndarray],
    sin3: tuple[np.ndarray, np.ndarray, np.ndarray],
    intrinsic: str,
    out: np.ndarray,
    scratch: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """Write Euler rotation matrices into ``out`` without allocating.

    ``cos3``/``sin3`` are the cosines and *parity-signed* sines (``s * sin``, s = -1 for the
    odd orders) of the three angles of the intrinsic order; ``out`` is ``(3, 3, *shape)``
    (may be a strided view) and ``scratch`` holds three arrays of ``shape``. Uses
    ``R_ijk(a, b, c) = P @ R_XYZ(s a, s b, s c) @ P.T`` with ``P = [e_i, e_j, e_k]``.
    """
    (ca, cb, cc), (sa, sb, sc) = cos3, sin3
    ix, _ = _order_parity(intrinsic)
    tmp, sa_sb, ca_sb = scratch

    def o(m: int, n: int) -> np.ndarray:
        return out[ix[m], ix[n], ...]  # a view, 0-d for single matrices

    np.multiply(sa, sb, out=sa_sb)
    np.multiply(ca, sb, out=ca_sb)
    # row 0: cb cc, -cb sc, sb
    np.multiply(cb, cc, out=o(0, 0))
    np.multiply(cb, sc, out=o(0, 1))
    np.negative(o(0, 1), out=o(0, 1))
    o(0, 2)[...] = sb
    # row 1: sa sb cc + ca sc, ca cc - sa sb sc, -sa cb
    np.multiply(sa_sb, cc, out=o(1, 0))
    np.add(o(1, 0), np.multiply(ca, sc, out=tmp), out=o(1, 0))
    np.multiply(ca, cc, out=o(1, 1))
    np.subtract(o(1, 1), np.multiply(sa_sb, sc, out=tmp), out=o(1, 1))
    np.multiply(sa, cb, out=o(1, 2))
    np.negative(o(1, 2), out=o(1, 2))
    # row 2: sa sc - ca sb cc, ca sb sc + sa cc, ca cb
    np.multiply(sa, sc, out=o(2, 0))
    np.subtract(o(2, 0), np.multiply(ca_sb, cc, out=tmp), out=o(2, 0))
    np.multiply(ca_sb, sc, out=o(2, 1))
    np.add(o(2, 1), np.multiply(sa, cc, out=tmp), out=o(2, 1))
    np.multiply(ca, cb, out=o(2, 2))


def euler_entries(a: np.ndarray, b: np.ndarray, c: np.ndarray, order: str) -> np.ndarray:
    """Rotation matrices of Euler angles, component-major: ``(3, 3, *shape)``.

    A lower-level form of :func:`euler_to_matrix` for code that keeps a long axis last.

    Parameters
    ----------
    a, b, c : float arrays of one common shape, radians
        First, second and third angle of ``order``.
    order : str
        Intrinsic (upper case) or extrinsic (lower case) order, see :func:`euler_to_matrix`.

    Returns
    -------
    (3, 3, *shape) float64 with ``out[r, col]`` the matrix entry ``R[r, col]``.

    Examples
    --------
    >>> m = euler_entries(np.zeros(4), np.zeros(4), np.full(4, np.pi / 2), "XYZ")
    >>> m.shape  # component-major: (3, 3, *shape)
    (3, 3, 4)
    >>> np.allclose(np.moveaxis(m, (0, 1), (-2, -1)), euler_to_matrix([0, 0, 90], "XYZ"))
    True
    """
    intrinsic, extrinsic = _parse_order(order)
    a, b, c = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (a, b, c)))
    if extrinsic:
        a, c = c, a
    _, s = _order_parity(intrinsic)
    (ca, sa), (cb, sb), (cc, sc) = _cos_sin(a, s), _cos_sin(b, s), _cos_sin(c, s)
    out = np.empty((3, 3) + a.shape)
    scratch = (np.empty(a.shape), np.empty(a.shape), np.empty(a.shape))
    _euler_fill((ca, cb, cc), (sa, sb, sc), intrinsic, out, scratch)
    return out


def euler_to_matrix(angles: np.ndarray, order: str, degrees: bool = True) -> np.ndarray:
    """Rotation matrices from Euler angles.

    Parameters
    ----------
    angles : (..., 3) float
        The three angles in the order the axes appear in ``order``; degrees unless
        ``degrees=False`` (radians).
    order : str
        One of ``"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"`` (intrinsic, BVH; ``"ZXY"`` gives
        ``Rz @ Rx @ Ry``) or the lower-case extrinsic forms.
    degrees : bool
        Whether ``angles`` are in degrees.

    Returns
    -------
    (..., 3, 3) float64

    Examples
    --------
    >>> euler_to_matrix([90, 0, 0], "ZXY").round(6) + 0.0  # 90 degrees about z
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> euler_to_matrix(np.zeros((5, 2, 3)), "ZXY").shape
    (5, 2, 3, 3)
    """
    angles = _as_float_array(angles, "angles", (3,))
    _parse_order(order)
    if degrees:
        angles = np.deg2rad(angles)
    ent = euler_entries(angles[..., 0], angles[..., 1], angles[..., 2], order)
    return np.moveaxis(ent, (0, 1), (-2, -1))


def matrix_to_euler(matrix: np.ndarray, order: str, degrees: bool = True) -> np.ndarray:
    """Euler angles of rotation matrices (inverse of :func:`euler_to_matrix`).

    The middle angle is in ``[-90, 90]`` degrees, the others in ``(-180, 180]``. At gimbal
    lock (middle angle ±90°) the third angle is set to 0 and the first absorbs the rest, so
    ``euler_to_matrix(matrix_to_euler(R, o), o)`` reproduces ``R`` everywhere.

    Parameters
    ----------
    matrix : (..., 3, 3) float
        Rotation matrices (assumed orthonormal with determinant +1).
    order : str
        As in :func:`euler_to_matrix`.
    degrees : bool
        Return degrees (default) or radians.

    Returns
    -------
    (..., 3) float64

    Examples
    --------
    >>> angles = np.array([30.0, -45.0, 60.0])
    >>> matrix_to_euler(euler_to_matrix(angles, "ZXY"), "ZXY").round(6)
    array([ 30., -45.,  60.])
    """
    m = _as_float_array(matrix, "matrix", (3, 3))
    intrinsic, extrinsic = _parse_order(order)
    (i, j, k), s = _order_parity(intrinsic)
    cos_b = np.hypot(m[..., i, i], m[..., i, j])
    b = np.arctan2(s * m[..., i, k], cos_b)
    locked = cos_b < _GIMBAL_EPS
    a = np.where(
        locked,
        np.arctan2(s * m[..., k, j], m[..., j, j]),
        np.arctan2(-s * m[..., j, k], m[..., k, k]),
    )
    c = np.where(locked, 0.0, np.arctan2(-s * m[..., i, j], m[..., i, i]))
    out = np.stack([a, b, c], axis=-1)
    if extrinsic:
        out = out[..., ::-1]
    return np.rad2deg(out) if degrees else out


def unwrap_degrees(angles: np.ndarray, axis: int = 0) -> np.ndarray:
    """Remove 360° jumps along time: ``np.unwrap`` in degrees.

    Real BEAT Euler channels are already unwrapped (values such as 397° or -2482° occur);
    this makes any angle track continuous in the same way, so that frame differences and
    mean/std statistics are not spoiled by wrap-around.

    Parameters
    ----------
    angles : (T, ...) float, degrees
        Angle tracks; time along ``axis`` (default 0).
    axis : int
        The time axis.

    Returns
    -------
    float64 array of the same shape, degrees; consecutive values differ by at most 180°.

    Examples
    --------
    >>> unwrap_degrees(np.array([170.0, -170.0, -150.0]))
    array([170., 190., 210.])
    """
    arr = np.asarray(angles, dtype=np.float64)
    if arr.ndim == 0:
        raise ValueError(f"angles must have at least one (time) dimension, got shape {arr.shape}")
    return np.unwrap(arr, period=360.0, axis=axis)


def nearest_euler(angles: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Of the Euler triples that give each rotation of ``angles``, the one nearest ``reference``.

    Every Tait-Bryan order writes one rotation as ``(a, b, c)`` and as ``(a + 180, 180 - b, c + 180)``
    (the two branches of the middle angle), each angle also up to any multiple of 360°. A file written
    from rotation matrices (``scipy``'s ``as_euler``, :func:`matrix_to_euler`) lands on
    ``|b| <= 90°`` in ``(-180, 180]``, where motion capture keeps continuous, unwrapped tracks
    (real BEAT: values such as 397° or -2482°). Comparing Euler angles channel by channel needs both
    on one representation: this returns, per triple, the candidate whose summed absolute difference
    to ``reference`` is smallest (on a tie the first branch, ``(a, b, c)`` up to 360° turns). The rotations
    are unchanged, whatever the order. :func:`beatlite.synth.motion.continuous_euler` applies it frame by frame
    with the previous frame as the reference.

    Parameters
    ----------
    angles : (..., 3) float, degrees
        Euler triples in any one Tait-Bryan order (intrinsic or extrinsic: the middle angle is the
        second either way).
    reference : (..., 3) float, degrees
        Triples of the same order, broadcastable with ``angles`` (e.g. the ground truth's, frame by frame).

    Returns
    -------
    (..., 3) float64, degrees

    Examples
    --------
    >>> nearest_euler(np.array([10.0, 80.0, -20.0]), np.array([370.0, 80.0, -20.0]))
    array([370.,  80., -20.])
    >>> nearest_euler(np.array([-170.0, 60.0, 170.0]), np.array([10.0, 120.0, -10.0]))
    array([ 10., 120., -10.])
    """
    a = _as_float_array(angles, "angles", (3,))
    ref = _as_float_array(reference, "reference", (3,))
    other = np.stack([a[..., 0] + 180.0, 180.0 - a[..., 1], a[..., 2] + 180.0], axis=-1)
    best, best_cost = None, None
    for cand in (a, other):
        cand = cand - 360.0 * np.round((cand - ref) / 360.0)
        cost = np.abs(cand - ref).sum(axis=-1, keepdims=True)
        if best is None:
            best, best_cost = cand, cost
        else:
            best = np.where(cost < best_cost, cand, best)
    return best


# ----------------------------------------------------------------------------- quaternions
def quat_to_matrix(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices from quaternions ``(w, x, y, z)``.

    Parameters
    ----------
    quat : (..., 4) float
        Quaternions; normalised here (a zero quaternion raises ``ValueError``).

    Returns
    -------
    (..., 3, 3) float64

    Examples
    --------
    >>> half = np.sqrt(0.5)
    >>> quat_to_matrix([half, 0, 0, half]).round(6) + 0.0  # 90 degrees about z
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    q = _as_float_array(quat, "quat", (4,))
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(norm < 1e-12):
        raise ValueError("quat contains zero-length quaternions, which are not rotations")
    w, x, y, z = np.moveaxis(q / norm, -1, 0)
    out = np.empty(q.shape[:-1] + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - z * w)
    out[..., 0, 2] = 2 * (x * z + y * w)
    out[..., 1, 0] = 2 * (x * y + z * w)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - x * w)
    out[..., 2, 0] = 2 * (x * z - y * w)
    out[..., 2, 1] = 2 * (y * z + x * w)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def matrix_to_quat(matrix: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(w, x, y, z)`` with ``w >= 0`` from rotation matrices.

    Uses the numerically stable branch of Shepperd's method per element (largest of
    ``w², x², y², z²``).

    Parameters
    ----------
    matrix : (..., 3, 3) float

    Returns
    -------
    (..., 4) float64

    Examples
    --------
    >>> matrix_to_quat(np.eye(3))
    array([1., 0., 0., 0.])
    >>> matrix_to_quat(euler_to_matrix([180, 0, 0], "ZXY")).round(6) + 0.0  # 180 degrees about z
    array([0., 0., 0., 1.])
    """
    m = _as_float_array(matrix, "matrix", (3, 3))
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    # 4*q_k^2 for k = w, x, y, z
    sq = np.stack(
        [1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], axis=-1
    )
    d21, d02, d10 = m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]
    s21, s02, s10 = m[..., 2, 1] + m[..., 1, 2], m[..., 0, 2] + m[..., 2, 0], m[..., 1, 0] + m[..., 0, 1]
    # candidate (unnormalised) quaternions, each exact when its own component is largest
    cand = np.stack(
        [
            np.stack([sq[..., 0], d21, d02, d10], axis=-1),
            np.stack([d21, sq[..., 1], s10, s02], axis=-1),
            np.stack([d02, s10, sq[..., 2], s21], axis=-1),
            np.stack([d10, s02, s21, sq[..., 3]], axis=-1),
        ],
        axis=-2,
    )
    best = np.argmax(sq, axis=-1)
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


# ----------------------------------------------------------------------------- axis-angle
def axis_angle_to_matrix(rotvec: np.ndarray) -> np.ndarray:
    """Rotation matrices from rotation vectors (Rodrigues' formula).

    Parameters
    ----------
    rotvec : (..., 3) float
        Unit axis times angle in radians.

    Returns
    -------
    (..., 3, 3) float64

    Examples
    --------
    >>> axis_angle_to_matrix([0, 0, np.pi / 2]).round(6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    v = _as_float_array(rotvec, "rotvec", (3,))
    theta = np.linalg.norm(v, axis=-1)
    small = theta < 1e-6
    safe = np.where(small, 1.0, theta)
    # sin(t)/t and (1-cos(t))/t^2 with Taylor series near 0
    a = np.where(small, 1 - theta**2 / 6, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta**2 / 24, (1 - np.cos(safe)) / safe**2)
    x, y, z = np.moveaxis(v, -1, 0)
    zero = np.zeros_like(x)
    k = np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=-1).reshape(v.shape[:-1] + (3, 3))
    eye = np.broadcast_to(np.eye(3), k.shape)
    return eye + a[..., None, None] * k + b[..., None, None] * (k @ k)


def matrix_to_axis_angle(matrix: np.ndarray) -> np.ndarray:
    """Rotation vectors (axis times angle in radians, angle in ``[0, π]``) from matrices.

    Parameters
    ----------
    matrix : (..., 3, 3) float

    Returns
    -------
    (..., 3) float64

    Examples
    --------
    >>> rotvec = np.array([0.1, -0.2, 0.3])
    >>> np.allclose(matrix_to_axis_angle(axis_angle_to_matrix(rotvec)), rotvec)
    True
    """
    q = matrix_to_quat(matrix)
    vnorm = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2 * np.arctan2(vnorm, q[..., 0])
    small = vnorm < 1e-8
    # rotvec = angle * v / |v|; near identity angle/|v| -> 2/w
    scale = np.where(small, 2.0 / np.maximum(q[..., 0], 1e-12), angle / np.where(small, 1.0, vnorm))
    return q[..., 1:] * scale[..., None]


# ----------------------------------------------------------------------------- 6D
def matrix_to_6d(matrix: np.ndarray) -> np.ndarray:
    """The 6D representation: first two columns of each matrix.

    Parameters
    ----------
    matrix : (..., 3, 3) float

    Returns
    -------
    (..., 6) float64, ``[R[:, 0], R[:, 1]]``

    Examples
    --------
    >>> matrix_to_6d(np.eye(3))
    array([1., 0., 0., 0., 1., 0.])
    """
    m = _as_float_array(matrix, "matrix", (3, 3))
    return np.concatenate([m[..., :, 0], m[..., :, 1]], axis=-1)


def euler_to_6d(angles: np.ndarray, order: str = "XYZ", degrees: bool = True) -> np.ndarray:
    """The 6D representation of each Euler triplet of a row (e.g. BEAT's 141 channels -> 282).

    Parameters
    ----------
    angles : (..., 3K) float
        K Euler triplets per row, each in ``order`` (BEAT's ``XYZ`` intrinsic by default).
    order : str
    degrees : bool

    Returns
    -------
    (..., 6K) float64
        Per triplet :func:`matrix_to_6d` of :func:`euler_to_matrix`: continuous in the rotation, unlike the angles.

    Examples
    --------
    >>> euler_to_6d([0.0, 0, 0, 0, 0, 90]).round(6) + 0.0  # the identity, then 90 degrees about Z
    array([ 1.,  0.,  0.,  0.,  1.,  0.,  0.,  1.,  0., -1.,  0.,  0.])
    """
    a = _as_float_array(angles, "angles", ())
    if a.ndim == 0 or a.shape[-1] % 3:
        raise ValueError(f"angles: the last axis must hold Euler triplets (3K values), got {a.shape}")
    triplets = a.reshape(a.shape[:-1] + (a.shape[-1] // 3, 3))
    six = matrix_to_6d(euler_to_matrix(triplets, order, degrees=degrees))
    return six.reshape(a.shape[:-1] + (-1,))


def sixd_to_matrix(sixd: np.ndarray) -> np.ndarray:
    """Rotation matrices from 6D vectors by Gram-Schmidt (Zhou et al. 2019).

    Parameters
    ----------
    sixd : (..., 6) float
        Two 3-vectors (the intended first and second columns); need not be orthonormal,
        but must not be zero or parallel (``ValueError``).

    Returns
    -------
    (..., 3, 3) float64 with columns ``b1, b2, b1 × b2``.

    Examples
    --------
    >>> sixd_to_matrix([2.0, 0, 0, 1, 1, 0])  # columns normalised and made orthogonal
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    d = _as_float_array(sixd, "sixd", (6,))
    a1, a2 = d[..., :3], d[..., 3:]
    n1 = np.linalg.norm(a1, axis=-1, keepdims=True)
    if np.any(n1 < 1e-12):
        raise ValueError("sixd: the first 3-vector is zero in some entries")
    b1 = a1 / n1
    u2 = a2 - np.sum(b1 * a2, axis=-1, keepdims=True) * b1
    n2 = np.linalg.norm(u2, axis=-1, keepdims=True)
    if np.any(n2 < 1e-12):
        raise ValueError("sixd: the two 3-vectors are parallel (or the second is zero) in some entries")
    b2 = u2 / n2
    b3 = np.cross(b1, b2)
    return np.stack([b1, b2, b3], axis=-1)
