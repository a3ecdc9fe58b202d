"""A live keyboard: what happens to one message between the port and the band.

:class:`KeyboardJam` is the handler :class:`virja.jam.ports.MidiInput` calls on
the MIDI backend's thread with ``(data, arrival_s)``.  It

1. stamps the event with ``arrival_s + delay_s`` (the latency model: with no
   delay the stroke is drawn at once and the planner compresses its
   anticipation; with ``--delay-ms`` sound and picture are both put off so every
   motion keeps its full anticipation);
2. routes it (:func:`virja.jam.keyboard.route`);
3. queues routed notes for the main loop (:meth:`KeyboardJam.drain`), which
   feeds the performance on its own thread;
4. forwards the message to the thru synth (at once, or due at
   ``arrival_s + delay_s``) and to an RMCP stream, if given.

:class:`RmcpStream` turns routed events into RMCP/1 MIDI datagrams
(:mod:`virja.rmcp.wire` builders) and sends them over UDP.
"""

from __future__ import annotations

import logging
import queue
import socket
import threading
from dataclasses import dataclass
from typing import Protocol

from virja.events import NoteOn, ProgramChange
from virja.jam.keyboard import KeyboardLayout, Routed, decode, encode, route
from virja.rmcp import wire
from virja.vocab import Performer

log = logging.getLogger(__name__)


class ThruSink(Protocol):
    def send(self, data: bytes) -> None: ...

    def send_at(self, data: bytes, due_s: float) -> None: ...


class RoutedSink(Protocol):
    def send_routed(self, routed: Routed) -> None: ...


@dataclass(frozen=True, slots=True)
class Arrival:
    """One routed event and the moment its key arrived (session seconds)."""

    arrival_s: float
    routed: Routed


def thru_bytes(data: bytes, routed: Routed | None) -> bytes | None:
    """What the thru synth gets for a message: the routed form of a band event
    (upper keys mapped to drums sound as drums), channel messages as they came
    (the pianist's notes, pitch bend, pedals), nothing for system messages."""
    if routed is not None:
        return encode(routed.event)
    if data and 0x80 <= data[0] <= 0xEF:
        return bytes(data)
    return None


class KeyboardJam:
    """Routes live messages; thread-safe hand-over to the main loop through a queue."""

    def __init__(
        self,
        layout: KeyboardLayout,
        *,
        delay_s: float = 0.0,
        thru: ThruSink | None = None,
        stream: RoutedSink | None = None,
        max_queue: int = 4096,
    ) -> None:
        if delay_s < 0:
            raise ValueError(f"delay_s must be >= 0, got {delay_s}")
        self.layout = layout
        self.delay_s = delay_s
        self.thru = thru
        self.stream = stream
        self._queue: queue.Queue[Arrival] = queue.Queue(maxsize=max_queue)
        self._dropped_lock = threading.Lock()  # handle() runs on the MIDI and RTP-MIDI threads
        self.dropped = 0

    def handle(self, data: bytes, arrival_s: float) -> None:
        """One raw message that arrived at ``arrival_s``: route, queue, forward."""
        time_s = arrival_s + self.delay_s
        event = decode(data, time_s=time_s)
        routed = None if event is None else route(event, self.layout)
        if self.thru is not None:
            out = thru_bytes(data, routed)
            if out is not None:
                if self.delay_s > 0:
                    self.thru.send_at(out, time_s)
                else:
                    self.thru.send(out)
        if routed is None or routed.performer is None:
            return
        if self.stream is not None:
            self.stream.send_routed(routed)
        try:
            self._queue.put_nowait(Arrival(arrival_s, routed))
        except queue.Full:
            with self._dropped_lock:
                self.dropped += 1
            log.warning("jam queue full (the main loop is stalled); event dropped")

    def drain(self) -> list[Arrival]:
        """Everything routed since the last call, in arrival order (main loop)."""
        out: list[Arrival] = []
        while True:
            try:
                out.append(self._queue.get_nowait())
            except queue.Empty:
                return out


# The program a remote `virja serve` needs to see on a channel before it gives
# that channel's notes to the bassist (GM 32, Acoustic Bass; routing rule 4).
RMCP_BASS_PROGRAM = 32


class RmcpStream:
    """Routed events as RMCP/1 MIDI datagrams to ``(host, port)`` over UDP.

    Each datagram's ``time`` is the event's time (arrival + delay).  Every bass
    note-on carries, in the same datagram, a program change to an acoustic bass
    before it, so the receiver's router gives that channel to the bassist even
    if it joined late or lost a datagram; drums go on channel 10 and need
    nothing.  Sequence numbers start at ``seq_start`` (the CLI passes the clock
    in milliseconds, so a restarted jam keeps numbering upwards).  Thread-safe:
    the keyboard's MIDI thread and the RTP-MIDI listener's thread both send, and
    each datagram gets its own number, sent in numbering order.
    """

    def __init__(self, host: str, port: int, *, sender: int = 1, seq_start: int = 0) -> None:
        self.sender = sender
        self.addr = (host, port)
        self._seq = seq_start & 0xFFFF_FFFF
        self._lock = threading.Lock()  # numbering and sending: one sender at a time
        self._bass_channels: set[int] = set()
        try:
            info = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0]
        except OSError as exc:
            raise ValueError(f"cannot resolve {host}:{port}: {exc}") from exc
        self._sock = socket.socket(info[0], socket.SOCK_DGRAM)
        self._target = info[4]
        self.sent = 0

    def datagrams(self, routed: Routed) -> list[bytes]:
        """The datagrams for one routed event (pure but for the sequence counter)."""
        out = []
        ev = routed.event
        t_us = wire.s_to_us(ev.time_s)
        perf: Performer | None = routed.performer
        if perf == "bass" and isinstance(ev, NoteOn):
            self._bass_channels.add(ev.channel)
            pc = ProgramChange(time_s=ev.time_s, channel=ev.channel, program=RMCP_BASS_PROGRAM)
            out.append(self._next(t_us, encode(pc), encode(ev)))
        else:
            out.append(self._next(t_us, encode(ev)))
        return out

    def _next(self, time_us: int, *messages: bytes) -> bytes:
        dgram = wire.midi(self.sender, self._seq, time_us, *messages)
        self._seq = (self._seq + 1) & 0xFFFF_FFFF
        return bytes(dgram)

    def send_routed(self, routed: Routed) -> None:
        if routed.performer is None:
            return
        with self._lock:
            for data in self.datagrams(routed):
                try:
                    self._sock.sendto(data, self._target)
                    self.sent += 1
                except OSError as exc:  # a remote that is not up must not stop the jam
                    log.warning("RMCP send to %s:%s failed: %s", *self.addr, exc)

    def close(self) -> None:
        self._sock.close()
