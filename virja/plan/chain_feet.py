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

from virja.plan import drums as drums_mod
from virja.plan.chain import GROUP_EPS_S, ChainContext
from virja.plan.chain_kit import HAND_WINDOW_S, REBOUND_VELOCITY, DrumChain, DrumHeld
from virja.plan.config import DrumNote
from virja.plan.timing import align
from virja.vocab import DrumStroke, Limb


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

    def _near(self) -> list[float]:
        """The times of this foot's strokes fixed, pending and last."""
        near = [ft for ft, _p in self.fixed] + [r.note.time_s for r in self.pending]
        if self.state is not None:
            near.append(self.state)
        return near

    def can_chick(self, t: float) -> bool:
        """The foot plays the hi-hat at ``t`` already, or can."""
        near = self._near()
        min_int = self.ctx.config.timing.get("hihat_pedal").min_interval_s
        return any(abs(ft - t) <= HAND_WINDOW_S for ft in near) or not any(
            abs(ft - t) < min_int - drums_mod.TIME_EPS_S for ft in near
        )

    def chick(self, rec: DrumHeld) -> bool:
        """A hi-hat note both hands are too busy for, played by this foot (a chick on
        the pedal) if the foot is free then or already plays the hi-hat then."""
        if rec.drum.piece != "hihat":
            return False
        t = rec.note.time_s
        timing = self.ctx.config.timing
        min_int = timing.get("hihat_pedal").min_interval_s
        near = self._near()
        if any(abs(ft - t) <= HAND_WINDOW_S for ft in near):
            shared = True  # the foot plays the hi-hat then: the note rides on that chick
        elif any(abs(ft - t) < min_int - drums_mod.TIME_EPS_S for ft in near):
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
            motion=DrumStroke("hihat", self.limb),
            cost=0.0,
        )
        if not shared and (self.state is None or t > self.state):
            self.state = t
        self.ctx.ledger.counts["foot_chick"] += 1
        return True
