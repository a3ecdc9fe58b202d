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
``[hand_speed]``, :func:`stroke_penalty`), so that the hand with time plays, and a stroke
that leaves the arms crossed while the other hand struck a moment before pays for the
crossing (timing.toml ``[hand_cross]``, :func:`cross_penalty`).  A stroke that no hand
can make in time is dropped at a penalty (``drop_penalty`` + 9 - priority), so dropping
happens only when nothing else is feasible.  Ties go to the right hand (the time-keeping
hand keeps the time).  Live, a stroke whose provisional hand is already drawn moving for
it (``Stroke.pin``) costs more with the other hand (``Stroke.switch``,
:func:`switch_penalty`), which can leave for it only now.

Feet are unambiguous: right foot kick, left foot hi-hat pedal.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Sequence
from dataclasses import dataclass

from virja.plan import fastdp
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
    # live only: the hand drawn moving for it already (a pin, plan.types.HandPin), and
    # what giving it to the other hand costs more (:func:`switch_penalty`)
    pin: Hand | None = None
    switch: float = 0.0


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
    hand at a stretch (``stretch_penalty``, when the timing has a stretch; on a cymbal
    of ``Timing.one_hand_doubles`` a double, ``one_hand_double_penalty``), and so is
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
            if strokes[i].piece in timing.one_hand_doubles:  # a cymbal's double
                return timing.one_hand_double_penalty
            return timing.stretch_penalty
    return drop_penalty(costs, strokes[i])


def switch_penalty(stroke: Stroke, hand: Hand | None) -> float:
    """What giving ``stroke`` to ``hand`` costs beyond the table because another hand
    was drawn moving for it (``Stroke.pin``, live only): ``Stroke.switch`` for the other
    hand (virja.plan.chain_hands prices it: the other hand leaves only now), nothing
    for the pinned one or a drop (which pays its own)."""
    if stroke.pin is None or hand is None or hand == stroke.pin:
        return 0.0
    return stroke.switch


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


def cross_penalty(timing: Timing, left: str | None, right: str | None, since: float) -> float:
    """What a stroke that leaves the left hand on ``left`` and the right hand on
    ``right`` pays for crossed arms (:meth:`Timing.crossed`), the other hand having
    struck ``since`` seconds before the stroke's group (0 when both strike in the group):
    ``Timing.cross_penalty`` when that is sooner than ``cross_window_s`` (less
    TIME_EPS_S), else 0 (either hand on no piece: 0)."""
    if (
        not timing.cross_penalty
        or left is None
        or right is None
        or not since < timing.cross_window_s - TIME_EPS_S
        or not timing.crossed(left, right)
    ):
        return 0.0
    return timing.cross_penalty


def transition(
    costs: DrumCosts, timing: Timing, state: HandState, group: HandGroup, assign: Assignment
) -> tuple[float, HandState, tuple[float, ...]] | None:
    """Objective increment, next state and per-stroke table cost; None if infeasible.

    Per-stroke cost is the table cost that stroke paid (0 for a dropped one);
    the increment adds the drop penalties.  Crossed arms (:func:`cross_penalty`): when
    both hands strike, their two pieces; when one does, its piece against the other
    hand's last (added where that hand's own penalty would be, left hand first).
    """
    prev, prev_t, t_right, t_left, p_right, p_left = state
    t = group.time
    by_hand = {h: s.piece for s, h in zip(group.strokes, assign, strict=True) if h is not None}
    stretch = 0.0
    if len(by_hand) == 2:
        stretch += cross_penalty(timing, by_hand[LEFT], by_hand[RIGHT], 0.0)
    elif len(by_hand) == 1 and LEFT not in by_hand and t_left is not None:
        stretch += cross_penalty(timing, p_left, by_hand[RIGHT], t - t_left)
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
    if len(by_hand) == 1 and RIGHT not in by_hand and t_right is not None:
        stretch += cross_penalty(timing, by_hand[LEFT], p_right, t - t_right)
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
        elif group.strokes[i].pin is not None:
            total += switch_penalty(group.strokes[i], hand)
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
    dt, stroke index)``; ``penalty`` is the sum of the drop penalties (and, live, of
    the :func:`switch_penalty` of a stroke given the other hand than its pin).
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
# a hand's steps per previous piece with each penalty replaced by its class (as
# :data:`_Steps`): (the largest time, ((time, class), ...))
_Classed = dict[str | None, tuple[float, tuple[tuple[float, int], ...]]]


# What a hand does in a played option: strikes a piece, or strikes nothing while the
# other hand strikes one: (this hand is the left, the other hand's piece); None: strikes
# nothing in an option where neither hand's last stroke matters to the other.
_HandKey = str | tuple[bool, str] | None


def _hand_key(piece: str | None, is_left: bool, other: str | None) -> _HandKey:
    """The :data:`_HandKey` of a hand striking ``piece`` (None: nothing) while the other
    hand strikes ``other``."""
    if piece is None and other is not None:
        return (is_left, other)
    return piece


def _needs(timing: Timing, piece: _HandKey) -> tuple[_Steps, _Need]:
    """For every previous piece of a hand (none included): :func:`_steps` with the
    largest of their times, and ``Timing.stretch_gap(prev, piece) - TIME_EPS_S``: the
    same floats :func:`transition` compares with, looked up once (made once per timing
    and piece: shared, read only).  A hand that does not play (``piece`` None) has no
    steps and needs -inf; one that does not play while the other hand strikes a piece
    (``(is_left, other)``) needs -inf and its steps are the crossing
    (:func:`cross_penalty`): ``(cross_window_s - TIME_EPS_S, cross_penalty)`` for a last
    piece that crosses the arms with the other hand's, none for any other."""
    global _needs_cache
    entry = _needs_cache
    if entry is None or entry[0] is not timing:
        entry = _needs_cache = (timing, {})
    found = entry[1].get(piece)
    if found is None:
        prevs: tuple[str | None, ...] = (None, *HAND_PIECES)
        if piece is None or isinstance(piece, tuple):
            idle: _Steps = dict.fromkeys(prevs, (-math.inf, ()))
            if piece is not None and timing.cross_penalty and timing.cross_window_s > 0:
                is_left, other = piece
                until = timing.cross_window_s - TIME_EPS_S
                for last in HAND_PIECES:
                    left, right = (last, other) if is_left else (other, last)
                    if timing.crossed(left, right):
                        idle[last] = (until, ((until, timing.cross_penalty),))
            found = (idle, dict.fromkeys(prevs, -math.inf))
        else:
            steps: _Steps = {}
            for prev in prevs:
                st = _steps(timing, prev, piece)
                steps[prev] = (max((time for time, _pen in st), default=-math.inf), st)
            reach: _Need = {prev: timing.stretch_gap(prev, piece) - TIME_EPS_S for prev in prevs}
            found = (steps, reach)
        entry[1][piece] = found
    return found


# the needs of the last timing used (matched by identity, as _cache below): a piece's
# needs do not depend on the stroke's offset or priority, which make most signatures
_needs_cache: tuple[Timing, dict[_HandKey, tuple[_Steps, _Need]]] | None = None


def _classed(steps: _Steps, scale: int) -> tuple[_Classed, list[float]]:
    """A hand's steps with each penalty numbered: the penalties it may pay (0.0 first,
    for none, then each distinct one as met) and the steps with ``number * scale`` in
    place of the penalty."""
    levels = [0.0]
    out: _Classed = {}
    for prev, (limit, st) in steps.items():
        classed = []
        for time, pen in st:
            if pen not in levels:
                levels.append(pen)
            classed.append((time, levels.index(pen) * scale))
        out[prev] = (limit, tuple(classed))
    return out, levels


def _classed_for(timing: Timing, piece: _HandKey, scale: int) -> tuple[_Classed, list[float]]:
    """:func:`_classed` of the steps of a hand striking ``piece`` (:func:`_needs`), made
    once per timing, piece and scale (shared, read only: every signature with that hand's
    piece has them)."""
    global _classed_cache
    entry = _classed_cache
    if entry is None or entry[0] is not timing:
        entry = _classed_cache = (timing, {})
    key = (piece, scale)
    found = entry[1].get(key)
    if found is None:
        found = entry[1][key] = _classed(_needs(timing, piece)[0], scale)
    return found


_classed_cache: tuple[Timing, dict[tuple[_HandKey, int], tuple[_Classed, list[float]]]] | None = (
    None
)


@dataclass(frozen=True, slots=True)
class _Compiled:
    """Everything about a group's options that does not depend on its time."""

    options: tuple[_Option, ...]  # in :func:`options` order
    played: tuple[_Played, ...]  # the options that play something, in the same order
    drop_penalty: float  # of the last option, which drops every stroke
    # per played option, for :func:`solve`: the right hand's (dt, reach, classed steps),
    # the left hand's, and the penalty by class ``right * n_left + left`` (the classes
    # number the penalties each hand may pay, 0 for none), the hands' penalties added
    # as :func:`transition` does (the left hand's first)
    right_plays: tuple[tuple[float, _Need, _Classed], ...]
    left_plays: tuple[tuple[float, _Need, _Classed], ...]
    pens: tuple[tuple[float, ...], ...]
    # what ``_dpcore.c``'s ``hand_window`` takes of a group: its options as doubles
    # (:func:`_native`; None when a piece is not a hand's), and per option (number of
    # strokes, (motion, stroke index) of each played stroke left hand first): the way back
    native: array[float] | None
    back: tuple[tuple[object, ...], ...]


def _compile(costs: DrumCosts, timing: Timing, strokes: tuple[Stroke, ...]) -> _Compiled:
    """The options of :func:`options` for ``strokes``, precompiled, in the same order."""
    opts = []
    flat: list[_Played] = []
    right_plays = []
    left_plays = []
    pens = []
    scales: list[int] = []
    for k, assign in enumerate(options(HandGroup(0.0, strokes))):
        played = []
        penalty = 0.0
        for i, (stroke, hand) in enumerate(zip(strokes, assign, strict=True)):
            if hand is None:
                penalty += unplayed_penalty(costs, timing, strokes, assign, i)
            else:
                if stroke.pin is not None:  # live: another hand drawn moving for it
                    penalty += switch_penalty(stroke, hand)
                played.append(
                    (hand == RIGHT, costs.index(stroke.piece, hand), stroke.piece, stroke.dt, i)
                )
        played.sort(key=lambda p: p[0])  # left (False) first
        opts.append(_Option(assign, tuple(played), penalty))
        if played:
            hand_of = {is_right: (piece, dt) for is_right, _m, piece, dt, _i in played}
            r_piece, r_dt = hand_of.get(True, (None, 0.0))
            l_piece, l_dt = hand_of.get(False, (None, 0.0))
            if r_piece is not None and l_piece is not None:  # both strike: crossed arms?
                penalty = penalty + cross_penalty(timing, l_piece, r_piece, 0.0)
            r_key = _hand_key(r_piece, False, l_piece)
            l_key = _hand_key(l_piece, True, r_piece)
            r_steps, r_reach = _needs(timing, r_key)
            l_steps, l_reach = _needs(timing, l_key)
            first, last = played[0][1], played[-1][1]
            flat.append(
                (
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
                    costs.table[first][last] if len(played) == 2 else 0.0,
                )
            )
            l_classed, l_levels = _classed_for(timing, l_key, 1)
            n_left = len(l_levels)
            scales.append(n_left)
            r_classed, r_levels = _classed_for(timing, r_key, n_left)
            right_plays.append((r_dt, r_reach, r_classed))
            left_plays.append((l_dt, l_reach, l_classed))
            by_class = []
            for r_pen in r_levels:
                for l_pen in l_levels:
                    total = penalty
                    if l_pen:  # as solve's plain loop: a penalty only when a step is met
                        total = total + l_pen
                    if r_pen:
                        total = total + r_pen
                    by_class.append(total)
            pens.append(tuple(by_class))
    assert not opts[-1].played  # the all-drop option is last
    back = tuple((len(strokes), *((m, i) for _r, m, _p, _dt, i in o.played)) for o in opts)
    return _Compiled(
        tuple(opts),
        tuple(flat),
        opts[-1].penalty,
        tuple(right_plays),
        tuple(left_plays),
        tuple(pens),
        _native(timing, flat, pens, scales, len(opts) - 1, opts[-1].penalty),
        back,
    )


# the pieces a hand part may hold, numbered for ``_dpcore.c``'s ``hand_window`` (0: none)
_PIECES: tuple[str | None, ...] = (None, *HAND_PIECES)
_PIECE_NUMBER = {piece: i for i, piece in enumerate(_PIECES)}


def _native(
    timing: Timing,
    flat: list[_Played],
    pens: list[tuple[float, ...]],
    scales: list[int],
    drop_k: int,
    drop_pen: float,
) -> array[float] | None:
    """A group's compiled options as ``_dpcore.c``'s ``hand_window`` reads them, one
    array of doubles (small integers are exact in a double): ``[n_played, drop_k,
    drop_pen, n_pieces]``; per played option ``[option, first motion, pair cost, last
    motion, right piece (-1: it does not play), right dt, left piece, left dt, offset of
    its penalties by class, their number, offset of the right hand's block, of the left
    hand's, the right hand's class scale (the left hand's number of penalties)]``; then
    the penalties; then a block per hand key met (:func:`_block`).  None when a piece
    is not one of :data:`_PIECES` (the Python loop then runs)."""
    n = len(flat)
    head = [float(n), float(drop_k), drop_pen, float(len(_PIECES))]
    recs: list[float] = []
    tail: list[float] = []
    base = len(head) + 13 * n
    where: dict[_HandKey, int] = {}  # each hand key's block, placed once
    blocks: list[list[float]] = []
    for played, by_class, scale in zip(flat, pens, scales, strict=True):
        k, r_piece, r_dt, _rs, _rr, l_piece, l_dt, _ls, _lr, last, _pen, first, pair = played
        if (r_piece is not None and r_piece not in _PIECE_NUMBER) or (
            l_piece is not None and l_piece not in _PIECE_NUMBER
        ):
            return None
        recs += [float(k), float(first), pair, float(last)]
        recs += [-1.0 if r_piece is None else float(_PIECE_NUMBER[r_piece]), r_dt]
        recs += [-1.0 if l_piece is None else float(_PIECE_NUMBER[l_piece]), l_dt]
        recs += [float(base + len(tail)), float(len(by_class))]
        tail += by_class
        r_key = _hand_key(r_piece, False, l_piece)
        l_key = _hand_key(l_piece, True, r_piece)
        for key in (r_key, l_key):
            if key not in where:
                where[key] = len(blocks)
                blocks.append(_block(timing, key))
        recs += [float(where[r_key]), float(where[l_key]), float(scale)]
    at = base + len(tail)
    starts = []
    for block in blocks:
        starts.append(float(at))
        at += len(block)
    for i in range(n):  # block numbers -> offsets
        rec = recs[13 * i : 13 * i + 13]
        recs[13 * i + 10] = starts[int(rec[10])]
        recs[13 * i + 11] = starts[int(rec[11])]
    out = array("d", head + recs + tail)
    for block in blocks:
        out.extend(block)
    return out


def _block(timing: Timing, piece: _HandKey) -> list[float]:
    """What a hand striking ``piece`` (a :data:`_HandKey`: None or ``(is_left, other)``
    when it does not play) needs, as ``hand_window`` reads it: per previous piece in :data:`_PIECES` order ``[reach, largest step time, offset of
    its steps from the block's start, their number]``, then the steps ``(time, penalty
    number)``, the penalties numbered as :func:`_classed` numbers them (0 for none, then
    as met).  The same for every group: made once per timing and piece."""
    global _blocks_cache
    entry = _blocks_cache
    if entry is None or entry[0] is not timing:
        entry = _blocks_cache = (timing, {})
    found = entry[1].get(piece)
    if found is None:
        reach = _needs(timing, piece)[1]
        classed = _classed_for(timing, piece, 1)[0]
        head: list[float] = []
        tail: list[float] = []
        size = 4 * len(_PIECES)
        for prev in _PIECES:
            limit, st = classed[prev]
            head += [reach[prev], limit, float(size + len(tail)), float(len(st))]
            for time, cls in st:
                tail += [time, float(cls)]
        found = entry[1][piece] = head + tail
    return found


_blocks_cache: tuple[Timing, dict[_HandKey, list[float]]] | None = None


def _table_native(costs: DrumCosts) -> array[float]:
    """The cost table's rows as one array of doubles (``hand_window``'s ``table``)."""
    global _table_cache
    entry = _table_cache
    if entry is None or entry[0] is not costs:
        entry = _table_cache = (costs, array("d", [c for row in costs.table for c in row]))
    return entry[1]


_table_cache: tuple[DrumCosts, array[float]] | None = None


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


# A played option as one layer of the solver uses it: (option index, its penalty by
# the sum of the hands' classes (:class:`_Compiled`), first played motion, table cost first -> second
# played motion, target key less the hands it leaves as they were, which hands those
# are: 1 the right hand, 2 the left, 3 both (0: both play)).
_Step = tuple[int, tuple[float, ...], int, float, int, int]
# a layer's parts: (previous motion, its time); a hand's (last stroke time, its piece)
_Row = tuple[int | None, float | None]
_Sub = tuple[float | None, str | None]
_INFEASIBLE = -(1 << 40)  # a hand's class for an option it cannot play in time (sums stay < 0)


@dataclass(slots=True)
class _Layer:
    """The states after a group, by parts: each state is a row (previous motion and its
    time) and a stroke per hand, numbered in ``rows``, ``rights`` and ``lefts``; state
    ``i`` is ``keys[i] = (row * len(rights) + right) * len(lefts) + left``.  ``came``:
    where each state came from, ``previous state * n_options + option``."""

    rows: list[_Row]
    rights: list[_Sub]
    lefts: list[_Sub]
    keys: list[int]
    came: list[int]
    n_options: int

    def parts(self, i: int) -> tuple[int, int, int]:
        """The numbers of state ``i``'s row, right hand's and left hand's parts."""
        ri, hands = divmod(self.keys[i], len(self.rights) * len(self.lefts))
        rh, lh = divmod(hands, len(self.lefts))
        return ri, rh, lh

    def state(self, i: int) -> HandState:
        ri, rh, lh = self.parts(i)
        prev, prev_t = self.rows[ri]
        t_right, p_right = self.rights[rh]
        t_left, p_left = self.lefts[lh]
        return (prev, prev_t, t_right, t_left, p_right, p_left)


def _hand_parts(
    parts: list[_Sub],
    t: float,
    max_interval: float,
    next_parts: dict[tuple[object, object], int],
    plays: tuple[tuple[float, _Need, _Classed], ...],
) -> tuple[list[int], list[list[int]]]:
    """For one hand's parts (last stroke time, piece) of a layer, before a group at
    ``t``: each part's number in the next layer once :func:`_canonical` has kept or
    forgotten it (numbered in ``next_parts`` as met), and its class per played option
    (``plays``: this hand's dt, reach and classed steps, :class:`_Compiled`): the class
    of the first step it comes sooner than (0: none, the penalty it pays numbered),
    :data:`_INFEASIBLE` too soon.  ``_dpcore.c``'s ``hand_parts`` is this loop compiled."""
    core = fastdp.core
    if core is not None:
        found: tuple[list[int], list[list[int]]] | None = core.hand_parts(
            parts, t, max_interval, next_parts, plays
        )
        if found is not None:
            return found
    kept: list[int] = []
    classes: list[list[int]] = []
    for last, piece in parts:
        if last is None:
            since = math.inf
            part: _Sub = (last, piece)
        else:
            since = t - last
            part = (None, None) if since >= max_interval else (last, piece)
        kept.append(next_parts.setdefault(part, len(next_parts)))
        row: list[int] = []
        for dt, reach, classed in plays:
            x = since + dt
            if x < reach[piece]:
                row.append(_INFEASIBLE)
                continue
            c = 0
            limit, steps = classed[piece]
            if x < limit:
                for time, cls in steps:
                    if x < time:
                        c = cls
                        break
            row.append(c)
        classes.append(row)
    return kept, classes


def _merge_layer(
    keys_in: list[int],
    accs: list[float],
    cur_rl: int,
    cur_lefts: int,
    row_costs: list[tuple[float, ...]],
    row_kept: list[int],
    right_kept: list[int],
    right_class: list[list[int]],
    left_kept: list[int],
    left_class: list[list[int]],
    steps: list[_Step],
    n_rl: int,
    n_lefts: int,
    drop_k: int,
    drop_pen: float,
) -> tuple[list[int], list[float], list[int]]:
    """One layer of :func:`solve`: every state of the layer (``keys_in``, ``accs``) with
    every played option (``steps``) and then the option that drops every stroke, merged
    into the next layer's states in first-reached order; returns their keys, least
    objectives and back-pointers (``state * n_options + option``).  ``_dpcore.c``'s
    ``hand_layer`` is this loop compiled."""
    # the next layer, by state key in first-reached order (a dictionary keeps the
    # order of insertion): least objective, and where it came from as
    # ``state * n_options + option``
    reached: dict[int, float] = {}
    came: dict[int, int] = {}
    n_options = drop_k + 1
    inf = math.inf
    get = reached.get
    for sid, (key, acc) in enumerate(zip(keys_in, accs, strict=True)):
        ri, hands = divmod(key, cur_rl)
        rh, lh = divmod(hands, cur_lefts)
        row = row_costs[ri]
        keep_r = right_kept[rh] * n_lefts
        keep_l = left_kept[lh]
        # what a step adds to its base key: the hands it leaves as they were
        kept_keys = (0, keep_r, keep_l, keep_r + keep_l)
        here = sid * n_options
        for (k, pens, first, pair, base, keeps), rc, lc in zip(
            steps, right_class[rh], left_class[lh], strict=True
        ):
            c = rc + lc
            if c < 0:
                continue
            key = base + kept_keys[keeps]
            total = acc + pens[c] + row[first] + pair
            old = get(key)
            if old is None:  # reached first: numbered now (as inf, then merged)
                reached[key] = total
                came[key] = here + k if total < inf else 0
            elif total < old:
                reached[key] = total
                came[key] = here + k
        # dropping every stroke: the row and hands as kept
        key = row_kept[ri] * n_rl + kept_keys[3]
        total = acc + drop_pen
        old = get(key)
        if old is None:
            reached[key] = total
            came[key] = here + drop_k if total < inf else 0
        elif total < old:
            reached[key] = total
            came[key] = here + drop_k
    # the same order: both keyed when first reached
    return list(reached), list(reached.values()), list(came.values())


def _step(
    layer: _Layer,
    accs: list[float],
    t: float,
    comp: _Compiled,
    max_interval: float,
    rest_s: float,
    table: tuple[tuple[float, ...], ...],
    none_row: tuple[float, ...],
    drop_k: int,
    drop_pen: float,
) -> tuple[list[_Row], list[_Sub], list[_Sub], list[int], list[float], list[int]]:
    """One group of :func:`solve` (the beam aside): the next layer's rows, right and left
    hands' parts, state keys, least objectives and back-pointers.  ``_dpcore.c``'s
    ``hand_step`` is this compiled."""
    next_rows: dict[tuple[object, object], int] = {}
    next_rights: dict[tuple[object, object], int] = {}
    next_lefts: dict[tuple[object, object], int] = {}
    # per row of this layer: the table row its first played motion pays, and the
    # row kept when every stroke is dropped
    row_costs: list[tuple[float, ...]] = []
    row_kept: list[int] = []
    for prev, prev_t in layer.rows:
        if prev_t is not None and t - prev_t >= rest_s:
            row_costs.append(none_row)
            row_kept.append(next_rows.setdefault((None, None), len(next_rows)))
        else:
            recent = prev_t is not None
            row_costs.append(table[prev] if prev is not None and recent else none_row)
            row_kept.append(next_rows.setdefault((prev, prev_t), len(next_rows)))
    right_kept, right_class = _hand_parts(
        layer.rights, t, max_interval, next_rights, comp.right_plays
    )
    left_kept, left_class = _hand_parts(layer.lefts, t, max_interval, next_lefts, comp.left_plays)
    # the parts each played option makes
    made: list[tuple[int, int, int]] = []
    for _k, r_piece, r_dt, _rn, _rr, l_piece, l_dt, _ln, _lr, last, *_ in comp.played:
        nr = -1
        if r_piece is not None:
            tr = None if t - (t + r_dt) >= max_interval else t + r_dt
            nr = next_rights.setdefault((tr, None if tr is None else r_piece), len(next_rights))
        nl = -1
        if l_piece is not None:
            tl = None if t - (t + l_dt) >= max_interval else t + l_dt
            nl = next_lefts.setdefault((tl, None if tl is None else l_piece), len(next_lefts))
        made.append((next_rows.setdefault((last, t), len(next_rows)), nr, nl))
    n_rights, n_lefts = len(next_rights), len(next_lefts)
    n_rl = n_rights * n_lefts
    steps: list[_Step] = []
    for played, pens, (nrow, nr, nl) in zip(comp.played, comp.pens, made, strict=True):
        k, first, pair = played[0], played[11], played[12]
        base = nrow * n_rl + max(nr, 0) * n_lefts + max(nl, 0)
        steps.append((k, pens, first, pair, base, (nr < 0) + 2 * (nl < 0)))
    cur_rl, cur_lefts = len(layer.rights) * len(layer.lefts), len(layer.lefts)
    shared = (
        layer.keys,
        accs,
        cur_rl,
        cur_lefts,
        row_costs,
        row_kept,
        right_kept,
        right_class,
        left_kept,
        left_class,
        steps,
        n_rl,
        n_lefts,
    )
    merged = None
    core = fastdp.core
    if core is not None:  # the same loop compiled (virja/plan/_dpcore.c)
        merged = core.hand_layer(*shared, len(next_rows), drop_k, drop_pen)
    if merged is None:
        merged = _merge_layer(*shared, drop_k, drop_pen)
    keys, nacc, codes = merged
    return (
        list(next_rows),  # type: ignore[arg-type]  # numbered in insertion order
        list(next_rights),  # type: ignore[arg-type]
        list(next_lefts),  # type: ignore[arg-type]
        keys,
        nacc,
        codes,
    )


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
    - A state is three parts: the row (previous motion and its time) and each hand's
      last stroke (time and piece).  A layer numbers its distinct parts and keeps,
      per state, the three numbers; the next layer's states are keyed by the integer
      ``(row * n_rights + right) * n_lefts + left`` over the next layer's parts,
      which are all known before the states are visited (each is a part of this
      layer kept or forgotten by :func:`_canonical`, or one a played option makes).
    - Whether an option is feasible, and what penalty each hand pays for it (at a
      stretch, at speed: :func:`stroke_penalty`), depend on one hand's part only:
      worked out once per distinct part and option (a class: 0 for no penalty, else
      the penalty's number among those the hand may pay for that option, the right
      hand's times the number of the left's; :data:`_INFEASIBLE` too soon), the same
      comparisons as :func:`transition` (``t - last + dt`` against
      :meth:`Timing.stretch_gap` less TIME_EPS_S, then each of :func:`_steps` in
      order; inf for a hand with no recent stroke, -inf needed by a hand that does
      not play).  The sum of the two classes indexes the option's penalty with those
      two hands' penalties added, the left hand's first, as :func:`transition` does.
    - A played option's target keeps the row it makes, the part of each hand that
      plays and the kept part of a hand that does not; dropping every stroke keeps
      the kept parts (the previous motion forgotten once ``rest_s`` old).  The
      table row a state's first played motion pays is looked up once per row.
    - A target is numbered at the first candidate reaching it, so the numbering is
      exactly the insertion order of the dictionary the plain DP would build, and
      the next layer is visited in the same order.
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
    prev0, prev_t0, t_right0, t_left0, p_right0, p_left0 = state
    compiled_all = [_compiled(costs, timing, group.strokes) for group in groups]
    core = fastdp.core
    pr0, pl0 = _PIECE_NUMBER.get(p_right0), _PIECE_NUMBER.get(p_left0)
    natives = [comp.native for comp in compiled_all]
    if (
        core is not None
        and pr0 is not None
        and pl0 is not None
        and None not in natives
        and all(len(row) == len(table[0]) for row in table)
    ):  # the whole window compiled (virja/plan/_dpcore.c)
        whole = core.hand_window(
            (prev0, prev_t0, t_right0, t_left0, pr0, pl0),
            [group.time for group in groups],
            natives,
            [comp.back for comp in compiled_all],
            _table_native(costs),
            len(table[0]),
            costs.none_row,
            max_interval,
            rest_s,
            -1 if beam is None else beam,
            _PIECES,
        )
        if whole is not None:
            ks, w_pers, w_states, w_total = whole
            return HandSolution(
                tuple(comp.options[k].assign for comp, k in zip(compiled_all, ks, strict=True)),
                tuple(w_pers),
                tuple(w_states),
                w_total,
            )
    start = _Layer([(prev0, prev_t0)], [(t_right0, p_right0)], [(t_left0, p_left0)], [0], [0], 1)
    layer = start
    accs: list[float] = [0.0]  # least objective reaching each state of the layer
    # per group: the layer after it, with its back-pointers (``_Layer.came``); the
    # per-stroke costs are recomputed once on the way back
    layers: list[_Layer] = []
    for group, comp in zip(groups, compiled_all, strict=True):
        t = group.time
        drop_k = len(comp.options) - 1
        drop_pen = comp.drop_penalty
        stepped = None
        core = fastdp.core
        if core is not None:  # the same step compiled (virja/plan/_dpcore.c)
            stepped = core.hand_step(
                layer.rows,
                layer.rights,
                layer.lefts,
                layer.keys,
                accs,
                t,
                max_interval,
                rest_s,
                table,
                none_row,
                comp.played,
                comp.pens,
                comp.right_plays,
                comp.left_plays,
                drop_k,
                drop_pen,
            )
        if stepped is None:
            stepped = _step(
                layer, accs, t, comp, max_interval, rest_s, table, none_row, drop_k, drop_pen
            )
        next_rows, next_rights, next_lefts, keys, nacc, codes = stepped
        n_options = drop_k + 1
        if beam is not None:
            kept_ids = keep_best(nacc, beam)
            if kept_ids is not None:  # cut: the least-cost states, renumbered in order
                keys = [keys[i] for i in kept_ids]
                nacc = [nacc[i] for i in kept_ids]
                codes = [codes[i] for i in kept_ids]
        layer = _Layer(
            next_rows,
            next_rights,
            next_lefts,
            keys,
            codes,
            n_options,
        )
        accs = nacc
        layers.append(layer)
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
        after = layers[gi]
        prev_id, k = divmod(after.came[cur], after.n_options)
        before = layers[gi - 1] if gi > 0 else start
        prev, prev_t = before.rows[before.parts(prev_id)[0]]
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
        states.append(after.state(cur))
        cur = prev_id
    return HandSolution(
        tuple(reversed(assigns)), tuple(reversed(pers)), tuple(reversed(states)), accs[end]
    )
