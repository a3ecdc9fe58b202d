"""The bassist: which string and fret for each note, and where the left hand is.

State is the left hand: ``(string, fret, position)`` of the last stopping
finger and the hand's position (the fret under the first finger), or None
before the first stopped note.  The position covers ``span(position)`` frets
above it (:class:`~virja.plan.config.Fingering`: a whole tone with 1-2-4
fingering in the lower positions, wider in thumb position).  Cost of the next
basic motion from ``(s0, f0, h0)`` (docs/scheduler.md):

- the paper's finger travel, the base: a stopped note at ``(s, f)`` costs
  ``|f - f0| + |s - s0|``; an open string ``s`` costs ``|s - s0|`` and leaves
  the hand where it is;
- no shift while the stopped frets lie in the span of ``h0``; otherwise the
  hand shifts to a position ``h`` that covers them, for ``shift_cost +
  shift_cost_per_fret * |h - h0|``, plus ``rushed_shift_cost`` when the time
  since the previous note is shorter than the shift takes
  (``shift_time(|h - h0|)``);
- every stopped note pays ``position_cost_per_fret * (h - 1)``: lower positions
  are preferred;
- from None, a stopped note pays only its position cost.

The paper's example holds: F1 on E fret 1 (position 1), then B-flat1 on A fret
1 costs 1 (E fret 6 costs 5 + a shift).  A double stop costs the move to its
*anchor*: the melody (higher) note's stop when stopped, else the other note's
stop, else (both open) like an open melody note; its position covers both
stops where one can.  Least total cost is found by dynamic programming over
hand states (Viterbi), not greedily.
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

from virja.plan import fastdp
from virja.plan.config import BassSetup, Fingering
from virja.vocab import BassPluck, as_bass_string

log = logging.getLogger(__name__)

Position = tuple[int, int]  # (string index low to high, fret; 0 = open)
HandState = tuple[int, int, int]  # (string, fret) of the stopping finger, hand position
BassState = HandState | None  # the left hand (never on an open string)
BassOption = tuple[Position, ...]  # one position per kept note, melody first

DEFAULT_FINGERING = Fingering()
# the highest fret of any fingerboard (BassSetup allows 36): no hand position or
# shift is larger
_MAX_POSITION = 36


def motion_key(string: str, fret: int, hand: BassState) -> BassPluck:
    """The basic motion: ``string`` plucked at ``fret``, with the left hand's position
    once it has one (an open string keeps the hand where it was).  Made once per
    motion (a pluck is frozen: shared by every note it plays)."""
    return _pluck(string, fret, None if hand is None else hand[2])


@functools.lru_cache(maxsize=4096)
def _pluck(string: str, fret: int, position: int | None) -> BassPluck:
    return BassPluck(as_bass_string(string), fret, position)


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


@functools.lru_cache(maxsize=4096)
def hand_positions(fingering: Fingering, low: int, high: int) -> tuple[int, ...]:
    """Positions whose span covers frets ``low..high`` (lowest first); if none can,
    those covering ``high`` alone (a stretch for the other finger)."""
    widest = max(fingering.span_frets, fingering.thumb_span_frets)
    out = tuple(h for h in range(max(1, high - widest), low + 1) if high <= h + fingering.span(h))
    if out or low == high:
        return out
    return hand_positions(fingering, high, high)


def _stops(option: BassOption) -> tuple[int, int] | None:
    frets = [f for _, f in option if f > 0]
    return (min(frets), max(frets)) if frets else None


def transitions(
    state: BassState,
    option: BassOption,
    fingering: Fingering = DEFAULT_FINGERING,
    gap_s: float = math.inf,
) -> list[tuple[float, BassState]]:
    """Every way to play ``option`` from ``state``: ``(cost, hand state after)``, one
    per hand position it may be played in (one when no shift is needed).
    ``gap_s`` is the time since the previous note (a shift needs time)."""
    a = anchor(option)
    if a is None:
        if state is None:
            return [(0.0, None)]
        return [(float(abs(option[0][0] - state[0])), state)]
    low, high = _stops(option) or (a[1], a[1])
    per = fingering.position_cost_per_fret
    if state is None:
        return [(per * (h - 1), (a[0], a[1], h)) for h in hand_positions(fingering, low, high)]
    s0, f0, h0 = state
    base = float(abs(a[1] - f0) + abs(a[0] - s0))
    if h0 <= low and high <= h0 + fingering.span(h0):
        return [(base + per * (h0 - 1), (a[0], a[1], h0))]
    out: list[tuple[float, BassState]] = []
    for h in hand_positions(fingering, low, high):
        d = abs(h - h0)
        c = base + fingering.shift_cost + fingering.shift_cost_per_fret * d + per * (h - 1)
        if gap_s < fingering.shift_time(d):
            c += fingering.rushed_shift_cost
        out.append((c, (a[0], a[1], h)))
    return out


def transition(
    state: BassState,
    option: BassOption,
    fingering: Fingering = DEFAULT_FINGERING,
    gap_s: float = math.inf,
) -> tuple[float, BassState]:
    """The cheapest of :func:`transitions` (the lower position on a tie)."""
    return min(transitions(state, option, fingering, gap_s), key=lambda t: t[0])


def shifted(before: BassState, after: BassState) -> bool:
    """Whether the hand changed position between two states."""
    return before is not None and after is not None and before[2] != after[2]


def path_cost(
    state: BassState,
    options: Sequence[BassOption],
    fingering: Fingering = DEFAULT_FINGERING,
    gaps: Sequence[float] | None = None,
) -> float:
    """Least total cost of playing ``options`` in order from ``state``, over every
    choice of hand position (the definition, by exhaustive search: for tests)."""
    if not options:
        return 0.0
    gap = math.inf if gaps is None else gaps[0]
    rest = None if gaps is None else gaps[1:]
    return min(
        c + path_cost(new, options[1:], fingering, rest)
        for c, new in transitions(state, options[0], fingering, gap)
    )


@dataclass(frozen=True)
class BassSolution:
    choice: tuple[int, ...]  # option index per group
    costs: tuple[float, ...]  # cost paid by each group
    states: tuple[BassState, ...]  # hand state after each group
    total: float


# One option of a group, worked out once (:func:`_prepared`): its anchor's string and
# fret (-1, -1: every note open), its melody string, stopped frets, and per hand position
# the position, the state it leads to and its position cost.
_Prepared = tuple[int, int, int, int, int, list[tuple[int, HandState, float]]]


def _prepare(fingering: Fingering, option: BassOption) -> _Prepared:
    a = anchor(option)
    if a is None:
        return (-1, -1, option[0][0], 0, 0, [])
    low, high = _stops(option) or (a[1], a[1])
    per = fingering.position_cost_per_fret
    hs = [(h, (a[0], a[1], h), per * (h - 1)) for h in hand_positions(fingering, low, high)]
    return (a[0], a[1], option[0][0], low, high, hs)


@dataclass(frozen=True, slots=True)
class _Tables:
    """What :func:`solve` works out from the fingering alone, by index (the same floats
    as the calls): ``span(h)``, ``shift_time(d)`` and the position cost of ``h``, for
    positions and shifts up to the frets of any fingerboard (36); and per group's
    options their :func:`_prepare`, memoised (at most _PREPARED_LIMIT groups)."""

    spans: list[int]
    shift_times: list[float]
    position_costs: list[float]
    prepared: dict[Sequence[BassOption], list[_Prepared]]
    # the fingering's costs all floats: the compiled DP (which sums in floats) gives
    # the very objects the loop gives
    floats: bool


_PREPARED_LIMIT = 4096  # distinct groups' options (chord_options memoises as many)
# kept across calls for the last fingering used, matched by identity (as
# virja.plan.drums does for its compiled options; a fingering is frozen); reading the
# global once makes it safe across threads
_tables_cache: tuple[Fingering, _Tables] | None = None


def _tables(fingering: Fingering) -> _Tables:
    global _tables_cache
    entry = _tables_cache
    if entry is None or entry[0] is not fingering:
        top = _MAX_POSITION + 1
        per = fingering.position_cost_per_fret
        tables = _Tables(
            [fingering.span(h) for h in range(top)],
            [fingering.shift_time(d) for d in range(top)],
            [per * (h - 1) for h in range(top)],
            {},
            all(
                type(x) is float
                for x in (
                    per,
                    fingering.shift_cost,
                    fingering.shift_cost_per_fret,
                    fingering.rushed_shift_cost,
                )
            ),
        )
        entry = _tables_cache = (fingering, tables)
    return entry[1]


def _prepared(
    tables: _Tables, fingering: Fingering, options: Sequence[BassOption]
) -> list[_Prepared]:
    """:func:`_prepare` of each of a group's options, in order (shared: not changed).
    Hashable options (the tuples of :func:`chord_options`) are memoised; others are
    worked out each time."""
    try:
        found = tables.prepared.get(options)
    except TypeError:  # a list, or options holding lists: not hashable
        return [_prepare(fingering, opt) for opt in options]
    if found is None:
        if len(tables.prepared) >= _PREPARED_LIMIT:
            tables.prepared.clear()
        found = tables.prepared[options] = [_prepare(fingering, opt) for opt in options]
    return found


def solve(
    state: BassState,
    groups: Sequence[Sequence[BassOption]],
    fingering: Fingering = DEFAULT_FINGERING,
    gaps: Sequence[float] | None = None,
) -> BassSolution:
    """Least-total-cost option per group from ``state`` (Viterbi over hand states).

    ``gaps[i]`` is the time from the previous note to group ``i`` (inf: unknown).
    Ties go to the earlier option (open strings and low frets first), then the
    lower hand position and, among end states, to the first reached.
    """
    shift_cost = fingering.shift_cost
    shift_per_fret = fingering.shift_cost_per_fret
    rushed = fingering.rushed_shift_cost
    tables = _tables(fingering)
    spans, shift_times, position_costs = tables.spans, tables.shift_times, tables.position_costs
    core = fastdp.core
    if core is not None and tables.floats:  # the same DP compiled (virja/plan/_dpcore.c)
        found = core.bass_solve(
            state,
            [_prepared(tables, fingering, options) for options in groups],
            gaps,
            spans,
            shift_times,
            position_costs,
            shift_cost,
            shift_per_fret,
            rushed,
        )
        if found is not None:  # None: input it does not take (the loop below does)
            return BassSolution(*found)
    best: dict[BassState, float] = {state: 0.0}
    backs: list[dict[BassState, tuple[BassState, int, float]]] = []
    for gi, options in enumerate(groups):
        gap = math.inf if gaps is None else gaps[gi]
        prepared = _prepared(tables, fingering, options)
        nxt: dict[BassState, float] = {}
        back: dict[BassState, tuple[BassState, int, float]] = {}
        get = nxt.get
        for prev, acc in best.items():
            if prev is None:
                for k, (a0, _a1, _melody, _low, _high, hs) in enumerate(prepared):
                    if a0 < 0:  # every note open: the hand stays where it is (nowhere)
                        moves: list[tuple[int, HandState, float]] = [(0, None, 0.0)]  # type: ignore[list-item]
                    else:
                        moves = hs
                    for _h, reached, c in moves:
                        total = acc + c
                        old = get(reached)
                        if old is None or total < old:
                            nxt[reached] = total
                            back[reached] = (prev, k, c)
                continue
            s0, f0, h0 = prev
            in_reach = h0 + spans[h0]  # the highest fret the hand covers without a shift
            for k, (a0, a1, melody, low, high, hs) in enumerate(prepared):
                if a0 < 0:  # every note open: the hand stays where it is
                    c = float(abs(melody - s0))
                    new: BassState = prev
                elif h0 <= low and high <= in_reach:
                    c = float(abs(a1 - f0) + abs(a0 - s0)) + position_costs[h0]
                    new = (a0, a1, h0)
                else:
                    base = float(abs(a1 - f0) + abs(a0 - s0))
                    for h, state_h, ph in hs:
                        d = abs(h - h0)
                        c = base + shift_cost + shift_per_fret * d + ph
                        if gap < shift_times[d]:
                            c += rushed
                        total = acc + c
                        old = get(state_h)
                        if old is None or total < old:
                            nxt[state_h] = total
                            back[state_h] = (prev, k, c)
                    continue
                total = acc + c
                old = get(new)
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
