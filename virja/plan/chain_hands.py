"""The drummer's hands: the chain of the online planner that chooses a hand per stroke.

Its state is :data:`virja.plan.drums.HandState` (what each hand struck last, and
when).  Notes within HAND_WINDOW_S of a group's first are one decision: notes of
one piece within SAME_STROKE_S are one stroke; the two most important strokes
go to the solver (:func:`virja.plan.drums.solve`, over at most
``bounds.window_groups`` groups, the plan kept until a note arrives), a further
stroke on a planned piece bounces off it, a third piece is more than two hands
can strike.  Before that, soft notes close after a stroke on their piece are set
aside as its rebounds (a buzz, a press roll), and a crowded hi-hat goes to the
left foot (:meth:`virja.plan.chain_feet.FootChain.chick`).  Shared rules:
:mod:`virja.plan.chain`, :mod:`virja.plan.chain_kit`.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from virja.plan import drums as drums_mod
from virja.plan.chain import GROUP_EPS_S, ChainContext, Held, WindowedPlan
from virja.plan.chain_feet import FootChain
from virja.plan.chain_kit import HAND_WINDOW_S, REBOUND_VELOCITY, DrumChain, DrumHeld, drum_stroke
from virja.plan.config import DrumNote, Timing
from virja.plan.types import DropReason, PlannedNote
from virja.vocab import Hand

# Notes of one piece this close are one stroke heard twice (head and rim, a pad's
# double trigger): the later ones ride on the first stroke, each at its own time.
SAME_STROKE_S = 0.010
# A soft hand note (a ghost note) this soon after another note on the same piece is
# part of a buzz or press roll: the same hand presses, the stick bounces.
BUZZ_VELOCITY = 48  # ghost notes and soft drag notes (below mezzo-piano)
BUZZ_S = 0.050
BUZZ_PIECES = frozenset({"snare", "tom_high", "tom_low", "tom_floor", "hihat", "ride"})

# A note this soft is a touch: round 9 found GMD's notes that no hand could reach
# without passing 7 m/s of tip (beyond_hand_speed) to be mostly of velocity 5-27 with a
# loud note on another pad; a hi-hat of velocity 7 kept its hand from a high tom of 58
# (the tom dropped) when the two weighed alike
TOUCH_VELOCITY = 20

# where a hand that has struck nothing yet waits: its ready pose, the stick over the snare
REST_PIECE = "snare"
_MARGIN_S = 1e-6  # the rebound rules look at notes this much further back, then test exactly

# one solved group: the hand per stroke (None: dropped), their costs, the state after
HandStep = tuple[drums_mod.Assignment, tuple[float, ...], drums_mod.HandState]
# a note a hand plays beyond the solver's strokes: (hand, piece, time, a stroke of its
# own rather than a bounce of the hand's last stroke)
Struck = tuple[str, str, float, bool]


def velocity_priority(priority: int, velocity: int) -> int:
    """A note's priority weighed by its velocity (lower = more important): a touch
    (velocity < 20, no louder than an electronic pad's cross-talk) gives way first,
    whatever its piece, a ghost note (< 40) next, a soft one (< 64) next, an accent
    (>= 100) is kept before a plain stroke of its piece."""
    if velocity < TOUCH_VELOCITY:
        return priority + 6
    if velocity < 40:
        return priority + 3
    if velocity < 64:
        return priority + 1
    if velocity >= 100:
        return max(0, priority - 1)
    return priority


@dataclass(frozen=True, slots=True)
class HandGroupPlan:
    """A hand group prepared for the solver: its (at most two) strokes, the notes of
    each, bounces (index of the stroke they ride on, notes) and notes beyond two hands."""

    group: drums_mod.HandGroup
    kept: list[list[DrumHeld]]
    bounces: list[tuple[int, list[DrumHeld]]]
    extra: list[DrumHeld]


def hand_group(
    group: list[DrumHeld],
    t0: float,
    chick: Callable[[float], bool] | None = None,
    pin: Callable[[DrumHeld], tuple[Hand | None, float]] | None = None,
) -> HandGroupPlan:
    """The strokes of a group: notes of one piece within SAME_STROKE_S are one stroke.

    The most important stroke (velocity-weighed priority, then the earlier) and the
    most important one on another piece (on the same piece when there is no other:
    a flam) are planned; a further stroke on a piece already planned is a bounce of the
    nearest planned stroke there (a buzz or a drag's second note, same hand); a
    third distinct piece within the window is more than two hands can strike.
    ``chick(t)``: whether the left foot can take a hi-hat stroke at ``t``
    (``Stroke.foot``: when both hands are busy, a closed hi-hat note is a chick).
    ``pin(r)``: the hand drawn moving for note ``r`` and what giving it to the other
    costs (``Stroke.pin``, ``Stroke.switch``; live only, :meth:`HandsChain.pin`).
    """
    if not group:
        return HandGroupPlan(drums_mod.HandGroup(t0, ()), [], [], [])
    if len(group) == 1:  # one note: one stroke (what the loops below make of it)
        r = group[0]
        stroke = drums_mod.Stroke(
            r.drum.piece,
            velocity_priority(r.drum.priority, r.note.velocity),
            r.note.time_s - t0,
            chick is not None and r.drum.piece == "hihat" and chick(r.note.time_s),
            *_pinned(pin, [r]),
        )
        return HandGroupPlan(drums_mod.HandGroup(t0, (stroke,)), [[r]], [], [])
    if len(group) == 2 and group[0].drum.piece != group[1].drum.piece:
        # two pieces: two strokes, the more important first (what the loops below make)
        a, b = group
        rank_a = (velocity_priority(a.drum.priority, a.note.velocity), a.note.time_s, a.seq)
        rank_b = (velocity_priority(b.drum.priority, b.note.velocity), b.note.time_s, b.seq)
        pair = ((rank_a, a), (rank_b, b)) if rank_a < rank_b else ((rank_b, b), (rank_a, a))
        return HandGroupPlan(
            drums_mod.HandGroup(
                t0,
                tuple(
                    drums_mod.Stroke(
                        r.drum.piece,
                        rank[0],
                        r.note.time_s - t0,
                        chick is not None and r.drum.piece == "hihat" and chick(r.note.time_s),
                        *_pinned(pin, [r]),
                    )
                    for rank, r in pair
                ),
            ),
            [[pair[0][1]], [pair[1][1]]],
            [],
            [],
        )
    clusters: list[list[DrumHeld]] = []
    for r in sorted(group, key=lambda r: (r.note.time_s, r.seq)):
        piece, t = r.drum.piece, r.note.time_s
        for c in clusters:  # the first cluster of its piece begun within SAME_STROKE_S
            if c[0].drum.piece == piece and t - c[0].note.time_s <= SAME_STROKE_S:
                c.append(r)
                break
        else:
            clusters.append([r])

    ranks = [
        (
            min(velocity_priority(r.drum.priority, r.note.velocity) for r in c),
            c[0].note.time_s,
            c[0].seq,
        )
        for c in clusters
    ]
    prio = {c[0].seq: rk[0] for c, rk in zip(clusters, ranks, strict=True)}
    ranked = [c for _rk, c in sorted(zip(ranks, clusters, strict=True), key=lambda x: x[0])]
    # the hands go to two pieces where there are two (a further stroke on one of them
    # is that hand's double), to a flam or drag on one piece where there is one
    other = next((c for c in ranked[1:] if c[0].drum.piece != ranked[0][0].drum.piece), None)
    kept = ranked[:2] if other is None else [ranked[0], other]
    bounces: list[tuple[int, list[DrumHeld]]] = []
    extra: list[DrumHeld] = []
    for c in ranked:
        if c is kept[0] or (len(kept) == 2 and c is kept[1]):
            continue
        piece = c[0].drum.piece
        near = [
            (abs(k[0].note.time_s - c[0].note.time_s), i)
            for i, k in enumerate(kept)
            if k[0].drum.piece == piece
        ]
        if near:
            bounces.append((min(near)[1], c))
        else:
            extra.extend(c)
    strokes = tuple(
        drums_mod.Stroke(
            c[0].drum.piece,
            prio[c[0].seq],
            c[0].note.time_s - t0,
            chick is not None and c[0].drum.piece == "hihat" and chick(c[0].note.time_s),
            *_pinned(pin, c),
        )
        for c in kept
    )
    return HandGroupPlan(drums_mod.HandGroup(t0, strokes), kept, bounces, extra)


def _pinned(
    pin: Callable[[DrumHeld], tuple[Hand | None, float]] | None, recs: list[DrumHeld]
) -> tuple[Hand | None, float]:
    """A stroke's ``Stroke.pin`` and ``Stroke.switch``: those of its first note with a
    pin (none without ``pin``)."""
    if pin is not None:
        for r in recs:
            if r.pin is not None:
                return pin(r)
    return None, 0.0


class HandsChain(DrumChain):
    """The drummer's two hands (see the module docstring); ``foot`` is the left
    foot's chain, which takes the hi-hat notes the hands cannot."""

    def __init__(self, ctx: ChainContext, foot: FootChain) -> None:
        super().__init__(ctx)
        self.foot = foot
        self.state: drums_mod.HandState = drums_mod.START
        self.plan: WindowedPlan[HandStep] = WindowedPlan(ctx.bounds.window_groups)
        # while a group is fixed: the notes its hands play beyond the solver's strokes
        # (:data:`Struck`), which :func:`_struck` adds to the hands' state
        self._bounced: list[Struck] | None = None
        self.pin_now = -math.inf  # live: when the pins were last told (:meth:`pin`)
        # the groups and state :meth:`provisional` last solved, and its steps
        self._shown: (
            tuple[tuple[tuple[drums_mod.HandGroup, ...], drums_mod.HandState], list[HandStep]]
            | None
        ) = None

    def kind(self, drum: DrumNote) -> str:
        return drum.piece

    def forget_plan(self) -> None:
        self.plan.forget()

    def pin(self, pins: dict[tuple[int, int, float], Hand], now_s: float) -> int:
        """Live: the hand drawn moving for each pending note at ``now_s`` (by channel,
        note and time rounded to 1e-9 s; plan.types.HandPin), the whole current set: a
        note not in it has no pin.  The plan then gives a pinned note the other hand
        only at :meth:`switch_cost` more.  Returns how many pending notes have one."""
        self.pin_now = now_s
        n = 0
        for r in self.pending:
            hand = (
                pins.get((r.note.channel, r.note.note, round(r.note.time_s, 9))) if pins else None
            )
            if hand != r.pin:
                r.pin = hand
                self.forget_plan()
            n += hand is not None
        if n:  # the price of a switch grows as the time left shrinks
            self.forget_plan()
        return n

    def switch_cost(self, rec: DrumHeld) -> tuple[Hand | None, float]:
        """The pin of ``rec`` and what giving it to the other hand costs beyond the
        table: ``shown_hand_penalty`` (drum_costs.toml), and what the speed that hand
        needs costs (timing.toml [hand_speed], drums.stroke_penalty) when it leaves for
        the note only now (:attr:`pin_now`), from the piece it struck last, over what the
        plan charges it from that stroke.  A switch with time to spare costs little; one
        at the motion's start (rest -> crash in 67 ms) the fastest tier."""
        hand = rec.pin
        if hand is None:
            return None, 0.0
        timing = self.ctx.config.timing
        other = drums_mod.LEFT if hand == drums_mod.RIGHT else drums_mod.RIGHT
        _prev, _pt, t_right, t_left, p_right, p_left = self.state
        last, piece = (t_left, p_left) if other == drums_mod.LEFT else (t_right, p_right)
        t, target = rec.note.time_s, rec.drum.piece
        # what the plan charges that hand from its last stroke in the state (none: free)
        charged = drums_mod.stroke_penalty(
            timing, piece, target, math.inf if last is None else t - last
        )
        # where it is: over the piece it played last (its ready pose over the snare
        # when it has played none), leaving now, or when that stroke lands
        played = next((p for _ft, p in reversed(self.fixed) if p.limb == other), None)
        where = played.piece if played is not None and played.piece else REST_PIECE
        leaves = self.pin_now if played is None else max(self.pin_now, played.impact)
        rushed = drums_mod.stroke_penalty(timing, where, target, t - leaves)
        return hand, self.ctx.config.costs.shown_hand_penalty + max(0.0, rushed - charged)

    def _rebounds(self, groups: list[list[DrumHeld]], decide: bool = True) -> set[int]:
        """The pending hand notes that are rebounds (REBOUND_VELOCITY) of an earlier
        note on the same piece, fixed or pending, within its ``min_interval_s`` (a
        buzz: soft rebounds of one pressed stroke), and, at any velocity, those
        within SAME_STROKE_S of an earlier note on the piece in an earlier group (one
        stroke heard twice, split by the grouping window; in one group the same rule
        makes them one stroke).  ``decide``: each note's decision is kept (taken once);
        otherwise an undecided note is only looked at (:meth:`provisional`)."""
        need = {r.drum.piece for r in self.pending if r.rebound is None}
        if not need:  # every note decided already
            return {r.seq for r in self.pending if r.rebound}
        strokes: dict[str, list[float]] = {}
        group_of = {r.seq: gi for gi, g in enumerate(groups) for r in g}
        earlier: dict[str, list[tuple[float, int]]] = {}  # piece: (time, group), -1 fixed
        for ft, p in self.fixed:
            if p.piece in need:
                strokes.setdefault(p.piece, []).append(ft)
                earlier.setdefault(p.piece, []).append((ft, -1))
        for r in self.pending:
            if r.drum.piece in need:
                strokes.setdefault(r.drum.piece, []).append(r.note.time_s)
                earlier.setdefault(r.drum.piece, []).append(
                    (r.note.time_s, group_of.get(r.seq, -2))
                )
        for times in strokes.values():  # sorted: a note looks only at those just before it
            times.sort()
        for pairs in earlier.values():
            pairs.sort()
        out: set[int] = set()
        for r in self.pending:
            rebound = r.rebound
            if rebound is None:
                rebound = self._is_rebound(r, group_of.get(r.seq, -2), strokes, earlier)
                if decide:
                    r.rebound = rebound
            if rebound:
                out.add(r.seq)
        return out

    def _is_rebound(
        self,
        r: DrumHeld,
        gi: int,
        strokes: dict[str, list[float]],
        earlier: dict[str, list[tuple[float, int]]],
    ) -> bool:
        """The rule of :meth:`_rebounds` for one undecided note of group ``gi``."""
        t = r.note.time_s
        # one stroke heard twice; on a cymbal a double within the grouping window is one
        # hand's (timing.toml [hand_stretch] one_hand_doubles), split by the window or not
        # (GMD rock 102 at 5.64 s: two ride notes 19 ms apart in two groups went to both
        # hands, the left crossing to the ride onto the right stick).  Not the hi-hat's:
        # a note there close after another may be the left foot's (_emit_rebound)
        same = SAME_STROKE_S
        if r.drum.piece in self.ctx.config.timing.one_hand_doubles and r.drum.piece != "hihat":
            same = HAND_WINDOW_S
        # the notes within a window a little wider than the rule's, then the rule itself
        pairs = earlier.get(r.drum.piece, [])
        lo = bisect.bisect_left(pairs, (t - same - GROUP_EPS_S - _MARGIN_S,))
        near = pairs[lo : bisect.bisect_left(pairs, (t,), lo)]
        if any(0 < t - s <= same + GROUP_EPS_S and g != gi for s, g in near):
            return True
        if r.note.velocity >= BUZZ_VELOCITY:
            return False
        if r.drum.piece not in BUZZ_PIECES:  # a crash swings away: no rebound
            return False
        reach = self.ctx.config.timing.get(r.drum.piece).min_interval_s
        if r.note.velocity >= REBOUND_VELOCITY:
            reach = max(reach, BUZZ_S)
        times = strokes.get(r.drum.piece, [])
        lo = bisect.bisect_left(times, t - reach - GROUP_EPS_S - _MARGIN_S)
        return any(
            0 < t - s <= reach + GROUP_EPS_S for s in times[lo : bisect.bisect_left(times, t, lo)]
        )

    def _decide_foot(
        self, group: list[DrumHeld], rebounds: set[int], decide: bool = True
    ) -> set[int]:
        """Three or more hand pieces at once, one the hi-hat: the left foot takes the
        hi-hat (a chick) if it is free, and the hands keep the rest.  Returns the
        group's notes given to the foot; ``decide`` as in :meth:`_rebounds`."""
        undecided = [r for r in group if r.to_foot is None]
        out = {r.seq for r in group if r.to_foot}
        if not undecided:
            return out
        pieces = {r.drum.piece for r in group if r.seq not in rebounds}
        crowded = len(pieces) >= 3 and "hihat" in pieces
        for r in undecided:
            to_foot = (
                crowded
                and r.seq not in rebounds
                and r.drum.piece == "hihat"
                and self.foot.can_chick(r.note.time_s)
            )
            if decide:
                r.to_foot = to_foot
            if to_foot:
                out.add(r.seq)
        return out

    def fix_groups(self, groups: list[list[DrumHeld]], n_groups: int) -> None:
        rebounds = self._rebounds(groups)
        for g in groups:
            self._decide_foot(g, rebounds)
        aside = rebounds | {r.seq for r in self.pending if r.to_foot}

        prepared: dict[int, HandGroupPlan] = {}  # by the group's first note, made once

        def prepare(g: list[DrumHeld]) -> HandGroupPlan:
            hp = prepared.get(g[0].seq)
            if hp is None:
                hp = prepared[g[0].seq] = hand_group(
                    [r for r in g if r.seq not in aside],
                    g[0].note.time_s,
                    self.foot.can_chick,
                    self.switch_cost,
                )
            return hp

        def solve(win: list[list[DrumHeld]], _gi: int) -> list[HandStep]:
            return self._steps([prepare(g).group for g in win])

        for gi in range(n_groups):
            hp = prepare(groups[gi])
            assignment, stroke_costs, state = self.plan.step(groups, gi, solve)
            self._bounced = []
            self._fix_group(groups[gi], hp, assignment, stroke_costs, rebounds, state)
            struck = _struck(state, self._bounced)
            self._bounced = None
            if struck != state:  # the plan held for later groups knew only the strokes
                self.forget_plan()
            self.state = struck

    def provisional(self) -> list[PlannedNote]:
        """The hand each pending note would get if nothing more arrived, as planned notes
        not yet fixed (``cost`` 0): the plan the chain holds for the pending groups
        (what the next commit fixes), else the least-cost plan of them, as the commit
        solves it (:meth:`_solved`).  Changes nothing: no note's decision is taken,
        nothing is fixed or emitted.  Rebounds of earlier strokes and hi-hat notes
        for the left foot are left out (their limb is not the solver's choice)."""
        if not self.pending:
            return []
        groups = self.groups()
        rebounds = self._rebounds(groups, decide=False)
        aside = set(rebounds)
        for g in groups:
            aside |= self._decide_foot(g, rebounds, decide=False)
        held = self.plan.held()
        n = min(len(groups), len(held) if held else self.ctx.bounds.window_groups)
        hps = [
            hand_group(
                [r for r in g if r.seq not in aside],
                g[0].note.time_s,
                self.foot.can_chick,
                self.switch_cost,
            )
            for g in groups[:n]
        ]
        steps = held if held else self._solved([hp.group for hp in hps])
        out: list[PlannedNote] = []
        for hp, (assignment, _costs, _state) in zip(hps, steps, strict=False):
            if len(assignment) != len(hp.group.strokes):
                continue
            for si, stroke in enumerate(hp.group.strokes):
                hand = assignment[si]
                other = 1 - si
                if (
                    hand is None
                    and len(assignment) == 2
                    and hp.group.strokes[other].piece == (stroke.piece)
                ):
                    hand = assignment[other]  # a rebound of the other stroke
                if hand is None:
                    continue
                recs = hp.kept[si]
                now = [r for r in recs if r.note.time_s - recs[0].note.time_s <= GROUP_EPS_S]
                rest = recs[len(now) :] + [r for k, c in hp.bounces if k == si for r in c]
                out.extend(_unfixed(r, stroke.piece, hand, now[0]) for r in now)
                out.extend(_unfixed(r, stroke.piece, hand, r) for r in rest)
        return out

    def _solved(self, groups: list[drums_mod.HandGroup]) -> list[HandStep]:
        """Steps for ``groups`` (the pending ones, at most a window, from the chain's
        state): the least-cost plan of them all, as the commit solves it, the last one
        kept while the groups and state are the same.  Before round 8 the latest solve's
        steps were continued by a solve of the groups a new note made; that plan could
        differ from the commit's (a ride shown to the left hand after a hi-hat stroke
        shown right, where the commit gives the hi-hat to the foot and the ride to the
        right), and live a hand shown moving now keeps its note (:meth:`pin`), so what is
        shown is the commit's plan.  Changes nothing the commit uses."""
        key = (tuple(groups), self.state)
        if self._shown is not None and self._shown[0] == key:
            return self._shown[1]
        steps = self._steps(groups)
        self._shown = (key, steps)
        return steps

    def _steps(self, groups: list[drums_mod.HandGroup]) -> list[HandStep]:
        """The least-cost steps of ``groups`` from the chain's state (drums.solve)."""
        sol = drums_mod.solve(
            self.ctx.config.costs,
            self.ctx.config.timing,
            self.state,
            groups,
            beam=self.ctx.bounds.beam,
        )
        return list(zip(sol.assignments, sol.stroke_costs, sol.states, strict=True))

    def _fix_group(
        self,
        group: list[DrumHeld],
        hp: HandGroupPlan,
        assignment: drums_mod.Assignment,
        stroke_costs: tuple[float, ...],
        rebounds: set[int],
        after: drums_mod.HandState,
    ) -> None:
        """Emit one group's notes by the solver's ``assignment`` of its strokes
        (``after``: the hands' state the solver gives after them)."""
        third: set[str] = set()  # the pieces dropped as a third hand piece
        for r in hp.extra:  # a third hand piece within the window
            if not self.foot.chick(r):
                self.drop(r, "three_pieces_at_once")
                third.add(r.drum.piece)
        late_rebounds = [r for r in group if r.seq in rebounds] if rebounds else []
        for r in group:
            if r.to_foot and not self.foot.chick(r):
                self.drop(r, "three_pieces_at_once")
        for si, stroke in enumerate(hp.group.strokes):
            recs = hp.kept[si]
            hand = assignment[si]
            bounces = [r for k, c in hp.bounces if k == si for r in c] if hp.bounces else []
            other = 1 - si
            if (
                hand is None
                and len(hp.group.strokes) == 2
                and hp.group.strokes[other].piece == stroke.piece
                and assignment[other] is not None
            ):
                # no second hand for it, but the first is on the same piece: a
                # rebound of that stroke (a drag, a buzz, a pad's double trigger)
                hand = assignment[other]
                assert hand is not None
                for r in recs + bounces:
                    self.emit_bounce(r, stroke.piece, hand)
                continue
            if hand is None:
                why = self._unplayed_why(stroke.piece, hp.group.time + stroke.dt)
                for r in recs + bounces:
                    if not self.foot.chick(r):
                        self.drop(r, why)
                continue
            if len(recs) == 1:  # most strokes: one note, nothing riding on it
                self.emit_stroke(recs, stroke.piece, hand, stroke_costs[si])
                for r in bounces:
                    self.emit_bounce(r, stroke.piece, hand)
                continue
            now = [r for r in recs if r.note.time_s - recs[0].note.time_s <= GROUP_EPS_S]
            self.emit_stroke(now, stroke.piece, hand, stroke_costs[si])
            for r in recs[len(now) :] + bounces:
                self.emit_bounce(r, stroke.piece, hand)
        for r in late_rebounds:
            if r.drum.piece in third:  # a bounce of the third piece's stroke, not played
                self.drop(r, "three_pieces_at_once")
            else:
                self._emit_rebound(r, after)

    def _unplayed_why(self, piece: str, t: float) -> DropReason:
        """Why the solver gave a stroke on ``piece`` at ``t`` no hand (while its group is
        fixed, from the hands' state before the group): ``beyond_hand_speed`` when a hand
        could strike it in time (:meth:`Timing.stretch_gap` from that hand's last
        stroke), so what kept it off is the speed of a move, its own or one it forces
        (timing.toml [hand_speed]'s top tier, past a drummer's hands); ``too_fast`` when
        no hand could strike again so soon."""
        timing = self.ctx.config.timing
        _prev, _pt, t_right, t_left, p_right, p_left = self.state
        for last, on in ((t_right, p_right), (t_left, p_left)):
            if _reach(timing, last, on, piece, t)[0]:
                return "beyond_hand_speed"
        return "too_fast"

    def emit_bounce(self, rec: Held, piece: str, limb: str) -> None:
        super().emit_bounce(rec, piece, limb)
        if self._bounced is not None:  # the hand strikes then too (fix_groups, _struck)
            self._bounced.append((limb, piece, rec.note.time_s, False))

    def _emit_rebound(self, rec: DrumHeld, after: drums_mod.HandState) -> None:
        """``rec`` rides on the latest stroke before it on its piece (see
        :meth:`_rebounds`): a hand's, while that hand is still there (``after``: the
        hands' state after the group), or on the hi-hat the left foot's (a chick or a
        pedal note: the pad reports the pedal's clamp, or the cymbals' splash, as a
        soft stroke; GMD rock 102 and 110 have open hi-hat notes of velocity 7-27
        within 25 ms of a pedal note), or the left foot's chick when the hand that
        struck has gone on to another piece.  Before round 9 the latest hand stroke on
        the piece carried it whatever came between: a left hand that had left the
        hi-hat for a tom 40 ms before was drawn back to the hi-hat and 11 ms later on
        the tom again (GMD rock 102, 39 m/s).  When no limb is there (what it rode on
        was dropped, or the hand has left and the foot cannot) it is a stroke of its
        own (:meth:`place_stroke`; once in the GMD corpus)."""
        t = rec.note.time_s
        piece = rec.drum.piece
        by = next(
            ((ft, p) for ft, p in reversed(self.fixed) if p.piece == piece and ft < t),
            None,
        )
        if piece == "hihat":
            foot_t = self.foot.last_before(t)
            if foot_t is not None and (by is None or foot_t >= by[0]) and self.foot.chick(rec):
                return
        if by is not None and self._still_on(by[1].limb, piece, t, after):
            self.emit_bounce(rec, piece, by[1].limb)
        elif not self.foot.chick(rec):
            self._own_stroke(rec, after)

    def _own_stroke(self, rec: DrumHeld, after: drums_mod.HandState) -> None:
        """A rebound with nothing to ride on, as a stroke of its own: by a free hand that
        reaches it from its stroke before or after (``after``: the hands' state after
        the group) under the top speed of timing.toml [hand_speed] (:meth:`place_stroke`),
        else dropped as the solver drops a stroke: ``beyond_hand_speed`` when a hand
        reaches it at a stretch only past that speed, ``too_fast`` when none can (GMD
        bossa 127 at 285.8 s: a side stick 38 ms after the left hand's low tom, 0.46 m
        away, riding on a snare note dropped as a third piece)."""
        t, piece = rec.note.time_s, rec.drum.piece
        timing = self.ctx.config.timing
        _prev, _pt, t_right, t_left, p_right, p_left = after
        fit: list[Hand] = []
        reached = False
        for hand, last, on in (
            (drums_mod.RIGHT, t_right, p_right),
            (drums_mod.LEFT, t_left, p_left),
        ):
            in_time, in_speed = _reach(timing, last, on, piece, t)
            reached |= in_time
            if in_speed:
                fit.append(hand)
        if fit:
            self.place_stroke(rec, timing.get(piece).min_interval_s, fit)
        else:
            self.drop(rec, "beyond_hand_speed" if reached else "too_fast")

    def _still_on(self, limb: str, piece: str, t: float, after: drums_mod.HandState) -> bool:
        """Whether hand ``limb`` is on ``piece`` at ``t`` by ``after`` (the hands' state
        after the group being fixed): its last stroke there, or its stroke on another
        piece far enough after ``t`` to reach it from there."""
        _prev, _pt, t_right, t_left, p_right, p_left = after
        last, on = (t_right, p_right) if limb == drums_mod.RIGHT else (t_left, p_left)
        if on is None or on == piece or last is None:
            return True
        gap = self.ctx.config.timing.stretch_gap(piece, on)
        return last - t >= gap - drums_mod.TIME_EPS_S

    def place_stroke(
        self,
        rec: DrumHeld,
        min_interval_s: float,
        hands: Sequence[Hand] = (drums_mod.LEFT, drums_mod.RIGHT),
    ) -> None:
        """The free hand (of ``hands``) cheapest by the table from the fixed motion
        before ``rec`` (none after a rest), or dropped (``no_free_limb``).  While a group
        is fixed the hand's state then has it as its last stroke (:func:`_struck`)."""
        t = rec.note.time_s
        costs = self.ctx.config.costs
        before = [(ft, p) for ft, p in self.fixed if ft < t - GROUP_EPS_S]
        row = costs.none_row
        if before and t - before[-1][0] < self.ctx.config.timing.rest_s:
            row = costs.motions.index(before[-1][1].motion.name)
        choices = [
            (costs.table[row][costs.index(rec.drum.piece, h)], h)
            for h in hands
            if self.limb_free(h, t, min_interval_s)
        ]
        if not choices:
            self.drop(rec, "no_free_limb")
            return
        cost, hand = min(choices)
        self.emit_stroke([rec], rec.drum.piece, hand, cost)
        if self._bounced is not None:
            self._bounced.append((hand, rec.drum.piece, t, True))


def _reach(
    timing: Timing, last: float | None, on: str | None, piece: str, t: float
) -> tuple[bool, bool]:
    """Whether a hand whose stroke nearest ``t`` was on ``on`` at ``last`` (before or
    after ``t``; None: none) strikes ``piece`` at ``t`` in time, at a stretch
    (:meth:`Timing.stretch_gap`), and whether also under the top speed tier of
    timing.toml [hand_speed] (a drummer's hands)."""
    if last is None or on is None:
        return True, True
    a, b = (on, piece) if last <= t else (piece, on)
    since = abs(t - last)
    if since < timing.stretch_gap(a, b) - drums_mod.TIME_EPS_S:
        return False, False
    top = max((pen for _speed, pen in timing.speed_tiers), default=math.inf)
    return True, drums_mod.stroke_penalty(timing, a, b, since) < top


def _struck(state: drums_mod.HandState, bounced: list[Struck]) -> drums_mod.HandState:
    """``state`` with each hand's last stroke moved to the latest note it played beyond
    the solver's strokes: on a bounce (a rebound, a buzz, a drag's second note) on the
    piece it is on, the hand strikes there then and leaves for another piece only
    after that; a stroke of its own (``moved``) puts it on that piece then.  The solver
    sees a group's strokes, not the notes riding on them; before round 9 a right hand
    with ghost notes on the snare 48 ms after its stroke (GMD funk 92) was sent to the
    hi-hat 6 ms after the last of them (74 m/s of stick tip)."""
    if not bounced:
        return state
    prev, prev_t, t_right, t_left, p_right, p_left = state
    for limb, piece, t, moved in bounced:
        if limb == drums_mod.RIGHT:
            if (t_right is None or t > t_right) and (moved or piece == p_right):
                t_right, p_right = t, piece
        elif (
            limb == drums_mod.LEFT and (t_left is None or t > t_left) and (moved or piece == p_left)
        ):
            t_left, p_left = t, piece
    return (prev, prev_t, t_right, t_left, p_right, p_left)


def _unfixed(rec: DrumHeld, piece: str, hand: str, timed: DrumHeld) -> PlannedNote:
    """``rec`` as a planned note not yet fixed: struck by ``hand`` on ``piece`` with the
    start and impact of ``timed`` (the stroke's first note, or itself)."""
    n = rec.note
    stroke = drum_stroke(piece, hand)
    return PlannedNote.of(
        n.time_s,
        rec.performer,
        n.channel,
        rec.played,
        n.velocity,
        stroke.limb,
        stroke.piece,
        None,
        None,
        stroke,
        timed.start,
        timed.impact,
        0.0,
        timed.late,
    )
