"""Routing live keyboard messages (pure): decode, split, channel 10, upper drums."""

from __future__ import annotations

import pytest

from virja.errors import ConfigError
from virja.events import ControlChange, NoteOff, NoteOn, ProgramChange
from virja.jam.keyboard import (
    DRUM_CHANNEL,
    UPPER_DRUM_NOTES,
    KeyboardLayout,
    decode,
    encode,
    pitch_name,
    route,
    routing_table,
    upper_drum_note,
)

T = 1_700_000_000.25  # a Unix time: live events carry session (Unix) seconds


def test_decode_note_on_carries_the_time_given() -> None:
    assert decode(b"\x90\x3c\x64", time_s=T) == NoteOn(time_s=T, channel=0, note=60, velocity=100)


def test_decode_velocity_zero_note_on_is_a_note_off() -> None:
    assert decode(b"\x93\x3c\x00", time_s=T) == NoteOff(time_s=T, channel=3, note=60, velocity=0)


def test_decode_note_off_controller_and_program() -> None:
    assert decode(b"\x81\x30\x40", time_s=T) == NoteOff(T, 1, 48, 64)
    assert decode(b"\xb9\x04\x7f", time_s=T) == ControlChange(T, 9, 4, 127)
    assert decode(b"\xc0\x20", time_s=T) == ProgramChange(T, 0, 32)


@pytest.mark.parametrize(
    "data",
    [b"", b"\x90\x3c", b"\x90\x80\x10", b"\xe0\x00\x40", b"\xf8", b"\xf0\x01\xf7", b"\x3c\x40"],
    ids=["empty", "short", "bad-data", "pitch-bend", "clock", "sysex", "no-status"],
)
def test_decode_anything_else_is_none_not_an_error(data: bytes) -> None:
    assert decode(data, time_s=T) is None


@pytest.mark.parametrize("data", [b"\x90\x3c\x64", b"\x8f\x01\x02", b"\xb2\x07\x40", b"\xc5\x21"])
def test_encode_inverts_decode(data: bytes) -> None:
    event = decode(data, time_s=T)
    assert event is not None
    assert encode(event) == data


def test_channel_10_goes_to_the_drums_as_is() -> None:
    ev = NoteOn(T, DRUM_CHANNEL, 80, 90)  # even a key above the split
    r = route(ev, KeyboardLayout())
    assert (r.performer, r.event) == ("drums", ev)


def test_keys_below_the_split_go_to_the_bass() -> None:
    r = route(NoteOn(T, 0, 47, 90), KeyboardLayout(split=48))
    assert (r.performer, r.event.note) == ("bass", 47)


def test_the_split_key_and_above_are_the_pianists() -> None:
    assert route(NoteOn(T, 0, 48, 90), KeyboardLayout(split=48)).performer is None
    assert route(NoteOn(T, 0, 100, 90), KeyboardLayout(split=48)).performer is None


def test_the_split_is_configurable() -> None:
    assert route(NoteOn(T, 0, 55, 90), KeyboardLayout(split=60)).performer == "bass"


def test_upper_drums_maps_white_keys_to_gm_drum_notes_on_channel_10() -> None:
    layout = KeyboardLayout(split=48, upper="drums")
    want = {48: 36, 50: 38, 52: 42, 53: 43, 55: 47, 57: 50, 59: 51, 62: 38}
    for key, drum in want.items():
        r = route(NoteOn(T, 0, key, 100), layout)
        assert (r.performer, r.event.channel, r.event.note) == ("drums", DRUM_CHANNEL, drum)
        assert r.event.time_s == T and r.event.velocity == 100


def test_upper_drums_note_off_maps_like_its_note_on() -> None:
    r = route(NoteOff(T, 2, 61, 0), KeyboardLayout(upper="drums"))  # C#4 -> pedal hi-hat
    assert isinstance(r.event, NoteOff) and (r.performer, r.event.note) == ("drums", 44)


def test_upper_drums_leaves_unmapped_keys_to_nobody() -> None:
    r = route(NoteOn(T, 0, 51, 100), KeyboardLayout(upper="drums"))  # D#3
    assert upper_drum_note(51) is None and r.performer is None


def test_upper_drums_keeps_the_bass_below_the_split() -> None:
    assert route(NoteOn(T, 0, 40, 100), KeyboardLayout(upper="drums")).performer == "bass"


def test_controllers_go_to_drums_on_channel_10_and_nobody_elsewhere() -> None:
    assert route(ControlChange(T, 9, 4, 10), KeyboardLayout()).performer == "drums"
    assert route(ControlChange(T, 0, 64, 127), KeyboardLayout()).performer is None


def test_upper_drum_table_covers_the_papers_kit() -> None:
    """Bass drum, snare, three toms, hi-hat (closed, open, pedal), ride and both crashes."""
    assert {36, 38, 50, 47, 43, 42, 46, 44, 51, 49, 57} == set(UPPER_DRUM_NOTES.values())


def test_g_sharp_plays_crash_2_on_its_own_piece() -> None:
    """G# (MIDI 56 = G#3) sends GM 57, which the kit map puts on crash 2."""
    from virja.plan.config import default_config

    r = route(NoteOn(T, 0, 56, 100), KeyboardLayout(upper="drums"))
    assert (r.performer, r.event.note) == ("drums", 57)
    drum = default_config().kit.lookup(57)
    assert drum is not None and drum.piece == "crash2"


def test_bad_layouts_are_config_errors() -> None:
    with pytest.raises(ConfigError, match="split"):
        KeyboardLayout(split=200)
    with pytest.raises(ConfigError, match="upper"):
        KeyboardLayout(upper="piano")  # type: ignore[arg-type]


def test_pitch_names_put_middle_c_at_c4() -> None:
    assert (pitch_name(60), pitch_name(48), pitch_name(61)) == ("C4", "C3", "C#4")


def test_routing_table_names_the_split_and_the_drum_keys() -> None:
    rows = dict(routing_table(KeyboardLayout(split=48, upper="drums")))
    assert rows["keys below C3 (48)"] == "bass"
    assert rows["keys from C3 (48) up, every D"] == "drums: 38 Acoustic Snare"
    assert rows["keys from C3 (48) up, every D#"] == "nothing"
    assert rows["keys from C3 (48) up, every G#"] == "drums: 57 Crash Cymbal 2"
