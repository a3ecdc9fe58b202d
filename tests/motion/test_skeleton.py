"""Forward kinematics: rest offsets, parent rotations carried down, vectorised frames."""

from __future__ import annotations

import numpy as np

from virja import quat
from virja.motion.ik import two_bone
from virja.motion.skeleton import SKELETON as SK


def test_rest_pose_positions_are_summed_offsets() -> None:
    pos = SK.rest_positions(np.array([1.0, 2.0, 3.0]))
    for i in range(1, SK.n_joints):
        np.testing.assert_allclose(pos[i], pos[SK.parents[i]] + SK.offsets[i], atol=1e-12)
    np.testing.assert_allclose(pos[0], [1, 2, 3])


def test_root_rotation_rotates_the_whole_body() -> None:
    loc = quat.identity((SK.n_joints,))
    q = quat.from_axis_angle([0, 1, 0], np.pi / 2)
    loc[0] = q
    pos, rot = SK.fk(loc, np.zeros(3))
    np.testing.assert_allclose(pos, quat.rotate(q, SK.rest_positions()), atol=1e-12)
    assert quat.angle_between(rot, q).max() < 1e-12


def test_elbow_rotation_moves_only_its_descendants() -> None:
    loc = quat.identity((SK.n_joints,))
    loc[SK.index("LeftForeArm")] = quat.from_axis_angle([1, 0, 0], -np.pi / 2)
    pos, _ = SK.fk(loc, np.zeros(3))
    rest = SK.rest_positions()
    moved = {SK.index(n) for n in ("LeftHand", "LeftHandEnd")}
    for i in range(SK.n_joints):
        if i in moved:
            assert np.linalg.norm(pos[i] - rest[i]) > 0.1
        else:
            np.testing.assert_allclose(pos[i], rest[i], atol=1e-12)
    # the forearm now points forward (+z): the hand is 0.26 m in front of the elbow
    np.testing.assert_allclose(
        pos[SK.index("LeftHand")] - pos[SK.index("LeftForeArm")], [0, 0, 0.26], atol=1e-12
    )


def test_fk_is_vectorised_over_frames() -> None:
    rng = np.random.default_rng(1)
    loc = quat.normalize(rng.normal(size=(6, SK.n_joints, 4)))
    roots = rng.normal(size=(6, 3))
    pos, rot = SK.fk(loc, roots)
    for k in range(6):
        p1, r1 = SK.fk(loc[k], roots[k])
        np.testing.assert_allclose(pos[k], p1, atol=1e-12)
        np.testing.assert_allclose(rot[k], r1, atol=1e-12)


def test_two_bone_ik_reaches_target_and_keeps_bone_lengths() -> None:
    root = np.array([0.2, 1.0, 0.0])
    target = np.array([0.3, 0.8, 0.4])
    sol = two_bone(
        root,
        target,
        root + np.array([0.5, -0.3, -0.2]),
        0.29,
        0.26,
        np.array([0, -1.0, 0]),
        np.array([-1.0, 0, 0]),
    )
    assert sol.reached
    np.testing.assert_allclose(sol.end, target, atol=1e-12)
    assert abs(np.linalg.norm(sol.elbow - root) - 0.29) < 1e-12
    assert abs(np.linalg.norm(target - sol.elbow) - 0.26) < 1e-12
    # the bones' world rotations carry the rest direction onto the solved bones
    np.testing.assert_allclose(root + quat.rotate(sol.upper, [0, -0.29, 0]), sol.elbow, atol=1e-12)
    np.testing.assert_allclose(
        sol.elbow + quat.rotate(sol.lower, [0, -0.26, 0]), target, atol=1e-12
    )


def test_two_bone_ik_clamps_out_of_reach() -> None:
    sol = two_bone(
        np.zeros(3),
        np.array([0, 0, 2.0]),
        np.array([0, -1.0, 0]),
        0.3,
        0.3,
        np.array([0, -1.0, 0]),
        np.array([-1.0, 0, 0]),
    )
    assert not sol.reached
    assert np.linalg.norm(sol.end) < 0.6 + 1e-9


def test_clip_joint_angles_stay_within_limits() -> None:
    from virja.motion.clip import default_library

    for clip in default_library().clips():
        ang = np.degrees(quat.angle(clip.rotations))
        assert np.all(ang.max(axis=0) <= SK.limits_deg + 1e-6), clip.name


def test_frames_of_a_few_rows_equal_the_arrays_and_are_orthonormal() -> None:
    from virja.motion import ik

    rng = np.random.default_rng(3)
    n = 3 * ik._FEW_FRAMES  # the arrays; one row at a time takes Python floats
    d, h = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    h[0] = 2.0 * d[0]  # parallel: h is nothing after it is made perpendicular
    for floor in (1e-12, 0.0):
        many = ik.frames(d, h, floor)
        few = np.stack([ik.frames(d[i : i + 1], h[i : i + 1], floor)[0] for i in range(n)])
        np.testing.assert_allclose(few, many, rtol=0, atol=1e-15)
        ok = many[1:]
        np.testing.assert_allclose(
            ok @ np.swapaxes(ok, -1, -2), np.broadcast_to(np.eye(3), ok.shape), atol=1e-12
        )
        np.testing.assert_allclose(np.linalg.det(ok), 1.0, atol=1e-12)
        assert np.allclose(many[1:, :, 0] * np.linalg.norm(d[1:], axis=-1, keepdims=True), d[1:])
    with np.errstate(invalid="ignore", divide="ignore"):  # a zero direction: nan, as arrays
        assert np.isnan(ik.frames(np.zeros((1, 3)), np.ones((1, 3)))).all()
