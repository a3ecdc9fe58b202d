"""One live message from the port to the band, the thru synth and an RMCP stream."""

from __future__ import annotations

import socket

import pytest

from virja.events import NoteOff, NoteOn, ProgramChange
from virja.jam.keyboard import KeyboardLayout, Routed
from virja.jam.live import RMCP_BASS_PROGRAM, KeyboardJam, RmcpStream, thru_bytes
from virja.rmcp import wire

T = 1_700_000_000.0


class FakeThru:
    def __init__(self) -> None:
        self.now: list[bytes] = []
        self.later: list[tuple[bytes, float]] = []

    def send(self, data: bytes) -> None:
        self.now.append(data)

    def send_at(self, data: bytes, due_s: float) -> None:
        self.later.append((data, due_s))


class FakeStream:
    def __init__(self) -> None:
        self.routed: list[Routed] = []

    def send_routed(self, routed: Routed) -> None:
        self.routed.append(routed)


def test_without_delay_the_event_time_is_the_arrival() -> None:
    jam = KeyboardJam(KeyboardLayout())
    jam.handle(b"\x90\x28\x64", T)
    (a,) = jam.drain()
    assert a.arrival_s == T and a.routed.event == NoteOn(T, 0, 40, 100)


def test_with_delay_the_event_time_is_arrival_plus_delay() -> None:
    jam = KeyboardJam(KeyboardLayout(), delay_s=0.12)
    jam.handle(b"\x99\x26\x64", T)
    (a,) = jam.drain()
    assert a.arrival_s == T and a.routed.event.time_s == T + 0.12


def test_pianists_notes_are_not_queued_for_the_band() -> None:
    jam = KeyboardJam(KeyboardLayout())
    jam.handle(b"\x90\x48\x64", T)
    jam.handle(b"\xe0\x00\x40", T)  # pitch bend
    assert jam.drain() == []


def test_drain_keeps_arrival_order_and_empties_the_queue() -> None:
    jam = KeyboardJam(KeyboardLayout())
    for i, note in enumerate((30, 31, 32)):
        jam.handle(bytes([0x90, note, 100]), T + i)
    assert [a.routed.event.note for a in jam.drain()] == [30, 31, 32]
    assert jam.drain() == []


def test_thru_without_delay_sends_everything_at_once() -> None:
    thru = FakeThru()
    jam = KeyboardJam(KeyboardLayout(upper="drums"), thru=thru)
    jam.handle(b"\x90\x28\x64", T)  # bass
    jam.handle(b"\x90\x3e\x64", T)  # D4 -> snare
    jam.handle(b"\x90\x3f\x64", T)  # D#4 -> unmapped: the pianist's, forwarded as is
    jam.handle(b"\xf8", T)  # clock: not forwarded
    assert thru.now == [b"\x90\x28\x64", b"\x99\x26\x64", b"\x90\x3f\x64"]
    assert thru.later == []


def test_thru_with_delay_is_due_at_arrival_plus_delay() -> None:
    thru = FakeThru()
    jam = KeyboardJam(KeyboardLayout(), delay_s=0.2, thru=thru)
    jam.handle(b"\x90\x50\x64", T)
    assert thru.now == [] and thru.later == [(b"\x90\x50\x64", T + 0.2)]


def test_thru_bytes_forwards_channel_messages_only() -> None:
    assert thru_bytes(b"\xb0\x40\x7f", None) == b"\xb0\x40\x7f"
    assert thru_bytes(b"\xfe", None) is None


def test_only_band_events_are_streamed() -> None:
    stream = FakeStream()
    jam = KeyboardJam(KeyboardLayout(), stream=stream)
    jam.handle(b"\x90\x28\x64", T)
    jam.handle(b"\x90\x48\x64", T)
    assert [r.event.note for r in stream.routed] == [40]


def test_negative_delay_is_refused() -> None:
    with pytest.raises(ValueError, match="delay_s"):
        KeyboardJam(KeyboardLayout(), delay_s=-0.1)


def test_rmcp_stream_puts_a_bass_program_before_every_bass_note() -> None:
    """Each bass note-on carries its channel's program in the same datagram, so a
    receiver that joined late or lost a datagram still routes it to the bassist."""
    stream = RmcpStream("127.0.0.1", 9, sender=7, seq_start=1000)
    try:
        first = stream.datagrams(Routed("bass", NoteOn(T, 0, 40, 100)))
        second = stream.datagrams(Routed("bass", NoteOff(T + 0.5, 0, 40, 0)))
        again = stream.datagrams(Routed("bass", NoteOn(T + 0.75, 0, 43, 90)))
        drums = stream.datagrams(Routed("drums", NoteOn(T + 1, 9, 38, 90)))
    finally:
        stream.close()
    parsed = [wire.Datagram.parse(d) for d in first + second + again + drums]
    assert [p.seq for p in parsed] == [1000, 1001, 1002, 1003]
    assert all(p.sender == 7 for p in parsed)
    assert parsed[0].time_us == wire.s_to_us(T)
    events = [wire.to_events(p) for p in parsed]
    assert events[0] == [ProgramChange(T, 0, RMCP_BASS_PROGRAM, 7), NoteOn(T, 0, 40, 100, 7)]
    assert events[1] == [NoteOff(T + 0.5, 0, 40, 0, 7)]
    assert events[2] == [
        ProgramChange(T + 0.75, 0, RMCP_BASS_PROGRAM, 7),
        NoteOn(T + 0.75, 0, 43, 90, 7),
    ]
    assert events[3] == [NoteOn(T + 1, 9, 38, 90, 7)]


def test_rmcp_stream_sends_datagrams_over_loopback_udp() -> None:
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.settimeout(5.0)
    stream = RmcpStream("127.0.0.1", rx.getsockname()[1])
    try:
        stream.send_routed(Routed("drums", NoteOn(T, 9, 36, 100)))
        data = rx.recv(2048)
    finally:
        stream.close()
        rx.close()
    assert wire.to_events(wire.Datagram.parse(data)) == [NoteOn(T, 9, 36, 100, 1)]


def test_rmcp_stream_numbers_each_datagram_once_when_two_threads_send() -> None:
    """jam --rtp-midi: the keyboard's MIDI thread and the RTP-MIDI listener's thread
    both send; every datagram gets its own sequence number, sent in numbering order."""
    import sys
    import threading

    class Wire:
        def __init__(self) -> None:
            self.sent: list[bytes] = []

        def sendto(self, data: bytes, target: object) -> None:
            self.sent.append(data)  # a list's append is atomic

        def close(self) -> None:
            pass

    stream = RmcpStream("127.0.0.1", 9, seq_start=0)
    stream._sock.close()
    fake = Wire()
    stream._sock = fake  # type: ignore[assignment]
    n = 1500

    def play(channel: int, performer: str) -> None:
        for i in range(n):
            stream.send_routed(Routed(performer, NoteOn(T + i, channel, 40, 90)))  # type: ignore[arg-type]

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # switch threads as often as possible: races show
    try:
        threads = [
            threading.Thread(target=play, args=(0, "bass")),
            threading.Thread(target=play, args=(9, "drums")),
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=30)
    finally:
        sys.setswitchinterval(interval)
    seqs = [wire.Datagram.parse(d).seq for d in fake.sent]
    assert len(seqs) == 2 * n and stream.sent == 2 * n
    assert seqs == list(range(2 * n))  # unique, and on the wire in numbering order
