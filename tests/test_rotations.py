"""Tests of the rotation conversions (scipy's Rotation is used as an independent oracle)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from beatlite.skeleton.rotations import (
    EULER_ORDERS,
    axis_angle_to_matrix,
    euler_entries,
    euler_to_6d,
    euler_to_matrix,
    matrix_to_6d,
    matrix_to_axis_angle,
    matrix_to_euler,
    matrix_to_quat,
    nearest_euler,
    quat_to_matrix,
    sixd_to_matrix,
    unwrap_degrees,
)

ALL_ORDERS = EULER_ORDERS + tuple(o.lower() for o in EULER_ORDERS)


@pytest.fixture()
def rng():
    return np.random.default_rng(1234)


def random_matrices(rng, n=500):
    return Rotation.random(n, random_state=rng.integers(1 << 31)).as_matrix()


def test_elementary_rotations_by_hand():
    # Rz(90) maps x -> y; Rx(90) maps y -> z; Ry(90) maps z -> x (right-handed)
    assert np.allclose(euler_to_matrix([90, 0, 0], "ZXY") @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(euler_to_matrix([90, 0, 0], "XYZ") @ [0, 1, 0], [0, 0, 1])
    assert np.allclose(euler_to_matrix([90, 0, 0], "YZX") @ [0, 0, 1], [1, 0, 0])
    # intrinsic ZXY = Rz @ Rx @ Ry: Ry(90) sends z to x, then Rx(90) leaves x, then Rz(90) sends x to y
    assert np.allclose(euler_to_matrix([90, 90, 90], "ZXY") @ [0, 0, 1], [0, 1, 0])
    assert np.allclose(euler_to_matrix([np.pi / 2, 0, 0], "ZXY", degrees=False) @ [1, 0, 0], [0, 1, 0])


@pytest.mark.parametrize("order", ALL_ORDERS)
def test_euler_to_matrix_matches_scipy(order, rng):
    angles = rng.uniform(-400, 400, size=(300, 3))  # beyond +-180 like real BEAT values
    ours = euler_to_matrix(angles, order)
    oracle = Rotation.from_euler(order, angles, degrees=True).as_matrix()
    assert ours.shape == (300, 3, 3)
    assert np.allclose(ours, oracle, atol=1e-12)


@pytest.mark.parametrize("order", ALL_ORDERS)
def test_matrix_to_euler_round_trips_and_matches_scipy(order, rng):
    mats = random_matrices(rng)
    angles = matrix_to_euler(mats, order)
    assert np.allclose(euler_to_matrix(angles, order), mats, atol=1e-6)
    assert np.allclose(angles, Rotation.from_matrix(mats).as_euler(order, degrees=True), atol=1e-6)
    # canonical range: middle angle in [-90, 90], the others in (-180, 180]
    assert np.all(np.abs(angles[:, 1]) <= 90 + 1e-9) and np.all(np.abs(angles) <= 180 + 1e-9)
    # euler -> matrix -> euler is the identity on the canonical range, radians too
    canon = np.column_stack(
        [rng.uniform(-179, 179, 200), rng.uniform(-89, 89, 200), rng.uniform(-179, 179, 200)]
    )
    rad = np.deg2rad(canon)
    assert np.allclose(matrix_to_euler(euler_to_matrix(rad, order, degrees=False), order, degrees=False), rad)


@pytest.mark.parametrize("order", EULER_ORDERS)
@pytest.mark.parametrize("middle", [90.0, -90.0, 90.0 - 1e-9])
def test_matrix_to_euler_is_gimbal_lock_safe(order, middle, rng):
    angles = np.column_stack([rng.uniform(-170, 170, 50), np.full(50, middle), rng.uniform(-170, 170, 50)])
    mats = euler_to_matrix(angles, order)
    back = matrix_to_euler(mats, order)
    assert np.all(np.isfinite(back))
    assert np.allclose(euler_to_matrix(back, order), mats, atol=1e-6)
    assert np.allclose(back[:, 1], middle, atol=1e-4)


def test_euler_entries_is_component_major(rng):
    a, b, c = rng.uniform(-3, 3, size=(3, 4, 5))
    ent = euler_entries(a, b, c, "YXZ")
    assert ent.shape == (3, 3, 4, 5)
    mats = euler_to_matrix(np.stack([a, b, c], axis=-1), "YXZ", degrees=False)
    assert np.allclose(np.moveaxis(ent, (0, 1), (-2, -1)), mats)


def test_arbitrary_leading_shapes(rng):
    angles = rng.uniform(-180, 180, size=(2, 3, 4, 3))
    mats = euler_to_matrix(angles, "ZYX")
    assert mats.shape == (2, 3, 4, 3, 3)
    assert matrix_to_euler(mats, "ZYX").shape == (2, 3, 4, 3)
    assert matrix_to_quat(mats).shape == (2, 3, 4, 4)
    assert matrix_to_axis_angle(mats).shape == (2, 3, 4, 3)
    assert matrix_to_6d(mats).shape == (2, 3, 4, 6)
    assert euler_to_matrix(np.array([10.0, 20.0, 30.0]), "XYZ").shape == (3, 3)


def test_quaternions_match_scipy_and_round_trip(rng):
    mats = random_matrices(rng)
    q = matrix_to_quat(mats)
    oracle = Rotation.from_matrix(mats).as_quat(scalar_first=True)
    oracle *= np.where(oracle[:, :1] < 0, -1, 1)  # same sign convention, w >= 0
    assert np.allclose(q, oracle, atol=1e-12)
    assert np.all(q[:, 0] >= 0) and np.allclose(np.linalg.norm(q, axis=1), 1)
    assert np.allclose(quat_to_matrix(q), mats, atol=1e-12)
    # non-unit input is normalised; q and -q are the same rotation
    assert np.allclose(quat_to_matrix(3.0 * q), mats) and np.allclose(quat_to_matrix(-q), mats)
    # 180-degree rotations (w = 0) take the other branches of the conversion
    for axis in np.eye(3):
        half_turn = axis_angle_to_matrix(np.pi * axis)
        assert np.allclose(quat_to_matrix(matrix_to_quat(half_turn)), half_turn)
    # hand case: 90 degrees about z -> (cos 45, 0, 0, sin 45)
    assert np.allclose(matrix_to_quat(euler_to_matrix([0, 0, 90], "XYZ")), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    with pytest.raises(ValueError, match="zero"):
        quat_to_matrix(np.zeros(4))


def test_axis_angle_matches_scipy_including_small_and_half_turn_angles(rng):
    mats = random_matrices(rng)
    rv = matrix_to_axis_angle(mats)
    assert np.allclose(rv, Rotation.from_matrix(mats).as_rotvec(), atol=1e-9)
    assert np.allclose(axis_angle_to_matrix(rv), mats, atol=1e-12)
    tiny = rng.normal(size=(20, 3)) * 1e-9
    assert np.allclose(matrix_to_axis_angle(axis_angle_to_matrix(tiny)), tiny, atol=1e-15)
    assert np.allclose(axis_angle_to_matrix(tiny), Rotation.from_rotvec(tiny).as_matrix(), atol=1e-15)
    assert np.allclose(axis_angle_to_matrix(np.zeros(3)), np.eye(3))
    half = np.array([0.0, 0.0, np.pi])
    assert np.allclose(axis_angle_to_matrix(half), np.diag([-1.0, -1.0, 1.0]))
    assert np.isclose(np.linalg.norm(matrix_to_axis_angle(np.diag([-1.0, -1.0, 1.0]))), np.pi)


def test_6d_round_trip_and_gram_schmidt(rng):
    mats = random_matrices(rng)
    six = matrix_to_6d(mats)
    assert np.allclose(six[:, :3], mats[:, :, 0]) and np.allclose(six[:, 3:], mats[:, :, 1])
    assert np.allclose(sixd_to_matrix(six), mats, atol=1e-12)
    noisy = sixd_to_matrix(six * 2.5 + rng.normal(scale=0.05, size=six.shape))
    assert np.allclose(noisy @ np.swapaxes(noisy, -1, -2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(noisy), 1.0)
    # hand case: a1 = (2, 0, 0), a2 = (1, 3, 0) -> b1 = x, b2 = y, b3 = z
    assert np.allclose(sixd_to_matrix([2, 0, 0, 1, 3, 0]), np.eye(3))
    with pytest.raises(ValueError, match="parallel"):
        sixd_to_matrix([1, 0, 0, 2, 0, 0])


def test_unwrap_degrees():
    # 170 -> -170 is a +20 step, -170 -> -150 another +20
    assert np.allclose(unwrap_degrees([170.0, -170.0, -150.0]), [170.0, 190.0, 210.0])
    track = np.column_stack([np.linspace(0, 1000, 60), np.linspace(0, -2482, 60)])
    wrapped = (track + 180) % 360 - 180
    assert np.allclose(unwrap_degrees(wrapped), track)
    assert np.allclose(unwrap_degrees(wrapped.T, axis=1), track.T)
    with pytest.raises(ValueError, match="time"):
        unwrap_degrees(5.0)


def test_input_validation_messages():
    with pytest.raises(ValueError, match=r"angles.*\(\.\.\., 3\).*\(4, 2\)"):
        euler_to_matrix(np.zeros((4, 2)), "XYZ")
    with pytest.raises(ValueError, match="order"):
        euler_to_matrix(np.zeros(3), "XYX")
    with pytest.raises(ValueError, match="order"):
        euler_to_matrix(np.zeros(3), "Xyz")
    with pytest.raises(ValueError, match=r"matrix.*\(5, 3, 2\)"):
        matrix_to_euler(np.zeros((5, 3, 2)), "XYZ")
    with pytest.raises(ValueError, match=r"quat.*\(3,\)"):
        quat_to_matrix(np.zeros(3))
    with pytest.raises(ValueError, match="sixd"):
        sixd_to_matrix(np.zeros((2, 5)))
    with pytest.raises(TypeError, match="numeric"):
        axis_angle_to_matrix("abc")


def _geodesic(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (rad) of a^T b, from both its sine and cosine parts (exact near 0 and near pi)."""
    d = np.swapaxes(a, -1, -2) @ b
    sin = np.linalg.norm(
        np.stack([d[..., 2, 1] - d[..., 1, 2], d[..., 0, 2] - d[..., 2, 0], d[..., 1, 0] - d[..., 0, 1]], -1),
        axis=-1,
    )
    return np.arctan2(sin / 2, (np.trace(d, axis1=-2, axis2=-1) - 1) / 2)


def _hard_rotations(rng, n=100_000):
    """10^5 rotations: uniform ones, plus the edge cases (identity, 1e-12..1e-4 rad, pi and pi - 1e-9..1e-5 about
    random axes and the coordinate axes, Euler gimbal lock at +-90 degrees in the middle angle)."""
    axes = rng.normal(size=(2000, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    axes[:3] = np.eye(3)
    tiny = np.logspace(-12, -4, 1000)
    near_pi = np.pi - np.concatenate([[0.0], np.logspace(-9, -5, 999)])
    edge = np.concatenate([axes[:1000] * tiny[:, None], axes[1000:] * near_pi[:, None], np.zeros((1, 3))])
    gimbal = np.radians(rng.uniform(-180, 180, size=(1000, 3)))
    gimbal[:, 1] = np.radians(rng.choice([-90.0, 90.0], size=1000) + rng.normal(scale=1e-7, size=1000))
    uniform = Rotation.random(n - len(edge) - len(gimbal), random_state=rng.integers(1 << 31)).as_rotvec()
    mats = axis_angle_to_matrix(np.concatenate([uniform, edge]))
    return np.concatenate([mats, euler_to_matrix(gimbal, "XYZ", degrees=False)])


def test_every_representation_round_trips_below_a_microradian_on_hard_rotations(rng):
    mats = _hard_rotations(rng)
    assert mats.shape == (100_000, 3, 3)
    trips = {
        "axis-angle": axis_angle_to_matrix(matrix_to_axis_angle(mats)),
        "quaternion": quat_to_matrix(matrix_to_quat(mats)),
        "6d": sixd_to_matrix(matrix_to_6d(mats)),
        **{f"euler {o}": euler_to_matrix(matrix_to_euler(mats, o), o) for o in ALL_ORDERS},
    }
    for name, back in trips.items():
        assert _geodesic(mats, back).max() < 1e-6, name
    # and against scipy (its axis-angle and quaternion of the same matrices, up to the quaternion's sign)
    np.testing.assert_allclose(axis_angle_to_matrix(Rotation.from_matrix(mats).as_rotvec()), mats, atol=1e-9)
    ours = matrix_to_quat(mats)
    theirs = Rotation.from_matrix(mats).as_quat(scalar_first=True)
    assert _geodesic(quat_to_matrix(ours), quat_to_matrix(theirs)).max() < 1e-6


def test_euler_to_6d_is_the_6d_of_each_triplet(rng):
    angles = rng.uniform(-180, 180, size=(5, 141))
    six = euler_to_6d(angles)
    assert six.shape == (5, 282)
    by_hand = matrix_to_6d(euler_to_matrix(angles.reshape(5, 47, 3), "XYZ")).reshape(5, 282)
    np.testing.assert_array_equal(six, by_hand)
    # continuity: a joint turning through 180 degrees jumps in Euler angles, not in 6D
    track = np.array([[0.0, 0.0, 179.0], [0.0, 0.0, -179.0]])
    assert np.abs(np.diff(track, axis=0)).max() == 358.0
    assert np.abs(np.diff(euler_to_6d(track), axis=0)).max() < np.radians(2.0) + 1e-12
    with pytest.raises(ValueError, match="triplets"):
        euler_to_6d(np.zeros((2, 4)))


@pytest.mark.parametrize("order", ALL_ORDERS)
def test_nearest_euler_finds_the_equivalent_triple_of_the_reference(order, rng):
    """A reference that is the other branch of the same rotations, with random 360° turns per angle, is found
    exactly; for any reference the result gives the same rotations and is no farther than either branch."""
    angles = matrix_to_euler(random_matrices(rng, 300), order)  # the principal branch, |middle| <= 90
    other = np.stack([angles[:, 0] + 180, 180 - angles[:, 1], angles[:, 2] + 180], axis=-1)
    turns = 360.0 * rng.integers(-7, 8, size=angles.shape)
    flip = rng.random(len(angles)) < 0.5
    reference = np.where(flip[:, None], other, angles) + turns
    np.testing.assert_allclose(euler_to_matrix(other, order), euler_to_matrix(angles, order), atol=1e-12)
    np.testing.assert_allclose(nearest_euler(angles, reference), reference, atol=1e-9)
    np.testing.assert_allclose(nearest_euler(other, reference), reference, atol=1e-9)
    anywhere = rng.uniform(-2000, 2000, size=angles.shape)
    near = nearest_euler(angles, anywhere)
    np.testing.assert_allclose(euler_to_matrix(near, order), euler_to_matrix(angles, order), atol=1e-9)
    cost = np.abs(near - anywhere).sum(axis=-1)
    for cand in (angles, other):  # each branch at its own best 360° turns
        best = cand - 360.0 * np.round((cand - anywhere) / 360.0)
        assert (cost <= np.abs(best - anywhere).sum(axis=-1) + 1e-9).all()
