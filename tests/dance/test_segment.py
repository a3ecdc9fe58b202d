"""Tests of virja.dance.segment (alpha, Kalman smoothing, cut points)."""

from __future__ import annotations

import numpy as np
import pytest

from virja import quat
from virja.dance import segment
from virja.dance.beats import extract_beats
from virja.dance.synth_capture import Teacher, make_teacher, min_jerk, off_beats, random_boundaries


def _cuts(
    t: Teacher, beats: object = None, q: float | None = segment.DEFAULT_Q_OVER_R
) -> list[int]:
    w = segment.part_weights(t.bvh.names, "legs")
    cuts, _ = segment.segment_motion(
        t.bvh.rotations, 30.0, t.beats_s if beats is None else beats, w, q_over_r=q
    )  # type: ignore[arg-type]
    return [c.frame for c in cuts]


def test_leg_weights_select_leg_joints_not_the_root(bounce: Teacher) -> None:
    w = segment.part_weights(bounce.bvh.names, "legs")
    chosen = [n for n, x in zip(bounce.bvh.names, w, strict=True) if x]
    assert chosen == ["LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot"]


def test_arm_weights_select_arm_joints(bounce: Teacher) -> None:
    w = segment.part_weights(bounce.bvh.names, "arms")
    assert [n for n, x in zip(bounce.bvh.names, w, strict=True) if x] == [
        "LeftArm",
        "LeftForeArm",
        "RightArm",
        "RightForeArm",
    ]


def test_all_weights_are_ones() -> None:
    assert segment.part_weights(["a", "b"], "all").tolist() == [1.0, 1.0]


def test_constant_spin_has_constant_angular_velocity_and_zero_alpha() -> None:
    """A joint turning 0.1 rad per frame about z: omega = 3 rad/s about z, alpha = 0."""
    ang = 0.1 * np.arange(20)
    q = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), ang)[:, None, :]
    om = segment.angular_velocity(q, 30.0)
    np.testing.assert_allclose(om[:, 0], np.tile([0.0, 0.0, 3.0], (19, 1)), atol=1e-9)
    np.testing.assert_allclose(
        segment.mean_angular_acceleration(q, 30.0, np.ones(1)), 0.0, atol=1e-6
    )


def test_angular_velocity_is_in_the_parts_own_axes() -> None:
    """Parent turned 90 deg about y: a local x spin stays about local x."""
    base = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.pi / 2)
    spin = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), 0.05 * np.arange(5))
    q = quat.multiply(base, spin)[:, None, :]
    om = segment.angular_velocity(q, 10.0)
    np.testing.assert_allclose(om[:, 0], np.tile([0.5, 0.0, 0.0], (4, 1)), atol=1e-9)


def test_alpha_is_sqrt_of_weighted_sum_of_part_accelerations() -> None:
    rng = np.random.default_rng(0)
    q = quat.normalize(rng.standard_normal((10, 3, 4)))
    a = segment.part_acceleration(q, 30.0)
    w = np.array([1.0, 0.0, 2.0])
    np.testing.assert_allclose(segment.mean_angular_acceleration(q, 30.0, w), np.sqrt(a @ w))


def test_negative_weights_raise() -> None:
    with pytest.raises(ValueError):
        segment.mean_angular_acceleration(quat.identity((5, 1)), 30.0, np.array([-1.0]))


def test_kalman_smoother_keeps_a_constant_and_reduces_noise() -> None:
    rng = np.random.default_rng(0)
    np.testing.assert_allclose(segment.kalman_smooth(np.full(50, 3.0)), 3.0)
    y = 1.0 + rng.standard_normal(500)
    assert np.std(segment.kalman_smooth(y, 0.1)) < 0.5 * np.std(y)


def test_kalman_smoother_follows_a_ramp_without_lag_in_the_middle() -> None:
    """RTS smoothing is two-sided: a straight line stays put away from the ends."""
    y = np.arange(100.0)
    np.testing.assert_allclose(segment.kalman_smooth(y, 1.0)[20:80], y[20:80], atol=1e-6)


def test_flat_bottom_minimum_is_its_middle_frame() -> None:
    x = np.array([3.0, 2.0, 0.0, 0.0, 0.0, 1.0, 2.0, 1.0, 2.0])
    assert segment.local_minima(x).tolist() == [3, 7]


def test_min_jerk_has_zero_velocity_and_acceleration_at_the_ends() -> None:
    s = np.linspace(0, 1, 10001)
    y = min_jerk(s)
    v = np.gradient(y, s)
    a = np.gradient(v, s)
    assert y[0] == 0 and y[-1] == pytest.approx(1)
    assert abs(v[0]) < 1e-3 and abs(v[-1]) < 1e-3
    assert abs(a[2]) < 0.05 and abs(a[-3]) < 0.05  # a(s) = 60 s + O(s^2)


@pytest.mark.parametrize("style", ["bounce", "sway", "kick"])
def test_unsmoothed_legs_cut_exactly_at_the_known_boundaries(style: str) -> None:
    rng = np.random.default_rng(7)
    b = random_boundaries(15, rng)
    t = make_teacher(style, b, seed=7)
    assert _cuts(t, q=None) == list(b)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_default_smoothing_finds_every_boundary_within_two_frames(seed: int) -> None:
    rng = np.random.default_rng(seed)
    b = random_boundaries(15, rng)
    cuts = _cuts(make_teacher("sway", b, seed=seed))
    assert len(cuts) == len(b)
    assert np.max(np.abs(np.array(cuts) - np.array(b))) <= 2


def test_off_beats_on_acceleration_peaks_are_not_cuts(bounce: Teacher) -> None:
    offs = off_beats(bounce.boundaries)
    assert offs, "the fixture must have off-beats to test"
    cuts = _cuts(bounce, q=None)
    for f in offs:
        assert min(abs(c - f) for c in cuts) > 3


def test_a_minimum_without_a_beat_is_not_a_cut(bounce: Teacher) -> None:
    """Dropping the beat on boundary 5 removes exactly that cut."""
    b = list(bounce.boundaries)
    beats = [x for x in bounce.beats_s if abs(x * 30 - b[5]) > 0.01]
    assert _cuts(bounce, beats, q=None) == b[:5] + b[6:]


def test_a_beat_farther_than_the_tolerance_is_not_a_cut(bounce: Teacher) -> None:
    b = list(bounce.boundaries)
    beats = [x + (5 / 30 if abs(x * 30 - b[3]) < 0.01 else 0.0) for x in bounce.beats_s]
    assert b[3] not in _cuts(bounce, beats, q=None)


def test_arms_moving_off_the_beat_give_other_cuts_than_the_legs(bounce: Teacher) -> None:
    w = segment.part_weights(bounce.bvh.names, "arms")
    cuts, _ = segment.segment_motion(bounce.bvh.rotations, 30.0, bounce.beats_s, w)
    assert len(cuts) < len(bounce.boundaries) - 3


def test_beats_extracted_from_synthetic_music_cut_within_two_frames(
    bounce: Teacher, bounce_music: np.ndarray
) -> None:
    cuts = _cuts(bounce, extract_beats(bounce_music).tolist())
    assert len(cuts) == len(bounce.boundaries)
    assert np.max(np.abs(np.array(cuts) - np.array(bounce.boundaries))) <= 2
