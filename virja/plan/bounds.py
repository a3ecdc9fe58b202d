"""Bounds on the planner's work per note, whatever arrives (docs/reliability.md).

The solvers are exact dynamic programmes over every pending note of a chain;
valid but hostile input (hundreds of drum notes a millisecond apart inside the
horizon, thousands of bass notes) makes their state space and their re-plans
grow without bound.  Three bounds sit around them, each far above what music
needs, so plans of real music do not change (docs/reliability.md says how that
was checked):

- :class:`DensityGate`: at most ``max_notes`` notes of one chain within
  ``span_s`` either side of a note's time; a note beyond that is dropped under
  its own reason, ``too_dense``, before it reaches a solver.  At most
  ``max_pending`` notes wait per chain (reason ``planner_full``).
- a window: one solve covers at most ``window_groups`` groups of notes; later
  groups are solved when the earlier ones are fixed.
- a beam: a DP layer keeps at most ``beam`` states (the least-cost ones, ties
  in the order reached) -- the cut-off that bounds a solve's work: the plan
  that comes out is the best the kept states allow, always a valid one.

The work of one solve is thus at most ``window_groups * beam * options``
transitions, whatever the traffic.  All three are counts, not clock readings,
so a plan stays a pure function of the notes and when they became known
(a live daemon's plan still equals its replay).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

# real drumming: the densest hand passage of the Groove MIDI Dataset has 11 notes in
# 0.25 s (a 0.125 s span either side); a hand strikes at most every 0.07 s
DENSE_SPAN_S = 0.125


@dataclass(frozen=True)
class PlanBounds:
    """The planner's bounds (see the module docstring); ``None`` disables the planner's."""

    span_s: float = DENSE_SPAN_S
    max_notes: int = 32  # per chain within span_s either side of a note
    max_pending: int = 1024  # notes waiting per chain
    window_groups: int = 16  # groups per solve
    beam: int = 64  # states per DP layer (drums' hands; real drumming needs 25-45)

    def __post_init__(self) -> None:
        if not self.span_s > 0 or min(self.max_notes, self.max_pending) < 1:
            raise ValueError("span_s must be > 0 and max_notes, max_pending >= 1")
        if self.window_groups < 1 or self.beam < 1:
            raise ValueError("window_groups and beam must be >= 1")


DEFAULT_BOUNDS = PlanBounds()


class DensityGate:
    """Times of the notes one chain took, to refuse a note where there are too many.

    ``admit(t)`` is O(log n); times long fixed are forgotten by ``forget_before``.
    """

    __slots__ = ("_span", "_max", "_times")

    def __init__(self, bounds: PlanBounds) -> None:
        self._span = bounds.span_s
        self._max = bounds.max_notes
        self._times: list[float] = []

    def admit(self, t: float) -> bool:
        """Whether a note at ``t`` fits (and if so it is counted)."""
        times = self._times
        lo = bisect.bisect_left(times, t - self._span)
        hi = bisect.bisect_right(times, t + self._span)
        if hi - lo >= self._max:
            return False
        times.insert(bisect.bisect_right(times, t), t)
        return True

    def forget_before(self, t: float) -> None:
        """Drop the times before ``t - span_s`` (no later note can count them)."""
        cut = bisect.bisect_left(self._times, t - self._span)
        if cut:
            del self._times[:cut]

    def __len__(self) -> int:
        return len(self._times)


def keep_best(costs: list[float], beam: int) -> list[int] | None:
    """Indices of the ``beam`` least ``costs`` in index order (ties: the lower index),
    or None when there are no more than ``beam`` (nothing to cut)."""
    if len(costs) <= beam:
        return None
    order = sorted(range(len(costs)), key=costs.__getitem__)  # stable: ties by index
    return sorted(order[:beam])
