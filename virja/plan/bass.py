"""The bassist: which string and fret for each note, by least total finger travel.

State is the left hand's stopping finger, ``(string index, fret)``, or None
before the first stopped note.  Cost of the next basic motion from state
``(s0, f0)`` (docs/scheduler.md):

- a stopped note at ``(s, f)``, ``f >= 1``: ``|f - f0| + |s - s0|``; the finger
  moves there;
- an open string ``s``: ``|s - s0|`` (0 on the finger's own string); the finger
  stays where it was (the hand does not jump to fret 0);
- from None, anything costs 0.

A double stop costs the move to its *anchor*: the melody (higher) note's stop
when stopped, else the other note's stop, else (both open) like an open melody
note.  Least total cost is found by dynamic programming over finger positions
(Viterbi), not greedily.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Sequence
from dataclasses import dataclass

from virja.plan.config import BassSetup

log = logging.getLogger(__name__)

Position = tuple[int, int]  # (string index low to high, fret; 0 = open)
BassState = Position | None  # the stopping finger (never an open string)
BassOption = tuple[Position, ...]  # one position per kept note, melody first


def fold_into_range(setup: BassSetup, note: int) -> int:
    """``note`` moved by whole octaves into the bass's range (unchanged if inside)."""
    while note < setup.lowest:
        note += 12
    while note > setup.highest:
        note -= 12
    return note


def positions(setup: BassSetup, note: int) -> list[Position]:
    """Every playable (string, fret) for ``note``, open strings first, then low frets."""
    out = [
        (s, note - open_note)
        for s, (_, open_note) in enumerate(setup.strings)
        if 0 <= note - open_note <= setup.frets
    ]
    return sorted(out, key=lambda p: (p[1], p[0]))


def group_options(setup: BassSetup, pitches: Sequence[int]) -> tuple[int, list[BassOption]]:
    """Options for notes sounding together, given distinct in-range pitches high to low.

    Returns ``(kept, options)``: ``kept`` is 2 when the two highest pitches make
    a playable double stop (different strings, stopped frets within the span),
    else 1 (the melody note alone); each option has ``kept`` positions.
    """
    top = positions(setup, pitches[0])
    if len(pitches) >= 2:
        second = positions(setup, pitches[1])
        pairs: list[BassOption] = [
            (p, q)
            for p in top
            for q in second
            if p[0] != q[0]
            and (p[1] == 0 or q[1] == 0 or abs(p[1] - q[1]) <= setup.double_stop_span_frets)
        ]
        if pairs:
            return 2, pairs
    return 1, [(p,) for p in top]


@functools.lru_cache(maxsize=4096)
def chord_options(setup: BassSetup, pitches: tuple[int, ...]) -> tuple[int, tuple[BassOption, ...]]:
    """:func:`group_options`, memoised: a pure function of hashable values (the setup is
    a frozen dataclass), asked again for every chord of every re-plan.  The options are
    a tuple, so the shared answer cannot be changed by a caller."""
    kept, options = group_options(setup, pitches)
    return kept, tuple(options)


def anchor(option: BassOption) -> Position | None:
    """The stop the finger moves to for ``option`` (None when every note is open)."""
    for p in option:
        if p[1] > 0:
            return p
    return None


def transition(state: BassState, option: BassOption) -> tuple[float, BassState]:
    """Cost of playing ``option`` from ``state``, and the finger's state after it."""
    a = anchor(option)
    if state is None:
        return 0.0, a
    if a is None:
        return float(abs(option[0][0] - state[0])), state
    return float(abs(a[1] - state[1]) + abs(a[0] - state[0])), a


def path_cost(state: BassState, options: Sequence[BassOption]) -> float:
    """Total cost of playing ``options`` in order from ``state`` (the definition)."""
    total = 0.0
    for opt in options:
        c, state = transition(state, opt)
        total += c
    return total


@dataclass(frozen=True)
class BassSolution:
    choice: tuple[int, ...]  # option index per group
    costs: tuple[float, ...]  # cost paid by each group
    states: tuple[BassState, ...]  # finger state after each group
    total: float


def solve(state: BassState, groups: Sequence[Sequence[BassOption]]) -> BassSolution:
    """Least-total-cost option per group from ``state`` (Viterbi over finger states).

    Ties go to the earlier option (open strings and low frets first) and,
    among end states, to the first reached.
    """
    best: dict[BassState, float] = {state: 0.0}
    backs: list[dict[BassState, tuple[BassState, int, float]]] = []
    for options in groups:
        # :func:`transition` inlined, with each option's anchor found once per group
        # instead of once per state (same arithmetic, same order, same results)
        prepared = [(anchor(opt), opt[0][0]) for opt in options]
        nxt: dict[BassState, float] = {}
        back: dict[BassState, tuple[BassState, int, float]] = {}
        for prev, acc in best.items():
            for k, (a, melody_string) in enumerate(prepared):
                new: BassState
                if prev is None:
                    c, new = 0.0, a
                elif a is None:
                    c, new = float(abs(melody_string - prev[0])), prev
                else:
                    c, new = float(abs(a[1] - prev[1]) + abs(a[0] - prev[0])), a
                total = acc + c
                old = nxt.get(new)
                if old is None or total < old:
                    nxt[new] = total
                    back[new] = (prev, k, c)
        best = nxt
        backs.append(back)
    end = min(best, key=lambda s: best[s])
    total = best[end]
    choice: list[int] = []
    costs: list[float] = []
    states: list[BassState] = []
    cur = end
    for back in reversed(backs):
        prev, k, c = back[cur]
        choice.append(k)
        costs.append(c)
        states.append(cur)
        cur = prev
    return BassSolution(
        tuple(reversed(choice)), tuple(reversed(costs)), tuple(reversed(states)), total
    )
