"""Tempo maps: beats <-> seconds across tempo changes."""

from __future__ import annotations

import pytest

from virja.tempo import ConstantTempo, TempoMap


def test_beat_at_crosses_a_tempo_change() -> None:
    m = TempoMap([(0.0, 0.5), (2.0, 0.25)])
    assert m.beat_at(2.0) == pytest.approx(4.0)
    assert m.beat_at(3.0) == pytest.approx(8.0)


def test_time_at_beat_inverts_beat_at() -> None:
    m = TempoMap([(0.0, 0.5), (1.5, 0.4), (4.0, 0.6)])
    for t in (0.0, 0.7, 1.5, 2.2, 4.0, 7.3):
        assert m.time_at_beat(m.beat_at(t)) == pytest.approx(t)


def test_seconds_per_beat_before_first_change_uses_first_tempo() -> None:
    m = TempoMap([(1.0, 0.3)])
    assert m.seconds_per_beat_at(0.0) == 0.3


def test_beat_times_lists_whole_beats() -> None:
    assert TempoMap([(0.0, 0.5)]).beat_times(0.2, 1.6) == pytest.approx([0.5, 1.0, 1.5])


def test_non_positive_tempo_is_rejected() -> None:
    with pytest.raises(ValueError, match="must be > 0"):
        TempoMap([(0.0, 0.0)])
    with pytest.raises(ValueError):
        ConstantTempo(-1.0)
