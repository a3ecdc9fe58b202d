"""RTP-MIDI packets (RFC 6295): golden ones from node-rtpmidi, delta times, running
status, SysEx, the journal flag, RTP header options, every truncation."""

from __future__ import annotations

import pytest

from tests.rtpmidi.conftest import node_payloads
from virja.rtpmidi import errors
from virja.rtpmidi.payload import (
    MidiCommand,
    MidiPacket,
    RtpHeader,
    encode_command_section,
    midi_packet,
    parse_command_section,
)

NODE_ONE = bytes.fromhex("8061a6c30000789bec22a18c2400992464")
NODE_RUNNING = bytes.fromhex("8061a6c400007c87ec22a18c0a99265a002a4600902864")
NODE_BIG = bytes.fromhex("8061a6c50000807bec22a18c8010c02000f07d0102f700902b5000802800")


def test_the_golden_packets_are_the_captured_ones() -> None:
    assert [p for p in node_payloads() if p[0] == 0x80] == [NODE_ONE, NODE_RUNNING, NODE_BIG]


def test_node_single_note_with_a_zero_delta_before_it() -> None:
    pkt = MidiPacket.parse(NODE_ONE)
    assert pkt.header == RtpHeader(0xA6C3, 0x789B, 0xEC22A18C)
    assert pkt.commands == (MidiCommand(0, b"\x99\x24\x64"),)
    assert not pkt.journal


def test_node_running_status_gives_each_command_its_status() -> None:
    pkt = MidiPacket.parse(NODE_RUNNING)
    assert [c.data for c in pkt.commands] == [b"\x99\x26\x5a", b"\x99\x2a\x46", b"\x90\x28\x64"]
    assert bytes(pkt) == NODE_RUNNING  # our encoder writes running status as node does


def test_node_long_list_with_sysex_program_and_note_off() -> None:
    pkt = MidiPacket.parse(NODE_BIG)
    assert [c.data for c in pkt.commands] == [
        b"\xc0\x20",
        b"\xf0\x7d\x01\x02\xf7",
        b"\x90\x2b\x50",
        b"\x80\x28\x00",
    ]
    assert [c.is_sysex for c in pkt.commands] == [False, True, False, False]


def test_delta_times_accumulate_in_ticks() -> None:
    data = midi_packet(5, 1, 1000, (0, [0x99, 36, 100]), (10, [0x99, 38, 90]), (300, [0x90, 40, 1]))
    pkt = MidiPacket.parse(data)
    assert [t for t, _ in pkt.offsets()] == [0, 10, 310]
    assert bytes(pkt) == data
    assert data[12:] == bytes.fromhex("0b") + bytes.fromhex(
        "992464 0a 265a 822c 902801".replace(" ", "")
    )


def test_z_flag_gives_the_first_command_a_delta() -> None:
    commands, journal = parse_command_section(bytes([0x20 | 5, 0x81, 0x00, 0xF8, 0x05, 0xFE]))
    assert commands == (MidiCommand(128, b"\xf8"), MidiCommand(5, b"\xfe"))
    assert not journal
    # node-rtpmidi's first packet: Z set, a zero delta; ours leaves Z clear for it
    assert bytes(MidiPacket.parse(NODE_ONE))[12:] == bytes.fromhex("03992464")


def test_realtime_keeps_running_status_system_common_cancels_it() -> None:
    section = bytes([0x90, 60, 100, 0, 0xF8, 0, 61, 100])
    commands, _ = parse_command_section(bytes([len(section)]) + section)
    assert [c.data for c in commands] == [b"\x90\x3c\x64", b"\xf8", b"\x90\x3d\x64"]
    section = bytes([0x90, 60, 100, 0, 0xF6, 0, 61, 100])
    with pytest.raises(errors.BadCommandSectionError, match="no status byte"):
        parse_command_section(bytes([len(section)]) + section)


def test_sysex_segments_cancel_and_embedded_realtime_are_skipped_whole() -> None:
    section = bytes(
        [0xF0, 1, 2, 0xF8, 3, 0xF0, 0, 0xF7, 4, 0xF0, 0, 0xF7, 5, 0xF4, 0, 0x99, 36, 100]
    )
    commands, _ = parse_command_section(bytes([0x80 | 0, len(section)]) + section)
    assert [c.data for c in commands] == [
        bytes([0xF0, 1, 2, 0xF8, 3, 0xF0]),
        bytes([0xF7, 4, 0xF0]),
        bytes([0xF7, 5, 0xF4]),
        b"\x99\x24\x64",
    ]


def test_journal_flag_is_reported_and_the_journal_not_read() -> None:
    payload = bytes([0x40 | 3, 0x99, 36, 100]) + b"\xde\xad\xbe\xef\x00"
    commands, journal = parse_command_section(payload)
    assert journal and commands == (MidiCommand(0, b"\x99\x24\x64"),)


def test_rtp_csrc_extension_and_padding_are_skipped() -> None:
    body = bytes([3, 0x99, 36, 100])
    head = bytearray(bytes(RtpHeader(1, 2, 3)))
    head[0] = 0x80 | 0x20 | 0x10 | 1  # padding, extension, one CSRC
    data = (
        bytes(head)
        + b"\x00\x00\x00\x09"
        + b"\xbe\xde\x00\x01"
        + b"\x00" * 4
        + body
        + b"\x00\x00\x03"
    )
    pkt = MidiPacket.parse(data)
    assert pkt.header.ssrc == 3 and pkt.commands[0].data == b"\x99\x24\x64"


@pytest.mark.parametrize(
    ("section", "error", "match"),
    [
        (bytes([0x45, 100]), errors.BadCommandSectionError, "no status byte"),
        (bytes([0x99, 36, 0xF8]), errors.BadCommandSectionError, "status byte 0xF8 where data"),
        (
            bytes([0x99, 36, 100, 0x80, 0x80, 0x80, 0x80, 0x00]),
            errors.BadCommandSectionError,
            "longer than 4",
        ),
        (bytes([0x99, 36, 100, 0x00]), errors.TruncatedError, "ends with a delta time"),
        (bytes([0xF0, 1, 2]), errors.TruncatedError, "has no end"),
        (bytes([0xF0, 1, 0x90, 0xF7]), errors.BadCommandSectionError, "status 0x90 inside"),
        (bytes([0x99, 36]), errors.TruncatedError, "1 of 2 data bytes"),
    ],
)
def test_bad_command_sections_are_typed_errors(
    section: bytes, error: type[Exception], match: str
) -> None:
    payload = bytes([0x80 | (len(section) >> 8), len(section) & 0xFF]) + section
    with pytest.raises(error, match=match):
        parse_command_section(payload)


def test_bad_rtp_version_and_padding() -> None:
    with pytest.raises(errors.BadVersionError, match="RTP version 1"):
        MidiPacket.parse(b"\x40" + NODE_ONE[1:])
    with pytest.raises(errors.TruncatedError, match="padding"):
        MidiPacket.parse(bytes([NODE_ONE[0] | 0x20]) + NODE_ONE[1:-1] + b"\xff")


@pytest.mark.parametrize("packet", [NODE_ONE, NODE_RUNNING, NODE_BIG])
def test_every_truncation_is_a_typed_error(packet: bytes) -> None:
    for n in range(len(packet)):
        with pytest.raises(errors.RtpMidiError):
            MidiPacket.parse(packet[:n])


def test_encoder_round_trips_long_lists_and_refuses_bad_deltas() -> None:
    cmds = tuple(MidiCommand(i % 3, bytes([0x90, i % 128, 1 + i % 127])) for i in range(200))
    section = encode_command_section(cmds)
    assert parse_command_section(section) == (cmds, False)
    with pytest.raises(ValueError, match="delta time"):
        encode_command_section([MidiCommand(1 << 28, b"\xf8")])
