"""The drummer: which hand strikes each hand note, by least total table cost.

The hand motions of the whole performance form one sequence, ordered by time,
and two motions at the same instant ordered left hand first, then right.  Its
cost is ``table[none][m1] + sum table[m_(k-1)][m_k]``, where the row is
"none" for the first motion and for any motion at least ``rest_s`` after the
previous one (docs/scheduler.md).  Constraints: one hand strikes one piece at
a time; the two strokes of a group (notes within the grouping window) go to
different hands; a hand strikes again only after :meth:`Timing.gap` from its
last stroke: the piece's ``min_interval_s`` on the same piece (rebound doubles,
taps, buzz), longer the farther it has to travel to another piece; at a stretch
(:meth:`Timing.stretch_gap`: a pressed double, a snap of the wrist) sooner, for
``stretch_penalty`` a stroke, as is a flam by one hand or a hi-hat stroke left to
the foot (:func:`unplayed_penalty`).  A move to another piece also pays for the speed
it needs, by tiers (distance / time since the hand's last stroke, timing.toml
``[hand_speed]``, :func:`stroke_penalty`), so that the hand with time plays.  A stroke that no hand can make in time is
dropped at a penalty (``drop_penalty`` + 9 - priority), so dropping happens only
when nothing else is feasible.  Ties go to the right hand (the time-keeping hand
keeps the time).

Feet are unambiguous: right foot kick, left foot hi-hat pedal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from virja.plan.bounds import keep_best
from virja.plan.config import DrumCosts, Timing
from virja.vocab import HAND_PIECES, Hand

LEFT: Hand = "left_hand"
RIGHT: Hand = "right_hand"
TIME_EPS_S = 1e-9


@dataclass(frozen=True)
class Stroke:
    """One hand stroke to be assigned: a piece, and how much it matters."""

    piece: str
    priority: int
    dt: float = 0.0  # its note's time after the group's time (within the grouping window)
    foot: bool = False  # a hi-hat stroke the left foot can take (a chick on the pedal)


@dataclass(frozen=True)
class HandGroup:
    """Hand strokes meant together (at most two); ``time`` is the earliest note's."""

    time: float
    strokes: tuple[Stroke, ...]


# (previous motion index or None, its time, right hand's last stroke time, left hand's
# last stroke time, right hand's last piece, left hand's last piece)
HandState = tuple[int | None, float | None, float | None, float | None, str | None, str | None]
START: HandState = (None, None, None, None, None, None)
Assignment = tuple[Hand | None, ...]  # per stroke; None = dropped


def options(group: HandGroup) -> list[Assignment]:
    """Every way to give the group's strokes to hands, drops last (the tie order:
    the right hand first, so that equal costs keep the time-keeping hand playing)."""
    if not group.strokes:  # a group of rebounds only: nothing for the hands to decide
        return [()]
    if len(group.strokes) == 1:
        return [(RIGHT,), (LEFT,), (None,)]
    if len(group.strokes) == 2:
        return [
            (RIGHT, LEFT),
            (LEFT, RIGHT),
            (RIGHT, None),
            (LEFT, None),
            (None, RIGHT),
            (None, LEFT),
            (None, None),
        ]
    raise ValueError(f"a hand group has 1 or 2 strokes, got {len(group.strokes)}")


def drop_penalty(costs: DrumCosts, stroke: Stroke) -> float:
    return costs.drop_penalty + (9 - min(stroke.priority, 9))


def unplayed_penalty(
    costs: DrumCosts, timing: Timing, strokes: tuple[Stroke, ...], assign: Assignment, i: int
) -> float:
    """What leaving stroke ``i`` to no hand of its own costs: a flam or drag (two strokes
    of one piece) played by one hand, the second note on the stroke's rebound, is that
    hand at a stretch (``stretch_penalty``, when the timing has a stretch), and so is
    a hi-hat stroke the left foot takes (``Stroke.foot``); any other stroke is
    dropped (:func:`drop_penalty`)."""
    if timing.stretch_interval_s is not None:
        if strokes[i].foot:
            return timing.stretch_penalty
        other = 1 - i
        if (
            len(strokes) == 2
            and assign[other] is not None
            and strokes[other].piece == strokes[i].piece
        ):
            return timing.stretch_penalty
    return drop_penalty(costs, strokes[i])


def _steps(timing: Timing, prev: str | None, piece: str) -> tuple[tuple[float, float], ...]:
    """:meth:`Timing.penalty_steps` with ``TIME_EPS_S`` taken off each time."""
    return tuple((time - TIME_EPS_S, pen) for time, pen in timing.penalty_steps(prev, piece))


def stroke_penalty(timing: Timing, prev: str | None, piece: str, since: float) -> float:
    """What a hand's stroke on ``piece`` costs ``since`` seconds after its stroke on
    ``prev`` (beyond the table): the largest penalty of :meth:`Timing.penalty_steps`
    whose time it comes sooner than (a stretch, the speed the move needs); 0 if none."""
    for time, pen in _steps(timing, prev, piece):
        if since < time:
            return pen
    return 0.0


def transition(
    costs: DrumCosts, timing: Timing, state: HandState, group: HandGroup, assign: Assignment
) -> tuple[float, HandState, tuple[float, ...]] | None:
    """Objective increment, next state and per-stroke table cost; None if infeasible.

    Per-stroke cost is the table cost that stroke paid (0 for a dropped one);
    the increment adds the drop penalties.
    """
    prev, prev_t, t_right, t_left, p_right, p_left = state
    t = group.time
    stretch = 0.0
    for stroke, by in sorted(
        ((s, h) for s, h in zip(group.strokes, assign, strict=True) if h is not None),
        key=lambda sh: sh[1] != LEFT,
    ):  # left hand first, as the solver adds them
        last, lp = (t_right, p_right) if by == RIGHT else (t_left, p_left)
        if last is None:
            continue
        since = t + stroke.dt - last
        if since < timing.stretch_gap(lp, stroke.piece) - TIME_EPS_S:
            return None
        stretch += stroke_penalty(timing, lp, stroke.piece, since)
    row = prev if prev is not None and prev_t is not None and t - prev_t < timing.rest_s else None
    order = sorted(
        (i for i, h in enumerate(assign) if h is not None),
        key=lambda i: 0 if assign[i] == LEFT else 1,
    )
    per = [0.0] * len(assign)
    total = stretch
    for i in order:
        hand = assign[i]
        assert hand is not None
        m = costs.index(group.strokes[i].piece, hand)
        c = costs.table[costs.none_row if row is None else row][m]
        per[i] = c
        total += c
        row = m
        if hand == RIGHT:
            t_right, p_right = t + group.strokes[i].dt, group.strokes[i].piece
        else:
            t_left, p_left = t + group.strokes[i].dt, group.strokes[i].piece
    for i, hand in enumerate(assign):
        if hand is None:
            total += unplayed_penalty(costs, timing, group.strokes, assign, i)
    if order:
        prev, prev_t = row, t
    return total, (prev, prev_t, t_right, t_left, p_right, p_left), tuple(per)


def _canonical(state: HandState, t: float, timing: Timing, max_interval: float) -> HandState:
    """Forget what no later group (at or after ``t``) can be affected by."""
    prev, prev_t, t_right, t_left, p_right, p_left = state
    if prev_t is not None and t - prev_t >= timing.rest_s:
        prev, prev_t = None, None
    if t_right is not None and t - t_right >= max_interval:
        t_right, p_right = None, None
    if t_left is not None and t - t_left >= max_interval:
        t_left, p_left = None, None
    return (prev, prev_t, t_right, t_left, p_right, p_left)


@dataclass(frozen=True)
class HandSolution:
    assignments: tuple[Assignment, ...]
    stroke_costs: tuple[tuple[float, ...], ...]
    states: tuple[HandState, ...]  # state after each group
    total: float  # table costs + drop penalties


@dataclass(frozen=True, slots=True)
class _Option:
    """One assignment of a group, precompiled: what :func:`transition` computes each time.

    ``played`` lists the played strokes left hand first as ``(is_right, motion, piece,
    dt, stroke index)``; ``penalty`` is the sum of the drop penalties.
    """

    assign: Assignment
    played: tuple[tuple[bool, int, str, float, int], ...]
    penalty: float


# A played option flattened for the solver's inner loop: (option index, the right
# hand's piece and its stroke's dt (None, 0.0 when the right hand does not play), its
# penalty steps by the piece the hand struck last (:func:`_steps`; none when it does
# not play), the least time the right hand needs since its last stroke at a stretch
# (:meth:`Timing.stretch_gap` less TIME_EPS_S; -inf for every piece when it does not
# play), the same four for the left hand, motion that ends the group (the next row),
# penalty, first played motion, table cost first -> second played motion (0.0 for
# one stroke)).
_Need = dict[str | None, float]
# per previous piece: (the largest time of the steps, -inf for none; the steps)
_Steps = dict[str | None, tuple[float, tuple[tuple[float, float], ...]]]
_Played = tuple[
    int,
    str | None,
    float,
    _Steps,
    _Need,
    str | None,
    float,
    _Steps,
    _Need,
    int,
    float,
    int,
    float,
]


def _needs(timing: Timing, piece: str | None) -> _Need:
    """``Timing.stretch_gap(prev, piece) - TIME_EPS_S`` for every previous piece of a
    hand (none included): the same floats :func:`transition` compares with, looked up
    once."""
    if piece is None:
        return dict.fromkeys((None, *HAND_PIECES), -math.inf)
    return {prev: timing.stretch_gap(prev, piece) - TIME_EPS_S for prev in (None, *HAND_PIECES)}


def _all_steps(timing: Timing, piece: str | None) -> _Steps:
    """:func:`_steps` for every previous piece of a hand (none included); none at all
    when the hand does not play."""
    if piece is None:
        return dict.fromkeys((None, *HAND_PIECES), (-math.inf, ()))
    out: _Steps = {}
    for prev in (None, *HAND_PIECES):
        steps = _steps(timing, prev, piece)
        out[prev] = (max((time for time, _pen in steps), default=-math.inf), steps)
    return out


@dataclass(frozen=True, slots=True)
class _Compiled:
    """Everything about a group's options that does not depend on its time."""

    options: tuple[_Option, ...]  # in :func:`options` order
    played: tuple[_Played, ...]  # the options that play something, in the same order
    drop_penalty: float  # of the last option, which drops every stroke


def _compile(costs: DrumCosts, timing: Timing, strokes: tuple[Stroke, ...]) -> _Compiled:
    """The options of :func:`options` for ``strokes``, precompiled, in the same order."""
    opts = []
    flat: list[_Played] = []
    for k, assign in enumerate(options(HandGroup(0.0, strokes))):
        played = []
        penalty = 0.0
        for i, (stroke, hand) in enumerate(zip(strokes, assign, strict=True)):
            if hand is None:
                penalty += unplayed_penalty(costs, timing, strokes, assign, i)
            else:
                played.append(
                    (hand == RIGHT, costs.index(stroke.piece, hand), stroke.piece, stroke.dt, i)
                )
        played.sort(key=lambda p: p[0])  # left (False) first
        opts.append(_Option(assign, tuple(played), penalty))
        if played:
            hand_of = {is_right: (piece, dt) for is_right, _m, piece, dt, _i in played}
            r_piece, r_dt = hand_of.get(True, (None, 0.0))
            l_piece, l_dt = hand_of.get(False, (None, 0.0))
            first, last = played[0][1], played[-1][1]
            flat.append(
                (
                    k,
                    r_piece,
                    r_dt,
                    _all_steps(timing, r_piece),
                    _needs(timing, r_piece),
                    l_piece,
                    l_dt,
                    _all_steps(timing, l_piece),
                    _needs(timing, l_piece),
                    last,
                    penalty,
                    first,
                    costs.table[first][last] if len(played) == 2 else 0.0,
                )
            )
    assert not opts[-1].played  # the all-drop option is last
    return _Compiled(tuple(opts), tuple(flat), opts[-1].penalty)


# Compiled options depend only on (costs, timing, strokes), not on the group's time, so
# they are kept across calls for the last configuration used (one per planner in
# practice).  The entry holds the config objects themselves and is matched by identity,
# so an id reused after garbage collection can never hit a stale entry; the tables are
# frozen (configs are never mutated).  Reading the module global once makes the lookup
# safe across threads: a replaced entry is a new tuple.
_CACHE_LIMIT = 4096  # distinct stroke signatures (a kit gives a few hundred at most)
_cache: tuple[DrumCosts, Timing, dict[tuple[Stroke, ...], _Compiled]] | None = None


def _compiled(costs: DrumCosts, timing: Timing, strokes: tuple[Stroke, ...]) -> _Compiled:
    global _cache
    entry = _cache
    if entry is None or entry[0] is not costs or entry[1] is not timing:
        entry = (costs, timing, {})
        _cache = entry
    table = entry[2]
    comp = table.get(strokes)
    if comp is None:
        if len(table) >= _CACHE_LIMIT:
            table.clear()
        comp = table[strokes] = _compile(costs, timing, strokes)
    return comp


# A move out of states with given hand times: (option index, penalty, first motion,
# pair cost, index of the state it leads to in the next layer).
_Move = tuple[int, float, int, float, int]


def solve(
    costs: DrumCosts,
    timing: Timing,
    state: HandState,
    groups: Sequence[HandGroup],
    *,
    beam: int | None = None,
) -> HandSolution:
    """Least-objective assignment of every group from ``state`` (DP over hand states).

    Groups must be in time order.  Ties go to the earlier option of
    :func:`options` (left before right, drops last).  Each step is exactly
    :func:`transition` followed by :func:`_canonical`; the candidates of a step are
    visited in order (states in the order they were first reached, options in
    :func:`options` order) and a state keeps the first candidate of least total.
    The loop is reorganised for speed without changing any result:

    - Options are compiled once per stroke signature (:func:`_compiled`).
    - Whether an option is feasible, and the hand times after it, depend only on the
      source state's hand times ``(t_right, t_left)``, which several states share
      (they differ in the previous motion).  So per group the feasible moves are
      built once per distinct pair of hand times, with their target states already
      looked up; a played option's target does not depend on the previous motion.
      What does depend on it is only the first played stroke's cost: one table row
      per state.  The all-drop option is always feasible and always last.
      Feasibility is ``not (t - last < need)`` per hand, with ``t - last`` = inf for
      a hand with no recent stroke and ``need`` = -inf for a hand that does not play:
      the same comparisons as :func:`transition`.
    - The states of a layer are numbered in the order they are first reached, and
      the layer is kept as lists indexed by that number (cost, back-pointer).  A
      target is numbered when its move is built, which happens at the first state
      with those hand times, in visiting order, just before its candidates are
      merged; so the numbering is exactly the insertion order of the dictionary the
      plain DP would build, and the next layer is visited in the same order.
    - Each total is summed in the same order as the plain DP (``acc + penalty +
      first + pair``, which matters once costs are fractions) and merged with the
      same strict ``<``, so ties resolve as before.  ``pair`` is 0.0 for a single
      stroke: adding +0.0 changes no sum (a sum starting from +0.0 is never -0.0).

    tests/plan/test_solver_equivalence.py keeps the plain DP and checks that every
    result (assignments, per-stroke costs, states, total) is equal on random input.

    ``beam`` (virja.plan.bounds): a layer of more states keeps only the ``beam`` of
    least objective, in their order; no effect on a layer that is not larger.
    """
    max_interval = timing.max_gap
    rest_s = timing.rest_s
    table = costs.table
    none_row = table[costs.none_row]
    inf = math.inf
    layer: list[HandState] = [state]  # the states reached, in first-reached order
    accs: list[float] = [0.0]  # least objective reaching each
    # back-pointers per group: the previous layer's state and the option index; the
    # per-stroke costs are recomputed once on the way back
    backs: list[tuple[list[int], list[int]]] = []
    layers: list[list[HandState]] = []
    compiled_all = []
    for group in groups:
        t = group.time
        comp = _compiled(costs, timing, group.strokes)
        compiled_all.append(comp)
        drop_k = len(comp.options) - 1
        drop_pen = comp.drop_penalty
        played_opts = comp.played
        moves_by_hands: dict[
            tuple[float | None, float | None, str | None, str | None],
            tuple[list[_Move], float | None, float | None, str | None, str | None],
        ] = {}
        index: dict[HandState, int] = {}  # next layer: state -> its number
        nxt: list[HandState] = []
        # inf until reached (every total is finite); every state is reached by the
        # candidate that numbers it
        nacc: list[float] = []
        back_s: list[int] = []
        back_k: list[int] = []
        for sid, acc in enumerate(accs):
            prev, prev_t, t_right, t_left, p_right, p_left = layer[sid]
            hands = (t_right, t_left, p_right, p_left)
            entry = moves_by_hands.get(hands)
            if entry is None:
                # hand times kept after the group (_canonical): forgotten once no
                # later group can be constrained by them
                keep_r, keep_pr = (
                    (None, None)
                    if t_right is not None and t - t_right >= max_interval
                    else (t_right, p_right)
                )
                keep_l, keep_pl = (
                    (None, None)
                    if t_left is not None and t - t_left >= max_interval
                    else (t_left, p_left)
                )
                since_r = inf if t_right is None else t - t_right
                since_l = inf if t_left is None else t - t_left
                moves: list[_Move] = []
                for (
                    k,
                    r_piece,
                    r_dt,
                    r_steps,
                    r_reach,
                    l_piece,
                    l_dt,
                    l_steps,
                    l_reach,
                    last,
                    penalty,
                    first,
                    pair,
                ) in played_opts:
                    # a hand that does not play needs -inf: never infeasible
                    r_since, l_since = since_r + r_dt, since_l + l_dt
                    if r_since < r_reach[p_right] or l_since < l_reach[p_left]:
                        continue
                    # at a stretch, at speed (stroke_penalty): the left hand's first
                    limit, steps = l_steps[p_left]
                    if l_since < limit:
                        for time, pen in steps:
                            if l_since < time:
                                penalty = penalty + pen
                                break
                    limit, steps = r_steps[p_right]
                    if r_since < limit:
                        for time, pen in steps:
                            if r_since < time:
                                penalty = penalty + pen
                                break
                    nr, npr = keep_r, keep_pr
                    if r_piece is not None:
                        nr = None if t - (t + r_dt) >= max_interval else t + r_dt
                        npr = None if nr is None else r_piece
                    nl, npl = keep_l, keep_pl
                    if l_piece is not None:
                        nl = None if t - (t + l_dt) >= max_interval else t + l_dt
                        npl = None if nl is None else l_piece
                    new = (last, t, nr, nl, npr, npl)
                    nid = index.get(new)
                    if nid is None:
                        nid = index[new] = len(nxt)
                        nxt.append(new)
                        nacc.append(inf)
                        back_s.append(0)
                        back_k.append(0)
                    moves.append((k, penalty, first, pair, nid))
                entry = moves_by_hands[hands] = (moves, keep_r, keep_l, keep_pr, keep_pl)
            moves, keep_r, keep_l, keep_pr, keep_pl = entry
            recent = prev_t is not None and t - prev_t < rest_s
            row = table[prev] if prev is not None and recent else none_row
            for k, penalty, first, pair, nid in moves:
                total = acc + penalty + row[first] + pair
                if total < nacc[nid]:
                    nacc[nid] = total
                    back_s[nid] = sid
                    back_k[nid] = k
            # dropping every stroke: the previous motion is forgotten once rest_s old
            dropped: HandState = (
                (None, None, keep_r, keep_l, keep_pr, keep_pl)
                if prev_t is not None and t - prev_t >= rest_s
                else (prev, prev_t, keep_r, keep_l, keep_pr, keep_pl)
            )
            nid = index.get(dropped)
            if nid is None:
                nid = index[dropped] = len(nxt)
                nxt.append(dropped)
                nacc.append(inf)
                back_s.append(0)
                back_k.append(0)
            total = acc + drop_pen
            if total < nacc[nid]:
                nacc[nid] = total
                back_s[nid] = sid
                back_k[nid] = drop_k
        if beam is not None:
            kept = keep_best(nacc, beam)
            if kept is not None:  # cut: the least-cost states, renumbered in order
                nxt = [nxt[i] for i in kept]
                nacc = [nacc[i] for i in kept]
                back_s = [back_s[i] for i in kept]
                back_k = [back_k[i] for i in kept]
        layer, accs = nxt, nacc
        layers.append(nxt)
        backs.append((back_s, back_k))
    # the first state (in layer order) of least objective
    end = 0
    for i, acc in enumerate(accs):
        if acc < accs[end]:
            end = i
    assigns: list[Assignment] = []
    pers: list[tuple[float, ...]] = []
    states: list[HandState] = []
    cur = end
    for gi in range(len(groups) - 1, -1, -1):
        back_s, back_k = backs[gi]
        prev_id, k = back_s[cur], back_k[cur]
        prev, prev_t = (layers[gi - 1] if gi > 0 else [state])[prev_id][:2]
        opt = compiled_all[gi].options[k]
        r = (
            prev
            if prev is not None and prev_t is not None and groups[gi].time - prev_t < rest_s
            else None
        )
        per = [0.0] * len(groups[gi].strokes)
        for _is_right, m, _piece, _dt, i in opt.played:
            per[i] = table[costs.none_row if r is None else r][m]
            r = m
        assigns.append(opt.assign)
        pers.append(tuple(per))
        states.append(layers[gi][cur])
        cur = prev_id
    return HandSolution(
        tuple(reversed(assigns)), tuple(reversed(pers)), tuple(reversed(states)), accs[end]
    )
