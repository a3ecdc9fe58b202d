"""What every chain of the online planner shares (docs/scheduler.md).

A *chain* is one player's limb or pair of limbs whose motions follow each other:
the bass's left hand (:mod:`virja.plan.chain_bass`), the drummer's hands
(:mod:`virja.plan.chain_hands`), each foot (:mod:`virja.plan.chain_feet`).
Each keeps the notes not yet started (``pending``) and what it has fixed.  The
rules common to all are written here once:

- a note taken in is aligned (start, impact, late: :func:`virja.plan.timing.align`)
  and passes the caps of :mod:`virja.plan.bounds` (``planner_full``, ``too_dense``);
- a note not after the chain's last fixed group is placed around the fixed
  motions (the chain's own :meth:`Chain.place_out_of_order`), any other waits;
- a chain that solves its groups keeps the plan in a :class:`WindowedPlan`
  (a window of groups per solve, the plan kept until a note arrives);
- :meth:`Chain.commit` fixes every group whose motion has started by ``now_s``
  (the reveal horizon: start = min over the group's notes, independent of the
  plan), with all earlier groups; :meth:`Chain.fix` does the chain's own fixing
  and then the bookkeeping (pending, its earliest start, the last fixed time,
  the density gate, the history kept for notes arriving out of order).

:class:`Ledger` holds what the chains hand out: planned notes (an outbox) and the
report's dropped and moved notes.
"""

from __future__ import annotations

import logging
import math
from abc import ABC, abstractmethod
from collections import Counter, deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Generic, TypeVar

from virja.events import NoteOn
from virja.plan import drums as drums_mod
from virja.plan.bounds import DensityGate, PlanBounds
from virja.plan.config import PlanConfig
from virja.plan.timing import aligned, offsets
from virja.plan.types import DroppedNote, DropReason, MovedNote, PlannedNote, PlanReport
from virja.vocab import BassString, Limb, MotionKey, Performer, Piece, as_limb  # noqa: F401  (as_limb: re-exported for the chains)

log = logging.getLogger(__name__)

GROUP_EPS_S = 0.001  # notes this close sound together (one stroke per piece and limb)
HISTORY = 64  # fixed strokes kept per chain for notes that arrive out of order
OFFSETS_KEPT = 4096  # alignment offsets kept per chain (kinds times tempi met)
MAX_REPORTED = 10_000  # dropped and moved notes kept for the report (totals are counted)


@dataclass(slots=True)
class Held:
    """A note the planner holds: its time, when it became known, its timing kind
    (a piece, ``"kick"``, ``"hihat_pedal"``, ``"pluck"``) and the note played (bass:
    the pitch after octave folding; drums: the note); start, impact and lateness
    once aligned."""

    seq: int
    performer: Performer
    note: NoteOn
    known_s: float
    kind: str
    played: int
    start: float = 0.0
    impact: float = 0.0
    late: bool = False


R = TypeVar("R", bound=Held)
S = TypeVar("S")


def group_notes(recs: list[R], window: float = GROUP_EPS_S) -> list[list[R]]:
    """``recs`` in time order, cut into groups of notes within ``window`` of the
    group's first note."""
    out: list[list[R]] = []
    for r in sorted(recs, key=lambda r: (r.note.time_s, r.seq)):
        if out and r.note.time_s - out[-1][0].note.time_s <= window + drums_mod.TIME_EPS_S:
            out[-1].append(r)
        else:
            out.append([r])
    return out


class Ledger:
    """The planned notes not yet handed out (``outbox``) and the report's cases."""

    def __init__(self) -> None:
        self.outbox: list[PlannedNote] = []
        self.dropped: deque[DroppedNote] = deque(maxlen=MAX_REPORTED)
        self.moved: deque[MovedNote] = deque(maxlen=MAX_REPORTED)
        self.counts: Counter[str] = Counter()
        self.unplayed: Counter[str] = Counter()  # per instrument: not a kit drummer's
        # for messages only: times are said from the input's start (Performance sets it)
        self.origin_s = 0.0

    def drop(self, rec: Held, reason: DropReason) -> None:
        log.info(
            "dropped %s note %d at %.3f s: %s",
            rec.performer,
            rec.note.note,
            rec.note.time_s - self.origin_s,
            reason,
        )
        self.dropped.append(DroppedNote(rec.performer, rec.note, reason))
        self.counts["dropped"] += 1
        self.counts[f"dropped_{reason}"] += 1

    def unmapped(self, performer: Performer, note: NoteOn) -> None:
        """A drum note outside the kit map: dropped before any chain sees it."""
        self.dropped.append(DroppedNote(performer, note, "unmapped"))
        self.counts["dropped"] += 1
        self.counts["dropped_unmapped"] += 1
        log.info("drum note %d not in the kit map: dropped", note.note)

    def move(self, performer: Performer, note: NoteOn, played: int) -> None:
        """A bass note out of range, played ``played`` (octaves moved)."""
        log.info("bass note %d out of range: played as %d", note.note, played)
        self.moved.append(MovedNote(performer, note, played))
        self.counts["moved"] += 1

    def report(self) -> PlanReport:
        return PlanReport(
            tuple(self.dropped),
            tuple(self.moved),
            tuple(sorted(self.counts.items())),
            tuple(sorted(self.unplayed.items())),
        )


class WindowedPlan(Generic[S]):
    """The optimal plan of a chain's pending groups, one step (decision) per group.

    Solved a window of at most ``window_groups`` groups at a time (plan.bounds: the
    work of one solve is bounded whatever arrives) and kept until a note arrives
    (:meth:`forget`), so fixing in several steps equals fixing in one, ties included.
    """

    def __init__(self, window_groups: int) -> None:
        self.window_groups = window_groups
        self._steps: list[S] | None = None

    def forget(self) -> None:
        self._steps = None

    def held(self) -> list[S] | None:
        """The steps kept for the pending groups from the first on (None when none):
        what the next commit fixes unless a note arrives first.  Read only."""
        return list(self._steps) if self._steps else None

    def step(
        self,
        groups: list[list[R]],
        gi: int,
        solve: Callable[[list[list[R]], int], Iterable[S]],
    ) -> S:
        """The step of ``groups[gi]``; when none is kept (none yet, or the window's
        plan is used up) ``solve(window, gi)`` the window starting there first."""
        if not self._steps:
            self._steps = list(solve(groups[gi : gi + self.window_groups], gi))
        return self._steps.pop(0)


@dataclass(frozen=True, slots=True)
class ChainContext:
    """What the chains of one planner share: its tables, bounds, ledger and tempo."""

    config: PlanConfig
    bounds: PlanBounds
    ledger: Ledger
    seconds_per_beat_at: Callable[[float], float]


class AnyChain(ABC):
    """A chain as the planner drives it, whatever its notes."""

    min_start: float

    @abstractmethod
    def commit(self, now_s: float) -> None: ...

    @abstractmethod
    def fix_all(self) -> None: ...

    @property
    @abstractmethod
    def pending_count(self) -> int: ...


class Chain(AnyChain, Generic[R]):
    """The part of a chain every chain shares (the module docstring); a subclass
    says how its groups are fixed (:meth:`fix_groups`) and how a note arriving
    after its chain's later notes were fixed is placed (:meth:`place_out_of_order`).

    ``window``: a group holds the notes within it of the group's first note.
    """

    window: float = GROUP_EPS_S

    def __init__(self, ctx: ChainContext) -> None:
        self.ctx = ctx
        self.pending: list[R] = []
        # min(r.start for r in pending), inf when none: kept up to date on every change of
        # pending so that each call need not scan it (it is checked on every note)
        self.min_start = math.inf
        self.last_fixed_t: float | None = None
        self.fixed: list[tuple[float, PlannedNote]] = []  # recent, for notes out of order
        self.gate = DensityGate(ctx.bounds)
        # what taking a note in reads, looked up once: the chain's config never changes
        self._timing = ctx.config.timing
        self._spb_at = ctx.seconds_per_beat_at
        self._max_pending = ctx.bounds.max_pending
        # timing.offsets per (kind, seconds per beat) met (a session has a few of each)
        self._offsets: dict[tuple[str, float], tuple[float, float, float]] = {}

    @property
    def pending_count(self) -> int:
        return len(self.pending)

    # -- taking a note in ---------------------------------------------------------

    def take(self, rec: R) -> None:
        """Align ``rec`` and take it in: dropped past a cap, placed around the fixed
        motions when out of order, else pending (the plan is then solved again)."""
        t = rec.note.time_s
        key = (rec.kind, self._spb_at(t))
        offs = self._offsets.get(key)
        if offs is None:
            if len(self._offsets) >= OFFSETS_KEPT:
                self._offsets.clear()
            offs = self._offsets[key] = offsets(self._timing, *key)
        rec.start, rec.impact, rec.late = aligned(offs, t, rec.known_s)
        if len(self.pending) >= self._max_pending:
            self.ctx.ledger.drop(rec, "planner_full")
            return
        if not self.gate.admit(t):
            self.ctx.ledger.drop(rec, "too_dense")
            return
        if self.last_fixed_t is not None and t <= self.last_fixed_t + GROUP_EPS_S:
            self.place_out_of_order(rec)
        else:
            self.pending.append(rec)
            if rec.start < self.min_start:
                self.min_start = rec.start
            self.forget_plan()

    def forget_plan(self) -> None:
        """A note joined the pending ones: a plan kept for them no longer holds."""

    # -- fixing ------------------------------------------------------------------

    def groups(self) -> list[list[R]]:
        return group_notes(self.pending, self.window)

    def commit(self, now_s: float) -> None:
        """Fix every group whose motion has started by ``now_s``, and all before it."""
        if self.min_start > now_s:  # nothing pending has started (or none pending)
            return
        groups = self.groups()
        started = [i for i, g in enumerate(groups) if min(r.start for r in g) <= now_s]
        if started:
            self.fix(groups, started[-1] + 1)

    def fix_all(self) -> None:
        groups = self.groups()
        self.fix(groups, len(groups))

    def fix(self, groups: list[list[R]], n_groups: int) -> None:
        """Plan the pending notes and fix the first ``n_groups`` of their ``groups``
        (:meth:`groups`)."""
        if n_groups == 0 or not self.pending:
            return
        self.fix_groups(groups, n_groups)
        fixed = {r.seq for g in groups[:n_groups] for r in g}
        self.pending = [r for r in self.pending if r.seq not in fixed]
        self.min_start = min((r.start for r in self.pending), default=math.inf)
        self.last_fixed_t = groups[n_groups - 1][0].note.time_s
        self.gate.forget_before(self.last_fixed_t)
        self.fixed = self.fixed[-HISTORY:]

    @abstractmethod
    def fix_groups(self, groups: list[list[R]], n_groups: int) -> None:
        """Emit (or drop) every note of the first ``n_groups`` of ``groups``."""

    @abstractmethod
    def place_out_of_order(self, rec: R) -> None:
        """Place ``rec`` around fixed motions without changing any of them."""

    # -- handing out -------------------------------------------------------------

    def emit(
        self,
        rec: Held,
        *,
        limb: Limb,
        piece: Piece | None,
        string: BassString | None,
        fret: int | None,
        motion: MotionKey,
        cost: float,
    ) -> PlannedNote:
        """``rec`` planned and fixed: to the outbox and this chain's history."""
        n = rec.note
        p = PlannedNote.of(
            n.time_s,
            rec.performer,
            n.channel,
            rec.played,
            n.velocity,
            limb,
            piece,
            string,
            fret,
            motion,
            rec.start,
            rec.impact,
            cost,
            rec.late,
        )
        self.ctx.ledger.outbox.append(p)
        self.fixed.append((n.time_s, p))
        return p

    def drop(self, rec: Held, reason: DropReason) -> None:
        self.ctx.ledger.drop(rec, reason)

    def fixed_at(self, t: float) -> list[PlannedNote]:
        """The fixed notes of this chain sounding with a note at ``t``."""
        return [p for ft, p in self.fixed if abs(ft - t) <= GROUP_EPS_S]

    def share(self, rec: Held, twin: PlannedNote) -> None:
        """``rec`` played by the fixed motion ``twin`` (same time, same pitch or piece)."""
        rec.start, rec.impact, rec.late = twin.start, twin.impact, twin.late
        self.emit(
            rec,
            limb=twin.limb,
            piece=twin.piece,
            string=twin.string,
            fret=twin.fret,
            motion=twin.motion,
            cost=0.0,
        )
