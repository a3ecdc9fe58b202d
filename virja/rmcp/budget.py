"""Per-peer budgets: no sender can monopolise the receiver (docs/reliability.md).

Each source address (host, port) gets token buckets for datagrams, bytes and
note-ons per second; what exceeds them is dropped by reason before the costly
work: ``rate_limited`` (datagram or byte budget) before a datagram is parsed;
``note_flood`` (note budget) for each note-on beyond it, and for a whole MIDI
datagram, unparsed, from a peer whose note budget is already spent -- so a
1,200-byte datagram of 400 notes costs a header peek, not a parse and 400 plans.
Clock replies owed to anyone have one shared budget (``clock_rate_limited``):
a forged source cannot turn the receiver into an amplifier.

Pure and sans-IO: every call takes ``now_us``.  At most ``max_peers`` peers are
tracked, least recently heard forgotten first (a forgotten peer starts again
with full buckets, as a new one does).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Hashable
from dataclasses import dataclass


@dataclass(frozen=True)
class Budget:
    """Rates per peer (per second); each bucket holds ``burst_s`` seconds of its rate
    (the note bucket ``notes_burst`` notes).

    The defaults are far above what a band sends (a dense drum part is about
    100 datagrams, 4 KB and 50 notes a second, a chord 10 notes at once) and
    well below what the daemon can plan.
    """

    datagrams_per_s: float = 1000.0
    bytes_per_s: float = 64_000.0
    notes_per_s: float = 200.0
    notes_burst: int = 64  # at most this many note-ons at once (a datagram's worth)
    clock_replies_per_s: float = 100.0  # all peers together
    burst_s: float = 1.0
    max_peers: int = 1024

    def __post_init__(self) -> None:
        rates = (self.datagrams_per_s, self.bytes_per_s, self.notes_per_s)
        if not all(r > 0 for r in rates) or not self.clock_replies_per_s >= 0:
            raise ValueError("budget rates must be > 0 (clock replies >= 0)")
        if not self.burst_s > 0 or self.max_peers < 1 or self.notes_burst < 1:
            raise ValueError("burst_s must be > 0, max_peers and notes_burst >= 1")


class Bucket:
    """A token bucket: ``rate`` tokens a second, at most ``depth``; starts full."""

    __slots__ = ("depth", "last_us", "rate", "tokens")

    def __init__(self, rate: float, depth: float, now_us: int) -> None:
        self.rate = rate
        self.depth = depth
        self.tokens = depth
        self.last_us = now_us

    def _refill(self, now_us: int) -> None:
        if now_us > self.last_us:
            self.tokens = min(self.depth, self.tokens + (now_us - self.last_us) * self.rate / 1e6)
        self.last_us = max(self.last_us, now_us)  # a clock step back refills nothing

    def take(self, n: float, now_us: int) -> bool:
        """Take ``n`` tokens if there are that many."""
        self._refill(now_us)
        if self.tokens >= n:
            self.tokens -= n
            return True
        return False

    def take_up_to(self, n: int, now_us: int) -> int:
        """Take as many whole tokens as there are, up to ``n``; how many."""
        self._refill(now_us)
        got = min(n, int(self.tokens))
        self.tokens -= got
        return got


class _Peer:
    __slots__ = ("bytes", "datagrams", "notes")

    def __init__(self, b: Budget, now_us: int) -> None:
        self.datagrams = Bucket(b.datagrams_per_s, b.datagrams_per_s * b.burst_s, now_us)
        self.bytes = Bucket(b.bytes_per_s, b.bytes_per_s * b.burst_s, now_us)
        self.notes = Bucket(b.notes_per_s, b.notes_burst, now_us)


class PeerBudgets:
    """The buckets of every peer heard lately (at most ``budget.max_peers``)."""

    def __init__(self, budget: Budget | None = None) -> None:
        self.budget = budget or Budget()
        self._peers: OrderedDict[Hashable, _Peer] = OrderedDict()
        b = self.budget
        self._clock = Bucket(b.clock_replies_per_s, b.clock_replies_per_s * b.burst_s, 0)
        self.evicted = 0

    def _peer(self, peer: Hashable, now_us: int) -> _Peer:
        p = self._peers.get(peer)
        if p is None:
            p = self._peers[peer] = _Peer(self.budget, now_us)
            if len(self._peers) > self.budget.max_peers:
                self._peers.popitem(last=False)
                self.evicted += 1
        else:
            self._peers.move_to_end(peer)
        return p

    def admit(self, peer: Hashable, size: int, now_us: int) -> bool:
        """Whether a datagram of ``size`` bytes from ``peer`` is within its budget."""
        p = self._peer(peer, now_us)
        if not p.datagrams.take(1, now_us):
            return False
        return p.bytes.take(size, now_us)

    def notes(self, peer: Hashable, n: int, now_us: int) -> int:
        """How many of ``n`` note-ons from ``peer`` fit its note budget (taken)."""
        return self._peer(peer, now_us).notes.take_up_to(n, now_us)

    def out_of_notes(self, peer: Hashable, now_us: int) -> bool:
        """Whether ``peer``'s note budget is spent (its next note-on would be shed)."""
        p = self._peers.get(peer)
        if p is None:
            return False
        p.notes._refill(now_us)
        return p.notes.tokens < 1

    def clock_reply(self, now_us: int) -> bool:
        """Whether one more clock reply may be sent now (shared by all peers)."""
        return self._clock.take(1, now_us)

    def __len__(self) -> int:
        return len(self._peers)


def peer_of(addr: object) -> Hashable:
    """The budget key of a transport address: (host, port), or the address itself."""
    if isinstance(addr, tuple) and len(addr) >= 2:
        return (addr[0], addr[1])
    return addr if isinstance(addr, Hashable) else repr(addr)
