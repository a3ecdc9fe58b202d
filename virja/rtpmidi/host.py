"""The sans-IO RTP-MIDI session listener: what a Mac's Network session host does.

Feed it with ``receive_datagram(data, addr, channel=CONTROL | DATA,
now_us=...)``; take the MIDI that arrived with ``drain_messages()`` and the
datagrams it owes (OK/NO answers, CK1 answers, RS feedback, BY on close) with
``datagrams_to_send(now_us=...)``, each with the channel to send it from.
Call ``tick(now_us)`` now and then: it drops sessions that went quiet and
queues receiver feedback.  It never raises on input and never sleeps; every
datagram it does not use is counted in ``stats.dropped`` by reason.

A session is keyed by the initiator's SSRC: IN on the control port makes it
*pending*, IN on the data port (same SSRC, same host) *open*.  MIDI is taken
only from open sessions, from the address their data IN came from.
Per-session state is a few numbers, and at most ``max_sessions`` exist; a
session quiet for ``session_timeout_s`` (pending: ``pending_timeout_s``) is
dropped.  A peer may send at most ``max_commands_per_s`` commands a second
(a token bucket); the rest are counted as ``flood``.
"""

from __future__ import annotations

import logging
import random
from collections import Counter, deque
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from virja.rtpmidi import CLOCK_RATE
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
from virja.rtpmidi.errors import RtpMidiError
from virja.rtpmidi.payload import MidiPacket

log = logging.getLogger(__name__)

Addr = Any  # (host, port) or (host, port, flow, scope), as the transport gives it
MAX_DATAGRAM = 4096  # an RTP-MIDI packet fits an Ethernet frame; anything past this is junk


class Channel(Enum):
    CONTROL = "control"
    DATA = "data"


@dataclass(frozen=True)
class HostConfig:
    name: str = "virja"
    ssrc: int | None = None  # None: random
    max_sessions: int = 16
    session_timeout_s: float = 60.0  # initiators sync every 10 s (Apple, node-rtpmidi)
    pending_timeout_s: float = 10.0
    feedback_interval_s: float = 1.0
    max_commands_per_s: float = 2000.0  # far above two hands; a burst of that many passes
    max_offset_s: float = 1.0  # a command's delta time may put it at most this far ahead
    max_queue: int = 65536


@dataclass(frozen=True, slots=True)
class Incoming:
    """One MIDI message as it arrived: its bytes, its time on the session clock
    (arrival plus the delta time within its packet) and the peer's SSRC."""

    data: bytes
    time_s: float
    arrival_s: float
    ssrc: int


@dataclass
class HostStats:
    datagrams: int = 0
    by_kind: Counter[str] = field(default_factory=Counter)
    dropped: Counter[str] = field(default_factory=Counter)
    sessions_opened: int = 0
    sessions_ended: int = 0
    sessions_timed_out: int = 0
    messages: int = 0
    sysex_skipped: int = 0
    journals_ignored: int = 0
    lost_packets: int = 0
    last_latency_ms: float | None = None  # one way, from the last CK2

    def as_dict(self) -> dict[str, object]:
        return {
            "datagrams": self.datagrams,
            "by_kind": dict(self.by_kind),
            "dropped": dict(self.dropped),
            "sessions_opened": self.sessions_opened,
            "sessions_ended": self.sessions_ended,
            "sessions_timed_out": self.sessions_timed_out,
            "messages": self.messages,
            "sysex_skipped": self.sysex_skipped,
            "journals_ignored": self.journals_ignored,
            "lost_packets": self.lost_packets,
        }


@dataclass
class Session:
    ssrc: int
    token: int
    name: str
    control: Addr
    data: Addr | None
    last_heard_us: int
    last_seq: int | None = None
    feedback_due: bool = False
    last_feedback_us: int = 0
    tokens: float = 0.0
    tokens_us: int = 0

    @property
    def open(self) -> bool:
        return self.data is not None


def _host(addr: Addr) -> Any:
    return addr[0] if isinstance(addr, tuple) and addr else addr


class SessionHost:
    """Accepts invitations and turns open sessions' RTP-MIDI into :class:`Incoming`."""

    def __init__(self, config: HostConfig | None = None) -> None:
        self.config = config or HostConfig()
        self.ssrc = self.config.ssrc if self.config.ssrc is not None else random.getrandbits(32)
        self.sessions: dict[int, Session] = {}
        self.stats = HostStats()
        self._messages: deque[Incoming] = deque()
        self._out: list[tuple[bytes, Addr, Channel]] = []
        self._epoch_us: int | None = None

    # -- input -----------------------------------------------------------------

    def receive_datagram(self, data: bytes, addr: Addr, *, channel: Channel, now_us: int) -> None:
        """One datagram that arrived on ``channel``'s port; never raises on bad input."""
        self.stats.datagrams += 1
        if self._epoch_us is None:
            self._epoch_us = now_us
        if len(data) > MAX_DATAGRAM:
            self.stats.dropped["too_long"] += 1
            return
        try:
            if is_control(data):
                self._control(parse_control(data), addr, channel, now_us)
            elif channel is Channel.DATA:
                self._midi(MidiPacket.parse(data), addr, now_us)
            else:
                self.stats.dropped["midi_on_control_port"] += 1
        except RtpMidiError as exc:
            self.stats.dropped[exc.reason] += 1
            log.debug("dropped a datagram from %s: %s", addr, exc)

    def _drop(self, reason: str) -> None:
        self.stats.dropped[reason] += 1

    def _control(self, pkt: Any, addr: Addr, channel: Channel, now_us: int) -> None:
        kind = packet_kind(pkt)
        self.stats.by_kind[kind] += 1
        if isinstance(pkt, SessionPacket):
            if pkt.command is Command.IN:
                self._invitation(pkt, addr, channel, now_us)
            elif pkt.command is Command.BY:
                s = self.sessions.get(pkt.ssrc)
                if s is None or _host(s.control) != _host(addr):
                    self._drop("unknown_session")
                    return
                del self.sessions[pkt.ssrc]
                self.stats.sessions_ended += 1
            else:  # OK / NO: answers to invitations; this host never invites
                self._drop("unexpected_" + kind.lower())
            return
        s = self.sessions.get(pkt.ssrc)
        if s is None or _host(s.control) != _host(addr):
            self._drop("unknown_session")
            return
        s.last_heard_us = now_us
        if isinstance(pkt, SyncPacket):
            if pkt.count == 0:
                ts = (pkt.timestamps[0], self._ticks(now_us), 0)
                self._out.append((bytes(SyncPacket(self.ssrc, 1, ts)), addr, channel))
            elif pkt.count == 2:
                t1, _t2, t3 = pkt.timestamps
                self.stats.last_latency_ms = (t3 - t1) / CLOCK_RATE * 1000 / 2
            else:
                self._drop("unexpected_ck1")
        elif isinstance(pkt, FeedbackPacket | LimitPacket):
            pass  # noted in by_kind: this host sends no MIDI, so nothing to trim or slow

    def _invitation(self, pkt: SessionPacket, addr: Addr, channel: Channel, now_us: int) -> None:
        s = self.sessions.get(pkt.ssrc)
        if channel is Channel.CONTROL:
            if s is None:
                if len(self.sessions) >= self.config.max_sessions:
                    self._drop("sessions_full")
                    self._answer(Command.NO, pkt, addr, channel)
                    return
                s = Session(pkt.ssrc, pkt.token, pkt.name, addr, None, now_us)
                self.sessions[pkt.ssrc] = s
            elif _host(s.control) != _host(addr) or s.token != pkt.token:
                self._drop("ssrc_in_use")
                self._answer(Command.NO, pkt, addr, channel)
                return
            s.last_heard_us = now_us
            self._answer(Command.OK, pkt, addr, channel)  # again on a repeated IN: ours was lost
            return
        if s is None or _host(s.control) != _host(addr) or s.token != pkt.token:
            self._drop("not_invited")
            self._answer(Command.NO, pkt, addr, channel)
            return
        if s.data is None:
            s.data = addr
            s.tokens = self.config.max_commands_per_s
            s.tokens_us = now_us
            self.stats.sessions_opened += 1
            log.info("RTP-MIDI session with %r (%s) open", s.name, _host(addr))
        s.last_heard_us = now_us
        self._answer(Command.OK, pkt, addr, channel)

    def _answer(self, cmd: Command, pkt: SessionPacket, addr: Addr, channel: Channel) -> None:
        reply = SessionPacket(cmd, pkt.token, self.ssrc, self.config.name)
        self._out.append((bytes(reply), addr, channel))

    def _midi(self, pkt: MidiPacket, addr: Addr, now_us: int) -> None:
        s = self.sessions.get(pkt.header.ssrc)
        if s is None or not s.open:
            self._drop("unknown_ssrc")
            return
        if addr != s.data:
            self._drop("wrong_peer")
            return
        seq = pkt.header.seq
        if s.last_seq is not None:
            ahead = (seq - s.last_seq) & 0xFFFF
            if ahead == 0 or ahead >= 0x8000:
                self._drop("stale_seq")
                return
            self.stats.lost_packets += ahead - 1
        s.last_seq = seq
        s.last_heard_us = now_us
        s.feedback_due = True
        self.stats.by_kind["MIDI"] += 1
        if pkt.journal:
            self.stats.journals_ignored += 1
        # token bucket: refill at the rate, at most one second's worth
        rate = self.config.max_commands_per_s
        s.tokens = min(rate, s.tokens + max(0, now_us - s.tokens_us) / 1e6 * rate)
        s.tokens_us = max(s.tokens_us, now_us)  # a clock step back refills nothing
        arrival_s = now_us / 1e6
        for ticks, cmd in pkt.offsets():
            if cmd.is_sysex:
                self.stats.sysex_skipped += 1
                continue
            offset_s = ticks / CLOCK_RATE
            if offset_s > self.config.max_offset_s:
                self._drop("delta_too_far")
                continue
            if s.tokens < 1:
                self._drop("flood")
                continue
            s.tokens -= 1
            if len(self._messages) >= self.config.max_queue:
                self._messages.popleft()
                self._drop("queue_full")
            self._messages.append(Incoming(cmd.data, arrival_s + offset_s, arrival_s, s.ssrc))
            self.stats.messages += 1

    # -- time --------------------------------------------------------------------

    def _ticks(self, now_us: int) -> int:
        """This host's clock for CK: 100 us ticks since the first datagram (small
        enough for peers that read only the low 32 bits of the u64)."""
        return max(0, now_us - (self._epoch_us or now_us)) * CLOCK_RATE // 1_000_000

    def tick(self, now_us: int) -> None:
        """Drop quiet sessions; queue receiver feedback that is due."""
        cfg = self.config
        for ssrc, s in list(self.sessions.items()):
            limit_s = cfg.session_timeout_s if s.open else cfg.pending_timeout_s
            if now_us - s.last_heard_us > limit_s * 1e6:
                del self.sessions[ssrc]
                self.stats.sessions_timed_out += 1
                log.info("RTP-MIDI session with %r timed out", s.name)
                continue
            if (
                s.feedback_due
                and s.last_seq is not None
                and now_us - s.last_feedback_us >= cfg.feedback_interval_s * 1e6
            ):
                self._out.append(
                    (bytes(FeedbackPacket(self.ssrc, s.last_seq)), s.control, Channel.CONTROL)
                )
                s.feedback_due = False
                s.last_feedback_us = now_us

    def close(self) -> None:
        """End every session (BY to each peer's control port)."""
        for s in self.sessions.values():
            bye = SessionPacket(Command.BY, s.token, self.ssrc, self.config.name)
            self._out.append((bytes(bye), s.control, Channel.CONTROL))
        self.stats.sessions_ended += len(self.sessions)
        self.sessions.clear()

    # -- output ----------------------------------------------------------------

    def drain_messages(self) -> list[Incoming]:
        out = list(self._messages)
        self._messages.clear()
        return out

    def datagrams_to_send(self, *, now_us: int) -> list[tuple[bytes, Addr, Channel]]:
        self.tick(now_us)
        out, self._out = self._out, []
        return out

    @property
    def open_sessions(self) -> int:
        return sum(1 for s in self.sessions.values() if s.open)
