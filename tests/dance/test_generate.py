"""Tests of virja.dance.generate (choice by sound, stretching, joins, waist increments)."""

from __future__ import annotations

import numpy as np
import pytest

from virja import quat
from virja.dance.database import DanceDatabase, DanceError, Segment
from virja.dance.generate import choose_segment, generate, smooth_join, stretch
from virja.dance.intervals import CorrectedInterval
from virja.dance.synth_music import music


def _new_beats(seed: int, n: int = 16) -> np.ndarray:
    return 0.4 + np.cumsum(np.random.default_rng(seed).uniform(0.3, 1.0, n))


def test_generated_length_runs_to_the_last_beat(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(0)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=1), beats_s=beats)
    frames = np.round(beats * 30).astype(int)
    assert g.bvh.n_frames == frames[-1] + 1
    assert sum(iv.span for iv in g.intervals) == frames[-1] - frames[0]


def test_each_choice_lies_within_the_interval_tolerance(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(1)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=1), beats_s=beats)
    for iv, k in zip(g.intervals, g.choices, strict=True):
        assert abs(bounce_db.segments[k].span - iv.span) <= iv.tolerance


def test_choice_is_the_nearest_sound_among_candidates() -> None:
    seg = [
        Segment(quat.identity((11, 1)), np.zeros((11, 3)), np.array(s), 10)
        for s in ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0])
    ]
    db = DanceDatabase((), 30.0, "legs", tuple(seg))
    assert choose_segment(db, CorrectedInterval(0, 0, 10, 0), np.array([1.2, 0.0, 0.0])) == 1
    assert choose_segment(db, CorrectedInterval(0, 0, 10, 0), np.array([9.0, 0.0, 0.0])) == 2


def test_stretch_keeps_the_ends_and_doubles_the_frames() -> None:
    q = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.linspace(0, 1, 6))[:, None, :]
    seg = Segment(q, np.linspace([0, 0, 0], [5, 0, 0], 6), np.zeros(3), 5)
    rot, pos = stretch(seg, 10)
    assert rot.shape == (11, 1, 4)
    np.testing.assert_allclose(quat.angle(rot[:, 0]), np.linspace(0, 1, 11), atol=1e-9)
    np.testing.assert_allclose(pos[:, 0], np.linspace(0, 5, 11))


def test_join_window_is_the_paper_axis_angle_interpolation() -> None:
    """Frame l of the window is R1 * rot(l theta / h) about the axis of R1^-1 R2."""
    axis = np.array([0.0, 1.0, 0.0])
    rots = np.concatenate(
        [
            np.tile(quat.identity((1, 1)), (10, 1, 1)),
            np.tile(quat.from_axis_angle(axis, 1.0)[None, None], (10, 1, 1)),
        ]
    )
    smooth_join(rots, 10, 10)
    np.testing.assert_allclose(quat.angle(rots[5:16, 0]), np.linspace(0.0, 1.0, 11), atol=1e-9)
    np.testing.assert_allclose(quat.angle(rots[:5, 0]), 0.0, atol=1e-12)  # outside untouched
    np.testing.assert_allclose(quat.angle(rots[16:, 0]), 1.0, atol=1e-12)


def test_joins_have_no_large_posture_jumps(bounce_db: DanceDatabase) -> None:
    """After smoothing, no frame-to-frame turn at a join exceeds the teacher's largest step."""
    beats = _new_beats(2, 24)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=3), beats_s=beats)
    step = quat.angle_between(g.bvh.rotations[:-1], g.bvh.rotations[1:]).max(axis=1)
    teacher_max = max(
        float(quat.angle_between(s.rotations[:-1], s.rotations[1:]).max())
        for s in bounce_db.segments
    )
    for c in g.joins:
        assert step[c - 1] <= 1.5 * teacher_max


def test_waist_stays_in_place_horizontally(bounce_db: DanceDatabase) -> None:
    """The teacher never travels, so accumulated increments keep the waist near its start."""
    beats = _new_beats(3, 24)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=3), beats_s=beats)
    xz = g.bvh.positions[:, 0, [0, 2]]
    assert np.max(np.abs(xz - xz[0])) < 30.0


def test_rumble_music_picks_segments_taught_with_rumble(bounce_db: DanceDatabase) -> None:
    """Music of colour 0 only: chosen segments' a_1 are on average the rumble's (> 1)."""
    beats = _new_beats(4, 20)
    y = music(beats, beats[-1] + 0.5, [0] * (len(beats) - 1), seed=9)
    g = generate(bounce_db, y, beats_s=beats)
    y2 = music(beats, beats[-1] + 0.5, [2] * (len(beats) - 1), seed=9)
    g2 = generate(bounce_db, y2, beats_s=beats)
    a_rumble = np.mean([bounce_db.segments[k].sound[0] for k in g.choices])
    a_hiss = np.mean([bounce_db.segments[k].sound[0] for k in g2.choices])
    assert a_rumble > a_hiss


def test_fewer_than_two_beats_is_a_dance_error(bounce_db: DanceDatabase) -> None:
    with pytest.raises(DanceError, match="at least 2"):
        generate(bounce_db, np.zeros(8000), beats_s=[0.5])


def test_generation_extracts_beats_when_not_given(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(5, 12)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=5))
    assert len(g.beats_s) == len(beats)


def test_choice_uses_standardised_sound_parameters() -> None:
    """a_1 spreads over 10, a_2 over 0.1: a step of 0.1 in a_2 weighs as much as 10 in a_1."""
    sounds = ([0.0, 0.0, 0.0], [10.0, 0.05, 0.0], [0.0, 0.1, 0.0], [10.0, 0.1, 0.0])
    seg = [Segment(quat.identity((11, 1)), np.zeros((11, 3)), np.array(s), 10) for s in sounds]
    db = DanceDatabase((), 30.0, "legs", tuple(seg))
    iv = CorrectedInterval(0, 0, 10, 0)
    # raw distance would pick segment 2 (0.1 away in a_2) over 1 (2 away in a_1)
    assert choose_segment(db, iv, np.array([8.0, 0.1, 0.0])) == 3
    assert choose_segment(db, iv, np.array([2.0, 0.1, 0.0])) == 2


def test_join_window_is_never_shorter_than_ten_frames(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(2)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=1), beats_s=beats)
    assert g.h == max(10, 2 * min(bounce_db.spans))
    assert generate(bounce_db, music(beats, beats[-1] + 0.5, seed=1), beats_s=beats, h=4).h == 4


def test_report_counts_distinct_segments_and_reuse(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(3, 30)
    g = generate(bounce_db, music(beats, beats[-1] + 0.5, seed=1), beats_s=beats)
    assert g.distinct == len(set(g.choices))
    assert g.most_reused == max(g.choices.count(c) for c in g.choices)
    assert 0.0 < g.interpolated_share <= 1.0
    assert f"{g.distinct} distinct" in g.summary()


def test_a_silent_phrase_is_reported_not_given_made_up_sound(
    bounce_db: DanceDatabase, caplog: pytest.LogCaptureFixture
) -> None:
    beats = _new_beats(4)
    x = music(beats, beats[-1] + 0.5, seed=1)
    lo, hi = int(beats[3] * 8000), int(beats[5] * 8000)
    x[lo - 4000 : hi + 4000] = 0.0  # silence around two beat intervals
    g = generate(bounce_db, x, beats_s=beats)
    assert g.unfitted
    assert "not fitted" in caplog.text
    assert "not fitted" in g.summary()


def test_random_choice_control_keeps_lengths_but_not_sound(bounce_db: DanceDatabase) -> None:
    beats = _new_beats(5, 30)
    x = music(beats, beats[-1] + 0.5, seed=1)
    g = generate(bounce_db, x, beats_s=beats)
    r = generate(bounce_db, x, beats_s=beats, random_choice=np.random.default_rng(0))
    assert r.intervals == g.intervals
    for iv, k in zip(r.intervals, r.choices, strict=True):
        assert abs(bounce_db.segments[k].span - iv.span) <= iv.tolerance
