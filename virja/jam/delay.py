"""The delay line of the thru output: a pure scheduler, time passed in.

With ``--delay-ms D`` every key's sound (the thru output) and picture are put
off by D, so the drawn player has the whole anticipation of each motion.  The
picture's delay is the event's time stamp (arrival + D); the sound's is this
queue: :meth:`DelayLine.push` a message with the time it is due,
:meth:`DelayLine.pop_due` hands back what is due at ``now_s``, in order of due
time (ties keep the order they were pushed in, so a note-off never overtakes
the note-on pushed before it at the same time).  The thread that sleeps until
the next due time lives in :mod:`virja.jam.ports`.
"""

from __future__ import annotations

import heapq
import itertools
from dataclasses import dataclass, field


@dataclass(frozen=True, order=True, slots=True)
class Due:
    """A message due at ``due_s`` (session seconds); ``seq`` keeps push order."""

    due_s: float
    seq: int
    data: bytes = field(compare=False)


class DelayLine:
    """A time-ordered queue of MIDI messages.  Not thread-safe (its IO owner locks)."""

    def __init__(self, limit: int = 65536) -> None:
        self._heap: list[Due] = []
        self._count = itertools.count()
        self.limit = limit
        self.dropped = 0

    def __len__(self) -> int:
        return len(self._heap)

    def push(self, data: bytes, due_s: float) -> bool:
        """Queue ``data`` for ``due_s``; False (and counted) when the queue is full."""
        if len(self._heap) >= self.limit:
            self.dropped += 1
            return False
        heapq.heappush(self._heap, Due(due_s, next(self._count), bytes(data)))
        return True

    def next_due_s(self) -> float | None:
        """When the earliest message is due; None when empty."""
        return self._heap[0].due_s if self._heap else None

    def pop_due(self, now_s: float) -> list[bytes]:
        """Every message due at or before ``now_s``, earliest first."""
        out: list[bytes] = []
        while self._heap and self._heap[0].due_s <= now_s:
            out.append(heapq.heappop(self._heap).data)
        return out

    def drain(self) -> list[bytes]:
        """Everything left, earliest first (on close: note-offs must not be lost)."""
        out = [d.data for d in sorted(self._heap)]
        self._heap.clear()
        return out
