"""Quaternion convention (w x y z), slerp edge cases and the pyrr regression."""

from __future__ import annotations

import numpy as np
import pytest

from virja import quat as Q

RNG = np.random.default_rng(7)


def _rand(n: int) -> np.ndarray:
    return Q.normalize(RNG.normal(size=(n, 4)))


def test_rotate_one_is_rotate_for_one_vector() -> None:
    for q, v in zip(_rand(50), RNG.normal(size=(50, 3)), strict=True):
        np.testing.assert_allclose(Q.rotate_one(q, v), Q.rotate(q, v), atol=1e-12)


def test_rotate_about_is_the_axis_angle_rotation() -> None:
    axis = RNG.normal(size=(40, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angle = RNG.uniform(-4.0, 4.0, size=40)
    v = RNG.normal(size=(40, 3))
    np.testing.assert_allclose(
        Q.rotate_about(v, axis, angle), Q.rotate(Q.from_axis_angle(axis, angle), v), atol=1e-12
    )


def test_cross_is_numpys() -> None:
    a, b = RNG.normal(size=(30, 3)), RNG.normal(size=(30, 3))
    np.testing.assert_array_equal(Q.cross(a, b), np.cross(a, b))
    np.testing.assert_array_equal(Q.cross(a, b[0]), np.cross(a, b[0]))


def test_multiply_matches_matrix_product() -> None:
    a, b = _rand(50), _rand(50)
    np.testing.assert_allclose(
        Q.to_matrix(Q.multiply(a, b)), Q.to_matrix(a) @ Q.to_matrix(b), atol=1e-12
    )


def test_rotate_matches_matrix() -> None:
    q = _rand(20)
    v = RNG.normal(size=(20, 3))
    np.testing.assert_allclose(
        Q.rotate(q, v), np.einsum("nij,nj->ni", Q.to_matrix(q), v), atol=1e-12
    )


def test_axis_angle_is_scalar_first() -> None:
    q = Q.from_axis_angle([0, 0, 1], np.pi / 2)
    np.testing.assert_allclose(q, [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])
    np.testing.assert_allclose(Q.rotate(q, [1.0, 0, 0]), [0, 1, 0], atol=1e-12)


def test_axis_angle_round_trip() -> None:
    q = _rand(30)
    axis, ang = Q.to_axis_angle(q)
    assert np.all(Q.angle_between(Q.from_axis_angle(axis, ang), q) < 1e-9)


def test_matrix_round_trip() -> None:
    q = _rand(100)
    assert np.all(Q.angle_between(Q.from_matrix(Q.to_matrix(q)), q) < 1e-9)


def test_inverse_undoes_rotation() -> None:
    q = _rand(10)
    np.testing.assert_allclose(Q.multiply(q, Q.inverse(q)), Q.identity((10,)), atol=1e-12)


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
def test_euler_round_trip_every_order(order: str) -> None:
    q = _rand(200)
    assert np.all(Q.angle_between(Q.from_euler(Q.to_euler(q, order), order), q) < 1e-9)


def test_euler_zxy_is_rz_rx_ry() -> None:
    """BVH 'Zrotation Xrotation Yrotation' means R = Rz @ Rx @ Ry."""
    z, x, y = 0.3, -0.7, 1.1
    q = Q.from_euler([z, x, y], "ZXY")
    want = Q.multiply(
        Q.multiply(Q.from_axis_angle([0, 0, 1], z), Q.from_axis_angle([1, 0, 0], x)),
        Q.from_axis_angle([0, 1, 0], y),
    )
    assert Q.angle_between(q, want) < 1e-12


def test_euler_gimbal_lock_round_trip() -> None:
    q = Q.from_euler([[0.4, np.pi / 2, -0.3], [0.2, -np.pi / 2, 0.5]], "ZXY")
    back = Q.from_euler(Q.to_euler(q, "ZXY"), "ZXY")
    assert np.all(Q.angle_between(back, q) < 1e-7)


def test_slerp_endpoints_and_midpoint() -> None:
    a = Q.from_axis_angle([0, 1, 0], 0.2)
    b = Q.from_axis_angle([0, 1, 0], 1.0)
    assert Q.angle_between(Q.slerp(a, b, 0.0), a) < 1e-12
    assert Q.angle_between(Q.slerp(a, b, 1.0), b) < 1e-12
    assert Q.angle_between(Q.slerp(a, b, 0.5), Q.from_axis_angle([0, 1, 0], 0.6)) < 1e-12


def test_slerp_antipodal_takes_short_way() -> None:
    """b given as -b (same rotation): the path must not swing through 180 degrees."""
    a = Q.from_axis_angle([1, 0, 0], 0.0)
    b = -Q.from_axis_angle([1, 0, 0], 0.8)
    mid = Q.slerp(a, b, 0.5)
    assert abs(Q.angle(mid) - 0.4) < 1e-12


def test_slerp_pyrr_regression_near_parallel_negative_dot() -> None:
    """pyrr's near-parallel fallback forgets the sign flip: a 0.1 rad step became ~171 deg.

    With a = identity and b = -(0.1 rad about z), every point of our slerp is
    within 0.1 rad of a (pyrr.quaternion.slerp lerps a and the *unflipped* b).
    """
    a = Q.identity()
    b = -Q.from_axis_angle([0, 0, 1], 0.1)
    ts = np.linspace(0.0, 1.0, 11)
    path = Q.slerp(a, b, ts)
    angles = Q.angle_between(path, a)
    assert np.all(angles <= 0.1 + 1e-12)
    np.testing.assert_allclose(angles, 0.1 * ts, atol=1e-9)


def test_slerp_tiny_angle_is_finite_and_unit() -> None:
    a = Q.from_axis_angle([0, 0, 1], 1e-9)
    b = Q.from_axis_angle([0, 0, 1], 3e-9)
    m = Q.slerp(a, b, 0.5)
    assert np.all(np.isfinite(m))
    assert abs(np.linalg.norm(m) - 1.0) < 1e-12
    assert Q.angle_between(m, Q.from_axis_angle([0, 0, 1], 2e-9)) < 1e-12


def test_slerp_identical_inputs() -> None:
    q = _rand(5)
    np.testing.assert_allclose(Q.slerp(q, q, 0.3), q, atol=1e-12)


def test_slerp_broadcasts_over_frames_and_joints() -> None:
    a = _rand(12).reshape(3, 4, 4)
    b = _rand(12).reshape(3, 4, 4)
    t = np.linspace(0, 1, 3)[:, None]
    out = Q.slerp(a, b, t)
    assert out.shape == (3, 4, 4)
    assert Q.angle_between(out[2], b[2]).max() < 1e-9


def test_from_two_vectors_including_opposite() -> None:
    for a, b in [([1, 0, 0], [0, 1, 0]), ([0, 0, 1], [0, 0, -1]), ([1, 2, 3], [1, 2, 3])]:
        q = Q.from_two_vectors(a, b)
        r = Q.rotate(q, np.array(a, dtype=float) / np.linalg.norm(a))
        np.testing.assert_allclose(r, np.array(b, dtype=float) / np.linalg.norm(b), atol=1e-12)


def test_bad_shape_raises_value_error() -> None:
    with pytest.raises(ValueError, match="last axis of 4"):
        Q.multiply(np.zeros(3), np.zeros(4))


# A few quaternions (up to quat._FEW rows) are worked out in Python floats, more as
# arrays: the two ways must agree, row by row, for every function with such a path.
_MANY = 3 * Q._FEW  # enough rows for the array path


def _both_ways(fn, *args: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # type: ignore[no-untyped-def]
    """``fn`` over all rows at once (the arrays) and one row at a time (Python floats)."""
    assert all(len(a) == _MANY for a in args)
    many = fn(*args)
    few = np.stack([fn(*(a[i : i + 1] for a in args))[0] for i in range(_MANY)])
    return many, few


def test_few_rows_in_python_floats_equal_the_arrays() -> None:
    a, b = _rand(_MANY), _rand(_MANY)
    b[:5] = -a[:5] + 1e-9  # near-antipodal: slerp flips the sign
    b[5:9] = a[5:9]  # identical: slerp's linear fallback
    t = RNG.uniform(-0.2, 1.2, size=_MANY)
    v = RNG.normal(size=(_MANY, 3))
    angle = RNG.uniform(-4.0, 4.0, size=_MANY)
    # matrices whose largest of trace, xx, yy, zz picks each of Shepperd's four rows
    turns = np.concatenate(
        [Q.identity((4,)), Q.from_axis_angle(np.eye(3), np.full(3, 3.0)), _rand(_MANY - 7)]
    )
    raw = RNG.normal(size=(_MANY, 4))
    raw[0] = 0.0  # a zero quaternion normalises to the identity
    for name, (many, few) in {
        "multiply": _both_ways(Q.multiply, a, b),
        "normalize": _both_ways(Q.normalize, raw),
        "rotate": _both_ways(Q.rotate, a, v),
        "cross": _both_ways(Q.cross, v, v[::-1].copy()),
        "from_matrix": _both_ways(Q.from_matrix, Q.to_matrix(turns)),
        "from_axis_angle": _both_ways(Q.from_axis_angle, v, angle),
        "slerp": _both_ways(Q.slerp, a, b, t),
    }.items():
        assert many.shape == few.shape, name
        # the same IEEE operations in the same order; sin and cos from numpy and math
        # could differ by an ulp on some platforms
        np.testing.assert_allclose(few, many, rtol=0, atol=1e-15, err_msg=name)


def test_few_rows_broadcast_as_the_arrays_do() -> None:
    a, v = _rand(3), RNG.normal(size=(3, 3))
    assert Q.multiply(a[0], a[:, None]).shape == (3, 1, 4)
    np.testing.assert_array_equal(Q.multiply(a[0], a), np.stack([Q.multiply(a[0], q) for q in a]))
    np.testing.assert_array_equal(Q.rotate(a[0], v), np.stack([Q.rotate(a[0], x) for x in v]))
    np.testing.assert_array_equal(
        Q.from_axis_angle([0.0, 1.0, 0.0], np.array([0.1, 0.2])),
        Q.from_axis_angle(np.array([[0.0, 1.0, 0.0]] * 2), np.array([0.1, 0.2])),
    )
    assert Q.slerp(a[0], a[1], np.array([0.0, 0.5, 1.0])).shape == (3, 4)
    with pytest.raises(ValueError, match="zero vector"):
        Q.from_axis_angle(np.zeros(3), 1.0)
