"""The planning side's timer: sleep until the next deadline, or until poked.

The daemon has nothing to do between deadlines: the start of the next motion
(the planner knows it, :meth:`~virja.plan.planner.OnlinePlanner.next_deadline`),
a status line, a recorder flush.  Datagrams poke the timer, because a note can
bring an earlier deadline.  Idle, the process sleeps (no fixed tick).
"""

from __future__ import annotations

import asyncio
import contextlib
import math

MAX_SLEEP_S = 3600.0  # an idle daemon still wakes once an hour (harmless; keeps waits bounded)


def wake_in(deadlines: list[float], now_s: float) -> float:
    """Seconds from ``now_s`` to the earliest of ``deadlines`` (0 if one has passed)."""
    earliest = min(deadlines, default=math.inf)
    return min(max(earliest - now_s, 0.0), MAX_SLEEP_S)


class DeadlineTimer:
    """``arm()``, do the work and compute the next deadline, then ``sleep(s)``:
    returns after ``s`` seconds or as soon as :meth:`poke` is called (also a poke
    between ``arm`` and ``sleep``: it is not lost)."""

    def __init__(self) -> None:
        self._wake = asyncio.Event()
        self.wakeups = 0

    def poke(self) -> None:
        self._wake.set()

    def arm(self) -> None:
        self._wake.clear()

    async def sleep(self, seconds: float) -> None:
        self.wakeups += 1
        if seconds <= 0 or self._wake.is_set():
            await asyncio.sleep(0)
            return
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._wake.wait(), seconds)
