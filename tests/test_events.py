"""The event model: frozen values with checked ranges."""

from __future__ import annotations

import dataclasses

import pytest

from virja.events import Beat, NoteOff, NoteOn, sort_events


def test_events_are_frozen() -> None:
    n = NoteOn(1.0, 9, 38, 100)
    with pytest.raises(dataclasses.FrozenInstanceError):
        n.time_s = 2.0  # type: ignore[misc]


@pytest.mark.parametrize(
    "kwargs, text",
    [
        ({"channel": 16}, "channel must be 0-15"),
        ({"note": 128}, "note must be 0-127"),
        ({"velocity": 0}, "velocity must be 1-127"),
    ],
)
def test_note_on_rejects_out_of_range_values(kwargs: dict[str, int], text: str) -> None:
    args = {"time_s": 0.0, "channel": 0, "note": 60, "velocity": 64} | kwargs
    with pytest.raises(ValueError, match=text):
        NoteOn(**args)


def test_sort_events_is_stable_for_simultaneous_events() -> None:
    a = NoteOff(1.0, 0, 60)
    b = NoteOn(1.0, 0, 60, 90)
    c = NoteOn(0.5, 0, 62, 90)
    assert sort_events([a, b, c]) == [c, a, b]


def test_beat_seconds_per_beat_from_tempo_us() -> None:
    assert Beat(0.0, 0, 1, 4, 2, 454_545).seconds_per_beat == pytest.approx(0.454545)
