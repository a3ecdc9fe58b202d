"""Tempo: seconds per beat as a function of session time.

A :class:`TempoMap` is a step function built from (time_s, seconds_per_beat)
change points; it converts between beats and seconds and lists beat times.
Every consumer that needs the tempo (the planner's look-ahead and its
anticipation scaling, the animator's idle nod, ``virja send``) takes any
object with ``seconds_per_beat_at(time_s)``: the :class:`Tempo` protocol.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Protocol

DEFAULT_SECONDS_PER_BEAT = 0.5  # 120 bpm, MIDI's default tempo (500000 us per beat)


class Tempo(Protocol):
    def seconds_per_beat_at(self, time_s: float) -> float:
        """Seconds per beat in force at ``time_s``."""
        ...


@dataclass(frozen=True)
class ConstantTempo:
    """One tempo for all time."""

    seconds_per_beat: float = DEFAULT_SECONDS_PER_BEAT

    def __post_init__(self) -> None:
        if not self.seconds_per_beat > 0:
            raise ValueError(f"seconds_per_beat must be > 0, got {self.seconds_per_beat}")

    def seconds_per_beat_at(self, time_s: float) -> float:
        return self.seconds_per_beat


@dataclass
class TempoMap:
    """A step function of tempo over time, with beat <-> second conversion.

    ``changes`` are (time_s, seconds_per_beat) sorted by time; before the first
    change the first tempo applies.  ``origin_s`` is the time of beat 0.
    """

    changes: list[tuple[float, float]] = field(
        default_factory=lambda: [(0.0, DEFAULT_SECONDS_PER_BEAT)]
    )
    origin_s: float = 0.0

    def __post_init__(self) -> None:
        if not self.changes:
            self.changes = [(self.origin_s, DEFAULT_SECONDS_PER_BEAT)]
        self.changes.sort(key=lambda c: c[0])
        for t, spb in self.changes:
            if not spb > 0:
                raise ValueError(f"tempo at {t} s must be > 0 seconds per beat, got {spb}")
        self._times = [c[0] for c in self.changes]

    @classmethod
    def from_changes(
        cls, changes: Iterable[tuple[float, float]], origin_s: float = 0.0
    ) -> TempoMap:
        return cls(list(changes), origin_s)

    def seconds_per_beat_at(self, time_s: float) -> float:
        i = bisect.bisect_right(self._times, time_s) - 1
        return self.changes[max(i, 0)][1]

    def beat_at(self, time_s: float) -> float:
        """The (fractional) beat number at ``time_s``; beat 0 is at ``origin_s``."""
        return self._beats_between(self.origin_s, time_s)

    def time_at_beat(self, beat: float) -> float:
        """Inverse of :meth:`beat_at`."""
        if beat >= 0:
            t = self.origin_s
            remaining = beat
            while True:
                spb = self.seconds_per_beat_at(t)
                nxt = self._next_change_after(t)
                if nxt is None or (nxt - t) / spb >= remaining:
                    return t + remaining * spb
                remaining -= (nxt - t) / spb
                t = nxt
        # before the origin: use the first tempo that applies there
        return self.origin_s + beat * self.seconds_per_beat_at(self.origin_s - 1e-9)

    def beat_times(self, start_s: float, end_s: float) -> list[float]:
        """Times of whole beats in [start_s, end_s]."""
        import math

        b = math.ceil(self.beat_at(start_s) - 1e-9)
        out: list[float] = []
        while True:
            t = self.time_at_beat(b)
            if t > end_s + 1e-9:
                return out
            out.append(t)
            b += 1

    def _next_change_after(self, t: float) -> float | None:
        i = bisect.bisect_right(self._times, t)
        return self._times[i] if i < len(self._times) else None

    def _beats_between(self, a: float, b: float) -> float:
        if b < a:
            return -self._beats_between(b, a)
        beats = 0.0
        t = a
        while t < b:
            nxt = self._next_change_after(t)
            end = b if nxt is None else min(nxt, b)
            beats += (end - t) / self.seconds_per_beat_at(t)
            t = end
        return beats
