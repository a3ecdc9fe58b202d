"""A generated dance placed on stage: floor, place, facing, time clamping."""

from __future__ import annotations

import numpy as np
import pytest

from virja import quat
from virja.dance.stage import DANCER_PLACE_XZ, DancerTrack
from virja.motion.bvh import Bvh
from virja.motion.export import skeleton_joints
from virja.motion.skeleton import SKELETON


def turning_dance(n: int = 31) -> Bvh:
    """The project skeleton standing 3 m left, facing +x, turning its head, rising 0.1 m."""
    joints = skeleton_joints()
    rot = np.tile(quat.identity((SKELETON.n_joints,)), (n, 1, 1))
    rot[:, 0] = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.array(np.pi / 2))
    head = SKELETON.names.index("Head")
    rot[:, head] = quat.from_axis_angle(np.tile([0.0, 1.0, 0.0], (n, 1)), np.linspace(0.0, 1.0, n))
    pos = np.broadcast_to(SKELETON.offsets, (n, SKELETON.n_joints, 3)).copy()
    pos[:, 0] = np.array([-3.0, 0.95, 0.0]) + np.linspace(0.0, 0.1, n)[:, None] * [0, 1, 0]
    return Bvh(joints, 1 / 30, rot, pos)


def test_first_frame_stands_on_the_floor_at_the_dancer_place() -> None:
    track = DancerTrack(turning_dance(), t0_s=2.0)
    fig = track.pose(2.0)
    lowest = np.argmin(fig.positions[:, 1])
    assert fig.positions[lowest, 1] == pytest.approx(fig.radii[lowest])
    assert np.allclose(fig.position("Hips")[[0, 2]], DANCER_PLACE_XZ)


def test_the_dancer_is_turned_to_face_the_audience() -> None:
    fig = DancerTrack(turning_dance()).pose(0.0)
    fwd = quat.rotate(fig.rotations[0], np.array([0.0, 0.0, 1.0]))
    assert np.allclose(fwd, [0.0, 0.0, 1.0], atol=1e-9)


def test_pose_interpolates_between_frames_and_clamps_outside() -> None:
    track = DancerTrack(turning_dance(), t0_s=1.0)
    y = lambda t: float(track.pose(t).position("Hips")[1])  # noqa: E731
    assert y(0.0) == y(1.0)  # before frame 0: held
    assert y(100.0) == y(2.0)  # after the last frame (1 s long): held
    assert y(1.5) == pytest.approx((y(1.0) + y(2.0)) / 2, abs=1e-9)  # halfway: linear


def test_every_frame_stands_on_the_floor() -> None:
    """The waist rises 10 cm over the dance (join drift): the feet stay on the floor."""
    track = DancerTrack(turning_dance())
    for t in (0.0, 0.5, 1.0):
        fig = track.pose(t)
        assert float(np.min(fig.positions[:, 1] - fig.radii)) == pytest.approx(0.0, abs=1e-9)


def test_the_dancer_stands_clear_of_the_kit_and_the_bass() -> None:
    from virja.geometry import GEOMETRY

    track = DancerTrack(turning_dance())
    kit_front = max(  # the nearest point of any drum or cymbal to the audience
        float(p.centre[2]) + max(float(getattr(p, "depth", 0.0)) / 2, float(p.radius))
        for p in GEOMETRY.kit.pieces.values()
    )
    assert float(track.positions[:, :, 2].min()) > kit_front + 0.2
    bassist = GEOMETRY.stage.bassist_origin
    gap = np.linalg.norm(track.positions[:, :, [0, 2]] - bassist[[0, 2]], axis=-1)
    assert float(gap.min()) > 0.8
