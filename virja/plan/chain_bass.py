"""The bass's chain of the online planner: the left hand over strings and frets.

Its state is the fretting hand (:data:`virja.plan.bass.BassState`); a group is the
notes within GROUP_EPS_S (a double stop); the pending groups are solved by
:func:`virja.plan.bass.solve` over at most ``bounds.window_groups`` groups, and
that plan is kept until a note arrives (fixing in several steps equals fixing in
one).  Shared rules: :mod:`virja.plan.chain`.
"""

from __future__ import annotations

import math

from virja.events import NoteOn
from virja.plan import bass as bass_mod
from virja.plan.chain import Chain, ChainContext, Held, WindowedPlan

# one solved group: the option chosen, the cost it paid, the hand after it
BassStep = tuple[int, float, bass_mod.BassState]
CHORDS_KEPT = 4096  # chords' options kept per chain (the pitches met)


class BassChain(Chain[Held]):
    """The bass's left hand (see the module docstring)."""

    def __init__(self, ctx: ChainContext) -> None:
        super().__init__(ctx)
        self.state: bass_mod.BassState = None
        self.plan: WindowedPlan[BassStep] = WindowedPlan(ctx.bounds.window_groups)
        self._setup = ctx.config.bass
        # bass.chord_options by the chord's pitches, for this chain's setup (which never
        # changes): looked up without hashing the setup again for every group
        self._chords: dict[tuple[int, ...], tuple[int, tuple[bass_mod.BassOption, ...]]] = {}
        self._lowest, self._highest = self._setup.lowest, self._setup.highest
        self._string_names = tuple(name for name, _open in self._setup.strings)

    def held(self, seq: int, note: NoteOn, known_s: float) -> Held:
        """``note`` as this chain holds it: folded into the bass's range (reported
        as moved when it had to be)."""
        played = note.note
        if not self._lowest <= played <= self._highest:
            played = bass_mod.fold_into_range(self._setup, played)
            if played != note.note:
                self.ctx.ledger.move("bass", note, played)
        return Held(seq, "bass", note, known_s, "pluck", played)

    def forget_plan(self) -> None:
        self.plan.forget()

    def _group(self, group: list[Held]) -> tuple[list[int], tuple[bass_mod.BassOption, ...]]:
        pitches: tuple[int, ...]
        if len(group) == 1:
            pitches = (group[0].played,)
        else:
            pitches = tuple(sorted({r.played for r in group}, reverse=True))
        found = self._chords.get(pitches)
        if found is None:
            if len(self._chords) >= CHORDS_KEPT:
                self._chords.clear()
            found = self._chords[pitches] = bass_mod.chord_options(self._setup, pitches)
        kept, options = found
        return list(pitches[:kept]), options

    def fix_groups(self, groups: list[list[Held]], n_groups: int) -> None:
        prepared: dict[int, tuple[list[int], tuple[bass_mod.BassOption, ...]]] = {}

        def prepare(gi: int) -> tuple[list[int], tuple[bass_mod.BassOption, ...]]:
            """:meth:`_group` of ``groups[gi]``, made once per call."""
            found = prepared.get(gi)
            if found is None:
                found = prepared[gi] = self._group(groups[gi])
            return found

        def solve(win: list[list[Held]], gi: int) -> list[BassStep]:
            times = [g[0].note.time_s for g in win]
            last = groups[gi - 1][0].note.time_s if gi > 0 else self.last_fixed_t
            gaps = [times[0] - last if last is not None else math.inf]
            gaps += [b - a for a, b in zip(times, times[1:], strict=False)]
            sol = bass_mod.solve(
                self.state,
                [prepare(gi + i)[1] for i in range(len(win))],
                self.ctx.config.bass.fingering,
                gaps,
            )
            return list(zip(sol.choice, sol.costs, sol.states, strict=True))

        for gi in range(n_groups):
            kept, opts = prepare(gi)
            choice, cost, state = self.plan.step(groups, gi, solve)
            self._emit_group(groups[gi], kept, opts[choice], cost, state)
            self.state = state

    def _emit_group(
        self,
        group: list[Held],
        kept: list[int],
        option: bass_mod.BassOption,
        cost: float,
        hand: bass_mod.BassState,
    ) -> None:
        """The notes of ``group`` on ``option``'s positions (the group's cost paid by
        its first note); a note the option does not keep cannot be stopped with it."""
        where = dict(zip(kept, option, strict=True))
        paid = False
        for rec in group:
            if rec.played not in where:
                self.drop(rec, "no_double_stop")
                continue
            s, f = where[rec.played]
            pluck = bass_mod.motion_key(self._string_names[s], f, hand)
            self.emit(
                rec,
                limb="right_hand",
                piece=None,
                string=pluck.string,
                fret=f,
                motion=pluck,
                cost=0.0 if paid else cost,
            )
            paid = True

    def place_out_of_order(self, rec: Held) -> None:
        """The same pitch fixed at its time: shared; another pitch fixed then: a double
        stop too late to plan, dropped; none: the cheapest position from the hand."""
        same = self.fixed_at(rec.note.time_s)
        twin = next((p for p in same if p.note == rec.played), None)
        if twin is not None:
            self.share(rec, twin)
        elif same:
            self.drop(rec, "no_double_stop")
        else:
            opts = [(p,) for p in bass_mod.positions(self.ctx.config.bass, rec.played)]
            fingering = self.ctx.config.bass.fingering
            best = min(opts, key=lambda o: bass_mod.transition(self.state, o, fingering)[0])
            cost, after = bass_mod.transition(self.state, best, fingering)
            self._emit_group([rec], [rec.played], best, cost, after)
