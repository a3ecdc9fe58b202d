"""The one MIDI bytes <-> event table, checked against mido's own parser."""

from __future__ import annotations

import mido
import pytest
from hypothesis import given
from hypothesis import strategies as st

from virja import midispec
from virja.events import Beat, ControlChange, NoteOff, NoteOn, ProgramChange
from virja.jam import keyboard
from virja.rmcp import wire
from virja.rmcp.bodies import MidiBody


def test_table_matches_mido_specs() -> None:
    for spec in midispec.SPECS:
        mido_spec = mido.messages.specs.SPEC_BY_STATUS[spec.status]
        assert mido_spec["type"] == spec.name
        assert mido_spec["length"] == 1 + spec.data_len
        if spec.event is not None:  # the event's fields are mido's, in wire order
            assert tuple(mido_spec["value_names"][1:]) == spec.fields


@pytest.mark.parametrize(
    "event",
    [
        NoteOn(1.5, 3, 60, 100, sender=7),
        NoteOff(1.5, 9, 36, 64, sender=7),
        ControlChange(1.5, 0, 64, 127, sender=7),
        ProgramChange(1.5, 15, 33, sender=7),
    ],
)
def test_round_trip_bytes_and_mido(event: NoteOn | NoteOff | ControlChange | ProgramChange) -> None:
    data = midispec.encode(event)
    assert data is not None
    assert midispec.decode(data, time_s=1.5, sender=7) == event
    msg = midispec.to_mido(event)
    assert msg is not None and msg.bytes() == list(data)
    assert midispec.from_mido(msg, time_s=1.5, sender=7) == event


def test_velocity_zero_note_on_is_a_note_off_everywhere() -> None:
    data = bytes((0x92, 40, 0))
    off = NoteOff(2.0, 2, 40, 0)
    assert midispec.decode(data, time_s=2.0) == off
    assert midispec.from_mido(mido.Message.from_bytes(data), time_s=2.0) == off
    assert keyboard.decode(data, time_s=2.0) == off
    body = MidiBody.parse(data)
    assert wire.midi_events(body, 2.0, 0) == [off]


def test_not_events() -> None:
    assert midispec.encode(Beat(0.0, 0, 1, 4, 0, 500_000)) is None
    assert midispec.to_mido(Beat(0.0, 0, 1, 4, 0, 500_000)) is None
    for data in ([0xE0, 0, 64], [0xA0, 60, 1], [0xD0, 5], [0xF8], [], [0x90, 60], [0x90, 60, 200]):
        assert midispec.decode(data, time_s=0.0) is None
    assert midispec.from_mido(mido.Message("pitchwheel", pitch=100), time_s=0.0) is None


@given(st.integers(0x80, 0xEF), st.integers(0, 127), st.integers(0, 127))
def test_decode_agrees_with_mido(status: int, a: int, b: int) -> None:
    data = [status, a, b][: 1 + midispec.data_len(status)]
    msg = mido.Message.from_bytes(data)
    assert midispec.decode(data, time_s=0.0) == midispec.from_mido(msg, time_s=0.0)
    ev = midispec.decode(data, time_s=0.0)
    if ev is not None and not (status & 0xF0 == 0x90 and b == 0):
        assert midispec.encode(ev) == bytes(data)
