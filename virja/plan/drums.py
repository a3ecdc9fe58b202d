"""The drummer: which hand strikes each hand note, by least total table cost.

The hand motions of the whole performance form one sequence, ordered by time,
and two motions at the same instant ordered left hand first, then right.  Its
cost is ``table[none][m1] + sum table[m_(k-1)][m_k]``, where the row is
"none" for the first motion and for any motion at least ``rest_s`` after the
previous one (docs/scheduler.md).  Constraints: one hand strikes one piece at
a time; the two strokes of a simultaneous pair go to different hands; a hand
strikes again only after the new motion's ``min_interval_s``.  A stroke that
no hand can make in time is dropped at a penalty (``drop_penalty`` + 9 -
priority), so dropping happens only when nothing else is feasible.

Feet are unambiguous: right foot kick, left foot hi-hat pedal.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from virja.plan.config import DrumCosts, Timing

Hand = str  # "left_hand" | "right_hand"
LEFT: Hand = "left_hand"
RIGHT: Hand = "right_hand"
TIME_EPS_S = 1e-9


@dataclass(frozen=True)
class Stroke:
    """One hand stroke to be assigned: a piece, and how much it matters."""

    piece: str
    priority: int


@dataclass(frozen=True)
class HandGroup:
    """Hand strokes sounding together (at most two distinct pieces)."""

    time: float
    strokes: tuple[Stroke, ...]


# (previous motion index or None, its time, right hand's last stroke, left hand's last stroke)
HandState = tuple[int | None, float | None, float | None, float | None]
START: HandState = (None, None, None, None)
Assignment = tuple[Hand | None, ...]  # per stroke; None = dropped


def options(group: HandGroup) -> list[Assignment]:
    """Every way to give the group's strokes to hands, drops last (the tie order)."""
    if len(group.strokes) == 1:
        return [(LEFT,), (RIGHT,), (None,)]
    if len(group.strokes) == 2:
        return [
            (LEFT, RIGHT),
            (RIGHT, LEFT),
            (LEFT, None),
            (RIGHT, None),
            (None, LEFT),
            (None, RIGHT),
            (None, None),
        ]
    raise ValueError(f"a hand group has 1 or 2 strokes, got {len(group.strokes)}")


def drop_penalty(costs: DrumCosts, stroke: Stroke) -> float:
    return costs.drop_penalty + (9 - min(stroke.priority, 9))


def transition(
    costs: DrumCosts, timing: Timing, state: HandState, group: HandGroup, assign: Assignment
) -> tuple[float, HandState, tuple[float, ...]] | None:
    """Objective increment, next state and per-stroke table cost; None if infeasible.

    Per-stroke cost is the table cost that stroke paid (0 for a dropped one);
    the increment adds the drop penalties.
    """
    prev, prev_t, t_right, t_left = state
    t = group.time
    for stroke, hand in zip(group.strokes, assign, strict=True):
        if hand is None:
            continue
        last = t_right if hand == RIGHT else t_left
        if last is not None and t - last < timing.get(stroke.piece).min_interval_s - TIME_EPS_S:
            return None
    row = prev if prev is not None and prev_t is not None and t - prev_t < timing.rest_s else None
    order = sorted(
        (i for i, h in enumerate(assign) if h is not None),
        key=lambda i: 0 if assign[i] == LEFT else 1,
    )
    per = [0.0] * len(assign)
    total = 0.0
    for i in order:
        hand = assign[i]
        assert hand is not None
        m = costs.index(group.strokes[i].piece, hand)
        c = costs.table[costs.none_row if row is None else row][m]
        per[i] = c
        total += c
        row = m
        if hand == RIGHT:
            t_right = t
        else:
            t_left = t
    for stroke, hand in zip(group.strokes, assign, strict=True):
        if hand is None:
            total += drop_penalty(costs, stroke)
    if order:
        prev, prev_t = row, t
    return total, (prev, prev_t, t_right, t_left), tuple(per)


def _canonical(state: HandState, t: float, timing: Timing, max_interval: float) -> HandState:
    """Forget what no later group (at or after ``t``) can be affected by."""
    prev, prev_t, t_right, t_left = state
    if prev_t is not None and t - prev_t >= timing.rest_s:
        prev, prev_t = None, None
    if t_right is not None and t - t_right >= max_interval:
        t_right = None
    if t_left is not None and t - t_left >= max_interval:
        t_left = None
    return (prev, prev_t, t_right, t_left)


@dataclass(frozen=True)
class HandSolution:
    assignments: tuple[Assignment, ...]
    stroke_costs: tuple[tuple[float, ...], ...]
    states: tuple[HandState, ...]  # state after each group
    total: float  # table costs + drop penalties


def _compiled(
    costs: DrumCosts, timing: Timing, group: HandGroup
) -> list[tuple[Assignment, tuple[tuple[bool, int, float, int], ...], float]]:
    """Per option: (assignment, played strokes left first as (is_right, motion, min
    interval, stroke index), drop penalty) -- what :func:`transition` computes each time."""
    out = []
    for assign in options(group):
        played = []
        penalty = 0.0
        for i, (stroke, hand) in enumerate(zip(group.strokes, assign, strict=True)):
            if hand is None:
                penalty += drop_penalty(costs, stroke)
            else:
                played.append(
                    (
                        hand == RIGHT,
                        costs.index(stroke.piece, hand),
                        timing.get(stroke.piece).min_interval_s - TIME_EPS_S,
                        i,
                    )
                )
        played.sort(key=lambda p: p[0])  # left (False) first
        out.append((assign, tuple(played), penalty))
    return out


def solve(
    costs: DrumCosts, timing: Timing, state: HandState, groups: Sequence[HandGroup]
) -> HandSolution:
    """Least-objective assignment of every group from ``state`` (DP over hand states).

    Groups must be in time order.  Ties go to the earlier option of
    :func:`options` (left before right, drops last).  Each step is exactly
    :func:`transition` (precompiled per group for speed).
    """
    max_interval = max(mt.min_interval_s for mt in timing.kinds.values())
    rest_s = timing.rest_s
    table = costs.table
    none_row = costs.none_row
    best: dict[HandState, float] = {state: 0.0}
    # back-pointers keep (previous state, option index); the per-stroke costs are
    # recomputed once on the way back instead of being built for every candidate
    backs: list[dict[HandState, tuple[HandState, int]]] = []
    compiled_all = []
    for group in groups:
        t = group.time
        compiled = _compiled(costs, timing, group)
        compiled_all.append(compiled)
        nxt: dict[HandState, float] = {}
        back: dict[HandState, tuple[HandState, int]] = {}
        for st, acc in best.items():
            prev, prev_t, t_right, t_left = st
            row0 = prev if prev is not None and prev_t is not None and t - prev_t < rest_s else None
            for k, (_assign, played, penalty) in enumerate(compiled):
                row = row0
                tr, tl = t_right, t_left
                total = acc + penalty
                ok = True
                for is_right, m, min_int, _i in played:
                    last = tr if is_right else tl
                    if last is not None and t - last < min_int:
                        ok = False
                        break
                    total += table[none_row if row is None else row][m]
                    row = m
                    if is_right:
                        tr = t
                    else:
                        tl = t
                if not ok:
                    continue
                # _canonical, inlined (this loop is the scheduler's hot spot)
                if played:
                    np_, npt = row, t
                elif prev_t is not None and t - prev_t >= rest_s:
                    np_, npt = None, None
                else:
                    np_, npt = prev, prev_t
                if tr is not None and t - tr >= max_interval:
                    tr = None
                if tl is not None and t - tl >= max_interval:
                    tl = None
                new = (np_, npt, tr, tl)
                old = nxt.get(new)
                if old is None or total < old:
                    nxt[new] = total
                    back[new] = (st, k)
        best = nxt
        backs.append(back)
    end = min(best, key=lambda s: best[s])
    total = best[end]
    assigns: list[Assignment] = []
    pers: list[tuple[float, ...]] = []
    states: list[HandState] = []
    cur = end
    for group, compiled, back in zip(
        reversed(groups), reversed(compiled_all), reversed(backs), strict=True
    ):
        prev_st, k = back[cur]
        assign, played, _penalty = compiled[k]
        prev, prev_t = prev_st[0], prev_st[1]
        row = (
            prev
            if prev is not None and prev_t is not None and group.time - prev_t < rest_s
            else None
        )
        per = [0.0] * len(group.strokes)
        for _is_right, m, _min_int, i in played:
            per[i] = table[none_row if row is None else row][m]
            row = m
        assigns.append(assign)
        pers.append(tuple(per))
        states.append(cur)
        cur = prev_st
    return HandSolution(
        tuple(reversed(assigns)), tuple(reversed(pers)), tuple(reversed(states)), total
    )
