"""Frame pacing: when to draw the next frame and for which moment (pure; time passed in).

A frame is due at a slot of the display (every ``period_s``: the monitor's refresh
with vsync, the configured rate otherwise).  Drawing takes time, so a frame is
started ``draw_s`` (a running estimate) before its slot and shows the pose of
the slot's moment: an impact appears on screen when its sound is due, not a
frame later.  A frame that cannot be ready by its slot is skipped (the next
slot that can still be met is taken): frames are never queued, so a slow frame
costs smoothness, never lag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

MAX_DRAW_ESTIMATE_S = 0.25  # a stall (swap-out, a hog) must not push every later frame back


@dataclass(frozen=True, slots=True)
class Slot:
    """The next frame: start drawing at ``draw_at``, show the pose of ``show_at``."""

    draw_at: float
    show_at: float


@dataclass
class FramePacer:
    """Slots ``period_s`` apart; ``draw_s`` is the running estimate of a frame's cost.

    With ``vsync`` the swap itself waits for the display, so a frame is drawn at
    once and shows the moment of the swap after it.
    """

    period_s: float
    vsync: bool = False
    draw_s: float = 0.0
    shown: int = 0
    skipped: int = 0
    _next_show: float | None = None

    def __post_init__(self) -> None:
        if not (self.period_s > 0 and math.isfinite(self.period_s)):
            raise ValueError(f"frame period must be > 0, got {self.period_s}")

    def next_slot(self, now: float) -> Slot:
        """The slot to draw for next, as of ``now`` (skipping those already missed)."""
        ready = now + self.draw_s
        if self.vsync:  # the swap waits for the display: draw now, shown when done
            return Slot(now, ready)
        if self._next_show is None:
            self._next_show = ready
        elif self._next_show < ready:  # missed: skip to the first slot that can be met
            missed = math.ceil((ready - self._next_show) / self.period_s - 1e-9)
            self.skipped += missed
            self._next_show += missed * self.period_s
        return Slot(self._next_show - self.draw_s, self._next_show)

    def drawn(self, started: float, finished: float) -> None:
        """A frame was drawn from ``started`` to ``finished``: learn its cost, advance."""
        cost = min(max(finished - started, 0.0), MAX_DRAW_ESTIMATE_S)
        self.draw_s = cost if self.shown == 0 else 0.8 * self.draw_s + 0.2 * cost
        self.shown += 1
        if self._next_show is not None:
            self._next_show += self.period_s
