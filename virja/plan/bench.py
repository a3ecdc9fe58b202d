"""A fixed workload for benchmarking the scheduler (tools/ times it; no clock here).

:func:`beat_workload` makes one beat of ``n`` notes per performer (seeded);
:func:`plan_one_beat` is the unit of work the performance target is about:
an :class:`OnlinePlanner` given the whole beat at once, then flushed.
"""

from __future__ import annotations

import random

from virja.events import NoteOn
from virja.plan.config import PlanConfig
from virja.plan.planner import OnlinePlanner
from virja.plan.types import PlannedNote
from virja.vocab import Performer

DRUM_NOTES = (36, 38, 42, 46, 51, 49, 45, 48, 43)


def beat_workload(
    seed: int = 0, n: int = 16, seconds_per_beat: float = 0.5
) -> list[tuple[Performer, NoteOn]]:
    """``n`` bass and ``n`` drum notes spread over one beat (drums two at a time)."""
    rng = random.Random(seed)
    step = seconds_per_beat / n
    out: list[tuple[Performer, NoteOn]] = []
    for i in range(n):
        t = i * step
        out.append(("bass", NoteOn(t, 0, rng.randint(28, 67), 100)))
        out.append(("drums", NoteOn(t - t % (2 * step), 9, rng.choice(DRUM_NOTES), 100)))
    return out


def plan_one_beat(
    notes: list[tuple[Performer, NoteOn]], config: PlanConfig | None = None
) -> list[PlannedNote]:
    """Plan one beat known in full at time -1 s (one DP per chain), return every note."""
    planner = OnlinePlanner(config)
    for performer, note in notes:
        planner.add_note(performer, note, now_s=-1.0)
    return planner.flush()
