"""The sans-IO RMCP/1 receiver: validate, verify, dedupe, horizon, lateness.

Feed it with ``receive_datagram(data, addr, now_us=...)``; take events with
``next_event()`` / ``drain_events()`` and the datagrams it wants sent (clock
replies) with ``datagrams_to_send(now_us=...)``.  It never raises on input and
never sleeps; every datagram or event it does not deliver is counted in
``stats.dropped`` under a reason (docs/rmcp.md lists them).

Events are released on arrival, not at their time: the planner needs them a
beat ahead.  Each comes wrapped in :class:`Received`; the consumer orders them
by ``event.time_s``.
"""

from __future__ import annotations

import logging
from collections import Counter, OrderedDict, deque
from dataclasses import dataclass, field, replace
from typing import Any

from virja.events import Event, NoteOn
from virja.midispec import NOTE_ON
from virja.rmcp.bodies import ClockRequestBody, MidiBody, UnknownBody
from virja.rmcp.budget import Budget, PeerBudgets, peer_of
from virja.rmcp.errors import RmcpError
from virja.rmcp.seqnum import SeqWindow, seq_add, seq_diff
from virja.rmcp.signing import sign, tag_matches
from virja.rmcp.wire import TAG_LEN, Datagram, Kind, clock_reply, kind_name, to_events, us_to_s

KIND_AT = 5  # the kind byte's offset in the header (after magic and version)

log = logging.getLogger(__name__)

Addr = Any  # whatever the transport gives: (host, port) or (host, port, flow, scope)


@dataclass(frozen=True)
class ReceiverConfig:
    """Receiver settings.

    horizon_s: events further ahead of arrival than this are dropped.
    lateness_s: a note-on at most this late is still delivered, marked late.
    key: HMAC key; when set, unsigned, forged and replayed datagrams are dropped.
    max_age_s: with a key, datagrams whose ``time`` is older than this are stale.
    max_senders: per-sender state kept for at most this many senders (LRU).
    sender_id: this endpoint's own sender id, used in the clock replies it sends.
    answer_clock: whether CLOCK_REQUESTs are answered.
    max_queue: at most this many undelivered events are kept (oldest dropped).
    budget: per-peer datagram, byte and note rates and the clock-reply rate
        (virja.rmcp.budget); None: unlimited.
    """

    horizon_s: float = 10.0
    lateness_s: float = 0.060
    key: bytes | None = None
    max_age_s: float = 30.0
    max_senders: int = 1024
    sender_id: int = 0
    answer_clock: bool = True
    max_queue: int = 65536
    budget: Budget | None = Budget()


@dataclass(frozen=True, slots=True)
class Received:
    """An event as delivered: arrival time on the session clock, and whether late.

    ``late`` is True when the event's time had already passed on arrival
    (a note-on within the lateness, or a note-off / controller / beat that is
    always applied).
    """

    event: Event
    arrival_s: float
    late: bool = False


@dataclass
class ReceiverStats:
    """Counters: datagrams seen, accepted (per kind), events delivered, drops by reason."""

    datagrams: int = 0
    accepted: int = 0
    events: int = 0
    late: int = 0
    by_kind: Counter[str] = field(default_factory=Counter)
    dropped: Counter[str] = field(default_factory=Counter)
    senders_evicted: int = 0

    def as_dict(self) -> dict[str, object]:
        return {
            "datagrams": self.datagrams,
            "accepted": self.accepted,
            "events": self.events,
            "late": self.late,
            "by_kind": dict(self.by_kind),
            "dropped": dict(self.dropped),
            "senders_evicted": self.senders_evicted,
        }


class _SenderState:
    __slots__ = ("window",)

    def __init__(self, seq: int) -> None:
        self.window = SeqWindow(seq)


class Receiver:
    """Sans-IO RMCP/1 receiver state (one per listening endpoint)."""

    def __init__(self, config: ReceiverConfig | None = None) -> None:
        self.config = config or ReceiverConfig()
        self.stats = ReceiverStats()
        self._senders: OrderedDict[int, _SenderState] = OrderedDict()
        self._events: deque[Received] = deque()
        self._clock_requests: deque[tuple[ClockRequestBody, Addr, int]] = deque(maxlen=64)
        self._seq = 0
        self._horizon_us = round(self.config.horizon_s * 1_000_000)
        self._max_age_us = round(self.config.max_age_s * 1_000_000)
        budget = self.config.budget
        self._budgets = PeerBudgets(budget) if budget is not None else None

    # -- input -----------------------------------------------------------------

    def receive_datagram(self, data: bytes, addr: Addr, *, now_us: int) -> None:
        """Take one datagram that arrived at ``now_us`` (session clock). Never raises."""
        self.stats.datagrams += 1
        try:
            self._receive(data, addr, now_us)
        except RmcpError as exc:
            self.stats.dropped[exc.reason] += 1
            log.debug("dropped datagram from %s: %s", addr, exc)
        except Exception:  # a bug must not stop the receiver; count it and go on
            self.stats.dropped["internal_error"] += 1
            log.exception("internal error on a datagram from %s", addr)

    def _receive(self, data: bytes, addr: Addr, now_us: int) -> None:
        # the budget first: a peer over it costs a dictionary look-up, not a parse
        budgets = self._budgets
        if budgets is not None:
            peer = peer_of(addr)
            if not budgets.admit(peer, len(data), now_us):
                self.stats.dropped["rate_limited"] += 1
                return
            # a peer out of note budget: its MIDI is shed unparsed (the kind byte peeked)
            midi = len(data) > KIND_AT and data[KIND_AT] == Kind.MIDI
            if midi and budgets.out_of_notes(peer, now_us):
                self.stats.dropped["note_flood"] += 1
                return
        dgram = Datagram.parse(data)
        key = self.config.key
        state = self._senders.get(dgram.sender)
        if key is not None:
            if not dgram.signed:
                self._drop("unsigned", dgram, addr)
                return
            if not tag_matches(key, data[:-TAG_LEN], dgram.tag):
                self._drop("bad_tag", dgram, addr)
                return
            if dgram.time_us < now_us - self._max_age_us:
                self._drop("stale", dgram, addr)
                return
        if state is not None:
            if state.window.seen(dgram.seq):
                self._drop("duplicate", dgram, addr)
                return
            if key is not None and seq_diff(dgram.seq, state.window.highest) <= 0:
                self._drop("replay", dgram, addr)
                return
        self._accept(dgram, state)
        self._deliver(dgram, addr, now_us)

    def _drop(self, reason: str, dgram: Datagram, addr: Addr) -> None:
        self.stats.dropped[reason] += 1
        log.debug(
            "dropped %s seq %d from sender %d at %s: %s",
            kind_name(dgram.kind),
            dgram.seq,
            dgram.sender,
            addr,
            reason,
        )

    def _accept(self, dgram: Datagram, state: _SenderState | None) -> None:
        if state is None:
            state = _SenderState(dgram.seq)
            self._senders[dgram.sender] = state
            if len(self._senders) > self.config.max_senders:
                self._senders.popitem(last=False)
                self.stats.senders_evicted += 1
        else:
            state.window.add(dgram.seq)
            self._senders.move_to_end(dgram.sender)
        self.stats.accepted += 1
        self.stats.by_kind[kind_name(dgram.kind)] += 1

    def _deliver(self, dgram: Datagram, addr: Addr, now_us: int) -> None:
        body = dgram.body
        if isinstance(body, UnknownBody):
            self.stats.dropped["unknown_kind"] += 1
            return
        if isinstance(body, ClockRequestBody):
            if not self.config.answer_clock:
                return
            if self._budgets is not None and not self._budgets.clock_reply(now_us):
                self.stats.dropped["clock_rate_limited"] += 1
                return
            self._clock_requests.append((body, addr, now_us))
            return
        time_us = now_us if dgram.immediate else dgram.time_us
        if time_us - now_us > self._horizon_us:
            self.stats.dropped["beyond_horizon"] += 1
            return
        too_late = now_us - time_us > round(self.config.lateness_s * 1_000_000)
        if self._budgets is not None and not too_late and isinstance(body, MidiBody):
            dgram = self._within_note_budget(dgram, body, addr, now_us)
        events = to_events(dgram, time_s=us_to_s(time_us))
        if not events:
            return
        now_s = us_to_s(now_us)
        late = time_us < now_us
        for ev in events:
            if too_late and isinstance(ev, NoteOn):
                self.stats.dropped["too_late"] += 1
                continue
            if len(self._events) >= self.config.max_queue:
                self._events.popleft()
                self.stats.dropped["queue_full"] += 1
            self._events.append(Received(ev, now_s, late))
            self.stats.events += 1
            if late:
                self.stats.late += 1

    def _within_note_budget(
        self, dgram: Datagram, body: MidiBody, addr: Addr, now_us: int
    ) -> Datagram:
        """``dgram`` without the note-ons beyond its peer's note budget (counted as
        ``note_flood``); they are cut from the messages before any event is made."""
        assert self._budgets is not None
        ons = [i for i, m in enumerate(body.messages) if m[0] & 0xF0 == NOTE_ON and m[2]]
        if not ons:
            return dgram
        allowed = self._budgets.notes(peer_of(addr), len(ons), now_us)
        if allowed >= len(ons):
            return dgram
        cut = set(ons[allowed:])
        self.stats.dropped["note_flood"] += len(cut)
        kept = tuple(m for i, m in enumerate(body.messages) if i not in cut)
        return replace(dgram, body=MidiBody(kept))

    # -- output ----------------------------------------------------------------

    def next_event(self) -> Received | None:
        """The oldest undelivered event (arrival order), or None."""
        return self._events.popleft() if self._events else None

    def drain_events(self) -> list[Received]:
        """Every undelivered event, in arrival order."""
        out = list(self._events)
        self._events.clear()
        return out

    def datagrams_to_send(self, *, now_us: int) -> list[tuple[bytes, Addr]]:
        """Clock replies owed, as (bytes, address); t2 is ``now_us``."""
        out: list[tuple[bytes, Addr]] = []
        while self._clock_requests:
            req, addr, t1_us = self._clock_requests.popleft()
            reply = clock_reply(
                self.config.sender_id, self._next_seq(), req, t1_us=t1_us, t2_us=now_us
            )
            if self.config.key is not None:
                reply = sign(reply, self.config.key)
            out.append((bytes(reply), addr))
        return out

    def _next_seq(self) -> int:
        seq = self._seq
        self._seq = seq_add(seq, 1)
        return seq

    @property
    def tracked_senders(self) -> int:
        return len(self._senders)

    @property
    def tracked_peers(self) -> int:
        """Source addresses with budgets (at most the budget's ``max_peers``)."""
        return len(self._budgets) if self._budgets is not None else 0
