"""Fuzzing the RTP-MIDI codec and session host with mutated golden packets.

The parsers raise nothing but RtpMidiError; the host never raises at all,
counts every datagram it does not use, keeps its state within its caps and
answers no more than one datagram per datagram received (plus feedback).
Seeds: the node-rtpmidi session (tests/data/rtpmidi) and packets built here
with delta times, SysEx segments, a journal and RTP header options.
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.mutate import apply_byte_edits, byte_edits, time_limit
from tests.rtpmidi.conftest import node_payloads
from virja.rtpmidi.control import Command, SessionPacket, parse_control
from virja.rtpmidi.errors import RtpMidiError
from virja.rtpmidi.host import Channel, HostConfig, SessionHost
from virja.rtpmidi.payload import MidiPacket, midi_packet

SSRC = 0xEC22A18C  # the node session's
BUILT = [
    midi_packet(SSRC, 1, 5, (3, [0x99, 36, 100]), (200, [0x99, 38, 1]), (0, [0xF8])),
    midi_packet(SSRC, 2, 5, (0, [0xF0, 1, 2, 0xF0]), (1, [0xF7, 3, 0xF7]), (0, [0x90, 40, 5])),
    midi_packet(SSRC, 3, 5, (0, [0x90, 40, 5])) + b"\x00\x00\x01",  # trailing bytes
    bytes([0xB1]) + midi_packet(SSRC, 4, 5, (0, [0x99, 36, 1]))[1:12] + b"\x00\x00\x00\x09"
    + b"\xbe\xde\x00\x01\x00\x00\x00\x00" + bytes([0x43, 0x99, 36, 100]) + b"\x80\x00\x01\x02",
]  # fmt: skip
SEEDS = node_payloads() + BUILT
PEER_C, PEER_D = ("127.0.0.1", 42428), ("127.0.0.1", 42429)


def parse_any(data: bytes) -> None:
    try:
        if data[:2] == b"\xff\xff":
            parse_control(data)
        else:
            MidiPacket.parse(data)
    except RtpMidiError:
        pass


@settings(max_examples=200, deadline=2000)
@given(seed=st.sampled_from(range(len(SEEDS))), edits=byte_edits())
def test_mutated_packets_parse_or_raise_a_typed_error(
    seed: int, edits: list[tuple[int, int, int]]
) -> None:
    with time_limit(2.0):
        parse_any(apply_byte_edits(SEEDS[seed], edits))


@settings(max_examples=60, deadline=4000)
@given(
    batch=st.lists(
        st.tuples(
            st.sampled_from(range(len(SEEDS))), byte_edits(), st.booleans(), st.integers(0, 3)
        ),
        min_size=1,
        max_size=40,
    )
)
def test_a_mutated_stream_into_an_open_session_is_counted_never_raised(
    batch: list[tuple[int, list[tuple[int, int, int]], bool, int]],
) -> None:
    host = SessionHost(HostConfig(max_sessions=4, max_queue=64))
    now = 1_800_000_000_000_000
    inv = bytes(SessionPacket(Command.IN, 0x10F4F0B4, SSRC, "node-peer"))
    host.receive_datagram(inv, PEER_C, channel=Channel.CONTROL, now_us=now)
    host.receive_datagram(inv, PEER_D, channel=Channel.DATA, now_us=now)
    assert len(host.datagrams_to_send(now_us=now)) == 2 and host.open_sessions == 1
    sent = 2
    with time_limit(4.0):
        for seed, edits, on_data, step_s in batch:
            data = apply_byte_edits(SEEDS[seed], edits)
            now += step_s * 1_000_000
            peer = PEER_D if on_data else PEER_C
            ch = Channel.DATA if on_data else Channel.CONTROL
            host.receive_datagram(data, peer, channel=ch, now_us=now)
            sent += 1
            assert len(host.sessions) <= 4
            assert len(host.drain_messages()) <= 64
            assert len(host.datagrams_to_send(now_us=now)) <= 1 + len(host.sessions)
    st_ = host.stats
    assert st_.datagrams == sent
    used = sum(st_.by_kind.values())
    assert used + sum(st_.dropped.values()) >= sent - st_.by_kind.get("MIDI", 0)
