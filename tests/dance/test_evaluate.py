"""Tests of virja.dance.evaluate (beat alignment over music beats, feature distance)."""

from __future__ import annotations

import numpy as np
import pytest

from virja.dance import evaluate
from virja.dance.synth_capture import Teacher, make_teacher, random_boundaries


def test_beat_align_is_one_on_the_beats_and_falls_with_distance() -> None:
    assert evaluate.beat_align([1.0, 2.0, 3.0], [1.0, 2.0]) == 1.0
    assert evaluate.beat_align([1.05], [1.0]) == pytest.approx(np.exp(-0.5))  # sigma 0.05 s
    assert evaluate.beat_align([], [1.0]) == 0.0


def test_beat_align_averages_over_music_beats() -> None:
    """A music beat with no motion beat near it counts; extra motion beats do not."""
    assert evaluate.beat_align([1.0], [1.0, 2.0]) == pytest.approx(0.5, abs=1e-6)
    assert evaluate.beat_align([1.0, 1.5, 2.0, 2.5], [1.0, 2.0]) == 1.0


def test_random_motion_beats_score_low() -> None:
    rng = np.random.default_rng(0)
    music = np.arange(0.5, 30.0, 0.5)
    motion = np.sort(rng.uniform(0, 30, 40))
    assert evaluate.beat_align(motion, music) < 0.35


def test_world_positions_put_the_feet_below_the_waist_at_rest(bounce: Teacher) -> None:
    pos = evaluate.world_positions(bounce.bvh)
    foot = bounce.bvh.names.index("LeftFoot")
    assert pos[0, foot, 1] < pos[0, 0, 1] - 50


def test_teacher_motion_beats_align_with_its_beats_better_than_shifted_beats(
    bounce: Teacher,
) -> None:
    on = evaluate.beat_align_bvh(bounce.bvh, bounce.beats_s)
    off = evaluate.beat_align_bvh(bounce.bvh, [b + 0.25 for b in bounce.beats_s])
    assert on > 0.4 and on > 2 * off


def _capture(style: str, seed: int, n: int = 20) -> object:
    return make_teacher(style, random_boundaries(n, np.random.default_rng(seed)), seed=seed).bvh


def test_feature_distance_is_zero_for_the_same_windows_and_grows_with_difference() -> None:
    a = evaluate.motion_features(_capture("bounce", 1))  # type: ignore[arg-type]
    b = evaluate.motion_features(_capture("kick", 2))  # type: ignore[arg-type]
    ref = np.concatenate([a, b])
    assert evaluate.feature_distance(a, a, ref) == 0.0
    assert evaluate.feature_distance(a, b, ref) > 0.5


def test_held_out_capture_of_a_teacher_is_nearer_than_another_teacher() -> None:
    """The measure is about the teacher, not the capture: a second capture of the same
    style is nearer than any capture of another style."""
    styles = ("bounce", "sway", "kick")
    train = {s: evaluate.motion_features(_capture(s, i)) for i, s in enumerate(styles)}  # type: ignore[arg-type]
    held = {s: evaluate.motion_features(_capture(s, 10 + i)) for i, s in enumerate(styles)}  # type: ignore[arg-type]
    ref = np.concatenate(list(held.values()))
    for s in styles:
        own = evaluate.feature_distance(train[s], held[s], ref)
        others = [evaluate.feature_distance(train[s], held[o], ref) for o in styles if o != s]
        assert own < min(others), (s, own, others)
