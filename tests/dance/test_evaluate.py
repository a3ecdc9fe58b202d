"""Tests of virja.dance.evaluate (beat alignment, style classifier)."""

from __future__ import annotations

import numpy as np
import pytest

from virja.dance import evaluate
from virja.dance.synth_capture import Teacher, make_teacher, random_boundaries


def test_beat_align_is_one_on_the_beats_and_falls_with_distance() -> None:
    assert evaluate.beat_align([1.0, 2.0], [1.0, 2.0, 3.0]) == 1.0
    assert evaluate.beat_align([1.1], [1.0]) == pytest.approx(np.exp(-0.5))
    assert evaluate.beat_align([], [1.0]) == 0.0


def test_world_positions_put_the_feet_below_the_waist_at_rest(bounce: Teacher) -> None:
    pos = evaluate.world_positions(bounce.bvh)
    foot = bounce.bvh.names.index("LeftFoot")
    assert pos[0, foot, 1] < pos[0, 0, 1] - 50


def test_teacher_motion_beats_align_with_its_beats_better_than_shifted_beats(
    bounce: Teacher,
) -> None:
    on = evaluate.beat_align_bvh(bounce.bvh, bounce.beats_s)
    off = evaluate.beat_align_bvh(bounce.bvh, [b + 0.25 for b in bounce.beats_s])
    assert on > 0.5 and on > off + 0.2


def test_classifier_tells_teachers_apart_on_new_captures() -> None:
    teachers = {
        s: make_teacher(s, random_boundaries(30, np.random.default_rng(i)), seed=i).bvh
        for i, s in enumerate(("bounce", "sway", "kick"))
    }
    fresh = {
        s: make_teacher(s, random_boundaries(20, np.random.default_rng(10 + i)), seed=10 + i).bvh
        for i, s in enumerate(("bounce", "sway", "kick"))
    }
    report = evaluate.style_accuracy(teachers, fresh)
    assert report.accuracy > 0.9
    assert set(report.confusion) == {"bounce", "sway", "kick"}
