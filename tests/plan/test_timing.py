"""Impact alignment (virja.plan.timing)."""

from __future__ import annotations

import pytest

from virja.plan.config import PlanConfig
from virja.plan.timing import align, anticipation_s


def test_anticipation_shortens_with_tempo_and_is_clamped(config: PlanConfig) -> None:
    t = config.timing
    ref = t.get("snare").anticipation_s
    assert anticipation_s(t, "snare", 0.5) == pytest.approx(ref)  # 120 bpm
    assert anticipation_s(t, "snare", 1.0) == pytest.approx(ref)  # 60 bpm: not longer
    assert anticipation_s(t, "snare", 0.2) == pytest.approx(ref * 0.4)  # 300 bpm
    assert anticipation_s(t, "snare", 0.01) == pytest.approx(t.get("snare").min_anticipation_s)


@pytest.mark.parametrize("bpm", [40, 60, 120, 200, 300, 400])
def test_notes_read_one_beat_ahead_are_never_late(config: PlanConfig, bpm: float) -> None:
    spb = 60.0 / bpm
    for kind in config.timing.kinds:
        a = align(config.timing, kind, 10.0, 10.0 - spb, spb)
        assert not a.late
        assert a.impact == pytest.approx(10.0, abs=1e-3)
        assert a.start >= 10.0 - spb - 1e-9


def test_motion_starts_one_anticipation_before_the_note(config: PlanConfig) -> None:
    a = align(config.timing, "crash", 2.0, 0.0, 0.5)
    assert a.start == pytest.approx(2.0 - config.timing.get("crash").anticipation_s)
    assert a.impact == 2.0 and not a.late


def test_late_note_is_compressed_and_marked(config: PlanConfig) -> None:
    mt = config.timing.get("snare")
    # known 10 ms before its time: starts now, impact after the smallest stroke
    a = align(config.timing, "snare", 1.0, 0.99, 0.5)
    assert a.start == 0.99
    assert a.impact == pytest.approx(0.99 + mt.min_anticipation_s)
    assert a.late
    # known a little late for the full stroke but in time for a short one: on time
    b = align(config.timing, "snare", 1.0, 1.0 - mt.min_anticipation_s - 0.01, 0.5)
    assert b.start > 1.0 - mt.anticipation_s
    assert b.impact == 1.0 and not b.late


def test_a_note_played_at_once_is_not_late_but_one_that_arrived_after_it_is() -> None:
    """A jam key (or RTP-MIDI note) strikes the shortest stroke after it arrives: that is
    how it is played, not lateness; arriving after its own time still is late."""
    from virja.plan.config import default_config
    from virja.plan.immediate import IMMEDIATE_STROKE_S, immediate_strokes
    from virja.plan.timing import align

    timing = immediate_strokes(default_config()).timing
    at_once = align(timing, "snare", 10.0, known_s=10.0, seconds_per_beat=0.5)
    assert at_once.impact == 10.0 + IMMEDIATE_STROKE_S and not at_once.late
    after = align(timing, "snare", 10.0, known_s=10.05, seconds_per_beat=0.5)
    assert after.late
    file_note = align(default_config().timing, "snare", 10.0, known_s=10.0, seconds_per_beat=0.5)
    assert file_note.late  # a file's note known at its time is late, as before
