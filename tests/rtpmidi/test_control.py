"""AppleMIDI control packets: golden ones from node-rtpmidi, round trips, every truncation."""

from __future__ import annotations

import pytest

from tests.rtpmidi.conftest import node_payloads
from virja.rtpmidi import errors
from virja.rtpmidi.control import (
    Command,
    FeedbackPacket,
    LimitPacket,
    SessionPacket,
    SyncPacket,
    is_control,
    packet_kind,
    parse_control,
)

NODE_IN = bytes.fromhex("ffff494e0000000210f4f0b4ec22a18c6e6f64652d7065657200")
NODE_CK0 = bytes.fromhex("ffff434bec22a18c00000000000000000000762100000000000000000000000000000000")
NODE_BY = bytes.fromhex("ffff42590000000210f4f0b4ec22a18c7669726a610000")


def test_the_golden_packets_are_the_captured_ones() -> None:
    captured = node_payloads()
    assert captured[0] == NODE_IN and captured[2] == NODE_CK0 and captured[-1] == NODE_BY


def test_node_invitation_fields_and_round_trip() -> None:
    pkt = parse_control(NODE_IN)
    assert pkt == SessionPacket(Command.IN, 0x10F4F0B4, 0xEC22A18C, "node-peer")
    assert bytes(pkt) == NODE_IN


def test_node_sync_fields_and_round_trip() -> None:
    pkt = parse_control(NODE_CK0)
    assert pkt == SyncPacket(0xEC22A18C, 0, (0x7621, 0, 0))
    assert bytes(pkt) == NODE_CK0
    assert packet_kind(pkt) == "CK0"


def test_node_bye_has_a_name_without_its_own_nul() -> None:
    pkt = parse_control(NODE_BY)
    assert isinstance(pkt, SessionPacket) and pkt.command is Command.BY
    assert pkt.name == "virja"
    # a BY cut right after the name (no NUL at all) still parses
    unterminated = parse_control(NODE_BY[:-2])
    assert isinstance(unterminated, SessionPacket) and unterminated.name == "virja"


def test_feedback_and_limit_round_trip() -> None:
    rs = FeedbackPacket(0x01020304, 0xBEEF)
    data = bytes(rs)
    assert data == bytes.fromhex("ffff525301020304beef0000")
    assert parse_control(data) == rs
    rl = LimitPacket(7, 1_000_000)
    assert parse_control(bytes(rl)) == rl


@pytest.mark.parametrize("packet", [NODE_IN, NODE_CK0, bytes(FeedbackPacket(1, 2))])
def test_every_truncation_is_a_typed_error(packet: bytes) -> None:
    fixed = {0x494E: 16, 0x434B: 36, 0x5253: 10}[int.from_bytes(packet[2:4], "big")]
    for n in range(fixed):
        with pytest.raises(errors.TruncatedError, match=r"truncated: \d+ of \d+ bytes"):
            parse_control(packet[:n])


def test_bad_signature_version_command_and_count() -> None:
    with pytest.raises(errors.BadSignatureError, match="signature 0xFFFE"):
        parse_control(b"\xff\xfe" + NODE_IN[2:])
    with pytest.raises(errors.BadVersionError, match="version 3, expected 2"):
        parse_control(NODE_IN[:7] + b"\x03" + NODE_IN[8:])
    with pytest.raises(errors.UnknownCommandError, match="unknown control command 0x5858"):
        parse_control(b"\xff\xffXX" + bytes(20))
    with pytest.raises(errors.RtpMidiError, match="count 3"):
        parse_control(NODE_CK0[:8] + b"\x03" + NODE_CK0[9:])


def test_control_and_rtp_never_collide() -> None:
    assert is_control(NODE_IN)
    assert not is_control(bytes.fromhex("8061a6c30000789bec22a18c2400992464"))
    assert not is_control(b"\xff")


def test_long_names_are_cut_and_bad_utf8_replaced() -> None:
    pkt = parse_control(NODE_IN[:16] + b"\xff" * 1000 + b"\x00")
    assert isinstance(pkt, SessionPacket) and len(pkt.name) == 256
