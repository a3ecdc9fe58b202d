"""A foot's chain of the online planner: the kick (right foot) or the hi-hat pedal
(left foot).

Its state is the time of its last stroke.  A group is one stroke (notes within
HAND_WINDOW_S of its first; the later ones are the beater's or the cymbals'
bounce); a stroke sooner than the foot can strike again (``min_interval_s``) is
the second note of a double from one press, played by the stroke's rebound.
The left foot also takes the hi-hat notes the hands give it
(:meth:`FootChain.chick`).  Shared rules: :mod:`virja.plan.chain`,
:mod:`virja.plan.chain_kit`.
"""

from __future__ import annotations

import math
from itertools import repeat
from operator import itemgetter, sub

from virja.plan import drums as drums_mod
from virja.plan.chain import GROUP_EPS_S, ChainContext
from virja.plan.chain_kit import HAND_WINDOW_S, REBOUND_VELOCITY, DrumChain, DrumHeld, drum_stroke
from virja.plan.config import DrumNote
from virja.plan.timing import align
from virja.vocab import Limb

_TIME = itemgetter(0)  # of a fixed stroke: (time, planned note)


class FootChain(DrumChain):
    """One foot (see the module docstring)."""

    def __init__(self, ctx: ChainContext, limb: Limb) -> None:
        super().__init__(ctx)
        self.limb = limb
        self.state: float | None = None  # the time of its last stroke

    def kind(self, drum: DrumNote) -> str:
        return "kick" if drum.piece == "kick" else "hihat_pedal"

    def fix_groups(self, groups: list[list[DrumHeld]], n_groups: int) -> None:
        """One stroke per group (notes within the window of its first); the group's
        later notes are the beater's or the cymbals' bounce (a double trigger).  A
        very soft note (REBOUND_VELOCITY) that a stroke follows sooner than the limb
        could strike twice is the beater touching the head before that stroke."""
        for gi, group in enumerate(groups[:n_groups]):
            first = group[0]
            piece = first.drum.piece
            t = first.note.time_s
            min_int = self.ctx.config.timing.get(first.kind).min_interval_s
            if (
                gi + 1 < len(groups)
                and all(r.note.velocity < REBOUND_VELOCITY for r in group)
                and groups[gi + 1][0].note.time_s - t < min_int - drums_mod.TIME_EPS_S
            ):
                for r in group:
                    self.emit_bounce(r, piece, self.limb)
                continue
            if self.state is not None and t - self.state < min_int - drums_mod.TIME_EPS_S:
                # sooner than the foot strikes twice (but at least the grouping window
                # after its stroke): the second note of a double from one press (the
                # kick's slide or heel-toe, a beater's double bounce; GMD kick pairs
                # 32-49 ms apart, hi-hat chicks 35 ms): played by that stroke's rebound
                for r in group:
                    self.emit_bounce(r, piece, self.limb)
                self.ctx.ledger.counts["foot_double"] += 1
                continue
            self.state = t
            now = [r for r in group if r.note.time_s - t <= GROUP_EPS_S]
            self.emit_stroke(now, piece, self.limb, 0.0)
            for r in group[len(now) :]:
                self.emit_bounce(r, piece, self.limb)

    def place_stroke(self, rec: DrumHeld, min_interval_s: float) -> None:
        if self.limb_free(self.limb, rec.note.time_s, min_interval_s):
            self.emit_stroke([rec], rec.drum.piece, self.limb, 0.0)
        else:
            self.drop(rec, "no_free_limb")

    # the hi-hat notes the hands give this foot -------------------------------------

    def _nearest(self, t: float) -> float:
        """How far from ``t`` the nearest of this foot's strokes fixed, pending and last
        is (inf: none).  Asked for every hi-hat stroke the hands plan: one pass."""
        d = min(map(abs, map(sub, map(_TIME, self.fixed), repeat(t))), default=math.inf)
        if self.pending:
            d = min(d, min(abs(r.note.time_s - t) for r in self.pending))
        if self.state is not None:
            d = min(d, abs(self.state - t))
        return d

    def last_before(self, t: float) -> float | None:
        """The time of this foot's latest note before ``t``, fixed or pending (None:
        none)."""
        times = [ft for ft, _p in self.fixed if ft < t]
        times += [r.note.time_s for r in self.pending if r.note.time_s < t]
        return max(times, default=None)

    def can_chick(self, t: float) -> bool:
        """The foot plays the hi-hat at ``t`` already (a stroke within HAND_WINDOW_S),
        or can (none within its ``min_interval_s``)."""
        d = self._nearest(t)
        min_int = self.ctx.config.timing.get("hihat_pedal").min_interval_s
        return d <= HAND_WINDOW_S or not d < min_int - drums_mod.TIME_EPS_S

    def chick(self, rec: DrumHeld) -> bool:
        """A hi-hat note both hands are too busy for, played by this foot (a chick on
        the pedal) if the foot is free then or already plays the hi-hat then."""
        if rec.drum.piece != "hihat":
            return False
        t = rec.note.time_s
        timing = self.ctx.config.timing
        min_int = timing.get("hihat_pedal").min_interval_s
        d = self._nearest(t)
        if d <= HAND_WINDOW_S:
            shared = True  # the foot plays the hi-hat then: the note rides on that chick
        elif d < min_int - drums_mod.TIME_EPS_S:
            return False
        else:
            shared = False
        a = align(timing, "hihat_pedal", t, rec.known_s, self.ctx.seconds_per_beat_at(t))
        rec.start, rec.impact, rec.late = a.start, a.impact, a.late
        self.emit(
            rec,
            limb=self.limb,
            piece="hihat",
            string=None,
            fret=None,
            motion=drum_stroke("hihat", self.limb),
            cost=0.0,
        )
        if not shared and (self.state is None or t > self.state):
            self.state = t
        self.ctx.ledger.counts["foot_chick"] += 1
        return True
