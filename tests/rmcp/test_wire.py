"""The RMCP/1 codec against golden datagrams (tests/data/rmcp, make_golden.py)."""

from __future__ import annotations

import pytest

from tests.rmcp.conftest import DATA, golden
from virja.events import Beat, Chord, ControlChange, NoteOff, NoteOn, ProgramChange
from virja.rmcp import errors, wire
from virja.rmcp.bodies import (
    BeatBody,
    ChordBody,
    ClockReplyBody,
    ClockRequestBody,
    MidiBody,
    UnknownBody,
)
from virja.rmcp.signing import load_key, sign, tag_matches, verify
from virja.rmcp.wire import Datagram, Flags, Kind

T = 1_700_000_000_123_456
VALID = sorted(p.name for p in DATA.glob("*.bin") if not p.name.startswith("bad_"))
INVALID = sorted(p.name for p in DATA.glob("bad_*.bin"))


def test_header_struct_is_24_bytes() -> None:
    assert wire.HEADER.size == 24


@pytest.mark.parametrize("name", VALID)
def test_valid_golden_round_trips(name: str) -> None:
    data = golden(name)
    assert bytes(Datagram.parse(data)) == data


def test_midi_golden_fields() -> None:
    d = Datagram.parse(golden("midi.bin"))
    assert (d.kind, d.sender, d.seq, d.time_us, d.flags) == (Kind.MIDI, 1, 7, T, Flags.NONE)
    assert isinstance(d.body, MidiBody)
    assert d.body.messages == (
        bytes([0x90, 60, 100]),
        bytes([0x99, 38, 90]),
        bytes([0x80, 60, 0]),
        bytes([0xB0, 64, 127]),
        bytes([0xC0, 33]),
        bytes([0xF0, 0x7E, 0x01, 0xF7]),
    )


def test_midi_events_convert_time_and_kinds() -> None:
    d = Datagram.parse(golden("midi.bin"))
    t = T / 1_000_000
    assert wire.to_events(d) == [
        NoteOn(t, 0, 60, 100, 1),
        NoteOn(t, 9, 38, 90, 1),
        NoteOff(t, 0, 60, 0, 1),
        ControlChange(t, 0, 64, 127, 1),
        ProgramChange(t, 0, 33, 1),
    ]


def test_velocity_zero_note_on_is_note_off() -> None:
    d = wire.midi(1, 0, T, bytes([0x93, 40, 0]))
    assert wire.to_events(d) == [NoteOff(T / 1e6, 3, 40, 0, 1)]


def test_beat_golden_fields_and_event() -> None:
    d = Datagram.parse(golden("beat.bin"))
    assert d.body == BeatBody(bar=12, beat=1, beats_per_bar=4, level=2, tempo_us=500_000)
    assert (d.sender, d.seq) == (3, 0)
    assert wire.to_events(d) == [Beat(T / 1e6, 12, 1, 4, 2, 500_000, 3)]


def test_chord_golden_bass_255_is_none() -> None:
    d = Datagram.parse(golden("chord.bin"))
    assert d.body == ChordBody(root=2, bass=None, quality="m7")
    assert wire.to_events(d) == [Chord(T / 1e6, 2, None, "m7", 3)]


def test_chord_with_bass() -> None:
    d = Datagram.parse(golden("chord_slash.bin"))
    assert d.body == ChordBody(root=0, bass=4, quality="maj7")


def test_clock_request_golden_fields() -> None:
    d = Datagram.parse(golden("clock_request.bin"))
    assert d.body == ClockRequestBody(nonce=0xDEADBEEF, t0_us=T)
    assert d.immediate and d.seq == 0xFFFFFFFF
    assert wire.to_events(d) == []


def test_clock_reply_golden_fields() -> None:
    d = Datagram.parse(golden("clock_reply.bin"))
    assert d.body == ClockReplyBody(0xDEADBEEF, T, T + 1500, T + 1600)


def test_unknown_kind_parses_as_unknown_body() -> None:
    d = Datagram.parse(golden("unknown_kind.bin"))
    assert d.body == UnknownBody(200, b"future")
    assert d.kind == 200 and wire.kind_name(d.kind) == "kind_200"


def test_signed_golden_verifies_with_key_file() -> None:
    key = load_key(DATA / "key.txt")
    assert key == b"virja-test-key"
    d = Datagram.parse(golden("midi_signed.bin"))
    assert d.signed and len(d.tag) == 16
    assert verify(d, key)
    assert not verify(d, b"other key")


def test_tag_matches_the_bytes_as_received() -> None:
    """The receiver's check: the tag over the datagram's bytes as they arrived."""
    data = golden("midi_signed.bin")
    key = b"virja-test-key"
    assert tag_matches(key, data[:-16], data[-16:])
    assert not tag_matches(key, data[:-17] + bytes([data[-17] ^ 1]), data[-16:])
    assert not tag_matches(b"other key", data[:-16], data[-16:])


def test_sign_builds_the_golden_bytes() -> None:
    d = wire.midi(2, 9, T, bytes([0x99, 42, 80]))
    assert bytes(sign(d, b"virja-test-key")) == golden("midi_signed.bin")


@pytest.mark.parametrize(
    ("name", "reason", "text"),
    [
        ("bad_too_short.bin", "too_short", "datagram too short: 23 of 24 header bytes"),
        ("bad_too_long.bin", "too_long", "datagram too long: 1201 bytes, at most 1200"),
        ("bad_magic.bin", "bad_magic", "bad magic b'RMCQ', expected b'RMCP'"),
        ("bad_version.bin", "bad_version", "unsupported version 2, expected 1"),
        ("bad_flags.bin", "bad_flags", "reserved flag bits set: 0x04"),
        ("bad_reserved.bin", "bad_reserved", "reserved byte is 1, must be 0"),
        ("bad_length_long.bin", "bad_length", "1 bytes after the end of the message (body_len 3)"),
        ("bad_length_unsigned_tag.bin", "bad_length", "tag truncated: 0 of 16 bytes"),
        ("bad_body_midi_empty.bin", "bad_body", "MIDI body is empty"),
        (
            "bad_body_midi_missing_data.bin",
            "bad_body",
            "MIDI message 0x90 at offset 0 truncated: 1 of 2 data bytes",
        ),
        (
            "bad_body_midi_data_above_127.bin",
            "bad_body",
            "MIDI message 0x90 at offset 0: data byte 0xC8 at offset 2 above 127",
        ),
        (
            "bad_body_midi_running_status.bin",
            "bad_body",
            "data byte 0x3E at offset 3 without a status byte (running status is not allowed)",
        ),
        (
            "bad_body_midi_unterminated_sysex.bin",
            "bad_body",
            "system exclusive at offset 0 has no F7",
        ),
        ("bad_body_midi_status_f1.bin", "bad_body", "status byte 0xF1 at offset 0 is not allowed"),
        ("bad_body_midi_status_f8.bin", "bad_body", "status byte 0xF8 at offset 0 is not allowed"),
        ("bad_body_beat_11.bin", "bad_body", "BEAT body must be 12 bytes, got 11"),
        ("bad_body_chord_n.bin", "bad_body", "CHORD body must be 3 + n = 6 bytes, got 5"),
        (
            "bad_body_clock_request_13.bin",
            "bad_body",
            "CLOCK_REQUEST body must be 12 bytes, got 13",
        ),
        ("bad_body_clock_reply_27.bin", "bad_body", "CLOCK_REPLY body must be 28 bytes, got 27"),
    ],
)
def test_invalid_golden_raises_typed_error(name: str, reason: str, text: str) -> None:
    with pytest.raises(errors.RmcpError) as info:
        Datagram.parse(golden(name))
    assert info.value.reason == reason
    assert str(info.value) == text
    assert isinstance(info.value, ValueError)


def test_every_invalid_golden_is_covered() -> None:
    covered = {p[0] for p in test_invalid_golden_raises_typed_error.pytestmark[0].args[1]}  # type: ignore[attr-defined]
    assert covered == set(INVALID)


def test_sysex_interrupted_by_status_names_it() -> None:
    with pytest.raises(errors.BadBodyError, match=r"has no F7 \(status 0x90 at offset 2\)"):
        MidiBody.parse(bytes([0xF0, 0x01, 0x90, 60, 100]))


def test_lone_f7_is_not_allowed() -> None:
    with pytest.raises(errors.BadBodyError, match="status byte 0xF7"):
        MidiBody.parse(bytes([0xF7]))


@pytest.mark.parametrize("status", [0xA0, 0xD0, 0xE5])
def test_other_channel_voice_messages_are_valid_but_carry_no_event(status: int) -> None:
    msg = bytes([status, 1]) if status & 0xF0 == 0xD0 else bytes([status, 1, 2])
    d = wire.midi(1, 0, T, msg)
    assert wire.to_events(d) == []


@pytest.mark.parametrize("name", VALID)
def test_every_truncation_is_rejected_with_its_length(name: str) -> None:
    data = golden(name)
    d = Datagram.parse(data)
    body_len = len(bytes(d.body))
    for n in range(len(data)):
        with pytest.raises(errors.RmcpError) as info:
            Datagram.parse(data[:n])
        err = info.value
        if n < 24:
            assert err.reason == "too_short"
            assert str(err) == f"datagram too short: {n} of 24 header bytes"
        elif n < 24 + body_len:
            assert err.reason == "bad_length"
            assert str(err) == f"body truncated: {n - 24} of {body_len} bytes"
        else:
            assert err.reason == "bad_length"
            assert str(err) == f"tag truncated: {n - 24 - body_len} of 16 bytes"


def test_checks_follow_the_spec_order_magic_before_version() -> None:
    data = bytearray(golden("midi.bin"))
    data[0:4] = b"XXXX"
    data[4] = 9
    with pytest.raises(errors.BadMagicError):
        Datagram.parse(bytes(data))


def test_builder_refuses_out_of_range_fields() -> None:
    with pytest.raises(ValueError, match="sender"):
        wire.midi(70000, 0, T, bytes([0x90, 1, 1]))
    with pytest.raises(ValueError, match="seq"):
        wire.midi(1, -1, T, bytes([0x90, 1, 1]))


def test_builder_refuses_invalid_midi() -> None:
    with pytest.raises(errors.BadBodyError):
        wire.midi(1, 0, T, bytes([0x90, 1]))


def test_builders_round_trip() -> None:
    for d in (
        wire.beat(1, 2, T, bar=0, beat=3, beats_per_bar=4, level=1, tempo_us=600_000),
        wire.chord(1, 3, T, root=11, bass=None, quality=""),
        wire.clock_request(1, 4, nonce=5, t0_us=T),
        wire.clock_reply(1, 5, ClockRequestBody(5, T), t1_us=T + 1, t2_us=T + 2),
        Datagram(1, 6, -5, UnknownBody(99, b"")),
    ):
        assert Datagram.parse(bytes(d)) == d


def test_time_conversion_is_microseconds() -> None:
    assert wire.us_to_s(1_500_000) == 1.5
    assert wire.s_to_us(1.5) == 1_500_000


def test_negative_time_is_valid() -> None:
    d = Datagram.parse(bytes(wire.midi(1, 0, -1, bytes([0x90, 1, 1]))))
    assert d.time_us == -1


def test_beat_body_rules() -> None:
    import struct

    with pytest.raises(errors.BadBodyError, match="level"):
        BeatBody.parse(struct.pack("!IBBBBI", 0, 1, 4, 3, 0, 500_000))
    with pytest.raises(errors.BadBodyError, match="beat must be 1-4"):
        BeatBody.parse(struct.pack("!IBBBBI", 0, 0, 4, 0, 0, 500_000))
    with pytest.raises(errors.BadBodyError, match="tempo"):
        BeatBody.parse(struct.pack("!IBBBBI", 0, 1, 4, 0, 0, 0))


def test_chord_root_above_11_is_invalid() -> None:
    with pytest.raises(errors.BadBodyError, match="root"):
        ChordBody.parse(bytes([12, 255, 0]))


def test_load_key_errors_name_the_file(tmp_path: object) -> None:
    from pathlib import Path

    from virja.errors import InputFileError

    p = Path(str(tmp_path)) / "k"
    with pytest.raises(InputFileError, match="key file not found"):
        load_key(p)
    p.write_bytes(b"  \n")
    with pytest.raises(InputFileError, match=r"k: key file is empty"):
        load_key(p)


def test_beat_reserved_byte_is_ignored_on_receipt_and_kept_for_the_round_trip() -> None:
    """The spec requires 0 only of the header's reserved byte; a BEAT body's is ignored."""
    from virja.rmcp.bodies import BeatBody

    data = bytes.fromhex("00000003020400070007a120")
    body = BeatBody.parse(data)
    assert (body.bar, body.beat, body.beats_per_bar, body.level, body.tempo_us) == (
        3,
        2,
        4,
        0,
        500_000,
    )
    assert bytes(body) == data
