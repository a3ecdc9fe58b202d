"""The fast solvers equal the plain dynamic programmes they replaced, result for result.

``virja.plan.drums.solve`` and ``virja.plan.bass.solve`` are reorganised for speed
(compiled options, moves shared by states with the same hand times, numbered
layers).  The plain versions are kept here as references; on seeded random input,
including cost tables with fractions and negative numbers (where the order of
additions could matter), zero intervals and odd start states, every assignment,
per-stroke cost, state and total must be identical, ties included.  Every test runs
twice: with the compiled inner loops (``virja/plan/_dpcore.c``, skipped when not
built) and with the Python loops.
"""

from __future__ import annotations

import dataclasses
import math
import random
from collections.abc import Iterator, Sequence

import pytest

from virja.plan import bass, drums, fastdp
from virja.plan.bounds import keep_best
from virja.plan.config import (
    BassSetup,
    DrumCosts,
    Fingering,
    MotionTiming,
    PlanConfig,
    Timing,
)
from virja.plan.drums import RIGHT, Assignment, HandGroup, HandSolution, HandState, Stroke
from virja.vocab import HAND_PIECES


@pytest.fixture(autouse=True, params=["compiled", "python"])
def loops(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """The solvers' inner loops: compiled (virja.plan.fastdp.core) or Python."""
    if request.param == "python":
        monkeypatch.setattr(fastdp, "core", None)
    elif fastdp.core is None:
        pytest.skip("virja/plan/_dpcore.c is not built (python tools/build_dpcore.py)")
    yield request.param


def _crossed(timing: Timing, left: str | None, right: str | None, since: float) -> float:
    """What the arms crossed cost: the left hand's piece right of the right hand's (but
    for the home posture) within the window; written apart from the solver's."""
    if left is None or right is None or (right, left) in timing.cross_home:
        return 0.0
    pos = timing.cross_positions
    if left not in pos or right not in pos:  # a timing without positions: no crossing
        return 0.0
    if since < timing.cross_window_s - drums.TIME_EPS_S and pos[left] > pos[right]:
        return timing.cross_penalty
    return 0.0


def _reference_drums(
    costs: DrumCosts,
    timing: Timing,
    state: HandState,
    groups: Sequence[HandGroup],
    beam: int | None = None,
) -> HandSolution:
    """The plain DP over hand states (the solver as it was before it was sped up; hand
    states carry each hand's last piece, strokes their offset in the group)."""
    max_interval = timing.max_gap
    rest_s, table, none_row = timing.rest_s, costs.table, costs.none_row
    best: dict[HandState, float] = {state: 0.0}
    backs: list[dict[HandState, tuple[HandState, int]]] = []
    compiled_all = []
    for group in groups:
        t = group.time
        compiled = []
        for assign in drums.options(group):
            plays, penalty = [], 0.0
            for i, (stroke, hand) in enumerate(zip(group.strokes, assign, strict=True)):
                if hand is None:
                    penalty += drums.unplayed_penalty(costs, timing, group.strokes, assign, i)
                else:
                    penalty += drums.switch_penalty(stroke, hand)  # live pins: 0 without
                    plays.append((hand == RIGHT, costs.index(stroke.piece, hand), stroke.piece, i))
            plays.sort(key=lambda p: p[0])  # left hand first
            compiled.append((assign, tuple(plays), penalty))
        compiled_all.append(compiled)
        nxt: dict[HandState, float] = {}
        back: dict[HandState, tuple[HandState, int]] = {}
        for st, acc in best.items():
            prev, prev_t, t_right, t_left, p_right, p_left = st
            row0 = prev if prev is not None and prev_t is not None and t - prev_t < rest_s else None
            for k, (_assign, played, penalty) in enumerate(compiled):
                # feasible at all (stretch_gap), and what each stroke pays for stretch and
                # speed; crossed arms (timing.toml [hand_cross]): a pair's two pieces with
                # the drops, one hand's piece against the other's last where the other
                # hand's own penalty would be (left hand first)
                ok, stretched = True, penalty
                hands = {is_right: piece for is_right, _m, piece, _i in played}
                if len(hands) == 2:
                    stretched = stretched + _crossed(timing, hands[False], hands[True], 0.0)
                if len(hands) == 1 and True in hands and t_left is not None:
                    stretched = stretched + _crossed(timing, p_left, hands[True], t - t_left)
                for is_right, _m, piece, i in played:
                    last, lp = (t_right, p_right) if is_right else (t_left, p_left)
                    ts = t + group.strokes[i].dt
                    eps = drums.TIME_EPS_S
                    if last is not None and ts - last < timing.stretch_gap(lp, piece) - eps:
                        ok = False
                    elif last is not None:  # at a stretch, at speed
                        stretched = stretched + drums.stroke_penalty(timing, lp, piece, ts - last)
                if len(hands) == 1 and False in hands and t_right is not None:
                    stretched = stretched + _crossed(timing, hands[False], p_right, t - t_right)
                row, tr, tl, total = row0, t_right, t_left, acc + stretched
                pr, pl = p_right, p_left
                for is_right, m, piece, i in played:
                    ts = t + group.strokes[i].dt
                    total += table[none_row if row is None else row][m]
                    row = m
                    if is_right:
                        tr, pr = ts, piece
                    else:
                        tl, pl = ts, piece
                if not ok:
                    continue
                if played:
                    np_, npt = row, t
                elif prev_t is not None and t - prev_t >= rest_s:
                    np_, npt = None, None
                else:
                    np_, npt = prev, prev_t
                if tr is not None and t - tr >= max_interval:
                    tr, pr = None, None
                if tl is not None and t - tl >= max_interval:
                    tl, pl = None, None
                new = (np_, npt, tr, tl, pr, pl)
                old = nxt.get(new)
                if old is None or total < old:
                    nxt[new] = total
                    back[new] = (st, k)
        if beam is not None and len(nxt) > beam:  # the beam: the least, in their order
            kept = keep_best(list(nxt.values()), beam)
            assert kept is not None
            states_in_order = list(nxt)
            nxt = {states_in_order[i]: nxt[states_in_order[i]] for i in kept}
        best = nxt
        backs.append(back)
    end = min(best, key=lambda s: best[s])
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
        r = (
            prev
            if prev is not None and prev_t is not None and group.time - prev_t < rest_s
            else None
        )
        per = [0.0] * len(group.strokes)
        for _is_right, m, _piece, i in played:
            per[i] = table[none_row if r is None else r][m]
            r = m
        assigns.append(assign)
        pers.append(tuple(per))
        states.append(cur)
        cur = prev_st
    return HandSolution(
        tuple(reversed(assigns)), tuple(reversed(pers)), tuple(reversed(states)), best[end]
    )


PIECES = list(HAND_PIECES)
ODD_COSTS = [-2.5, -1.0, 0.0, 0.1, 0.2, 0.5, 1.0, 1.25, 3.0, 9.0]


def _random_case(
    rng: random.Random, config: PlanConfig
) -> tuple[DrumCosts, Timing, HandState, list[HandGroup]]:
    costs, timing = config.costs, config.timing
    if rng.random() < 0.4:  # fractions and negatives: ties and rounding must match too
        table = tuple(
            tuple(rng.choice(ODD_COSTS) if rng.random() < 0.5 else float(rng.randint(0, 3))
                  for _ in range(len(costs.motions)))
            for _ in range(len(costs.motions) + 1)
        )  # fmt: skip
        costs = DrumCosts(costs.motions, table, rng.choice([1000.0, 0.0, 2.5, -3.0, 0.1]))
    if rng.random() < 0.3:  # zero, tiny and long intervals, no rest or a short one
        kinds = {
            k: MotionTiming(
                v.anticipation_s,
                v.min_anticipation_s,
                rng.choice([0.0, 0.03, 0.07, 0.2, v.min_interval_s]),
            )
            for k, v in timing.kinds.items()
        }
        moves = rng.choice([{}, timing.moves])  # no moves: every gap is min_interval_s
        timing = Timing(timing.reference_spb, rng.choice([0.0, 0.1, 1.5]), kinds, moves)
    if rng.random() < 0.5:  # the hand's stretch: none, or tight and costly or cheap
        floor = rng.choice([None, 0.0, 0.02, 0.05])
        timing = dataclasses.replace(
            timing,
            stretch_interval_s=floor,
            stretch_moves=rng.choice([{}, config.timing.stretch_moves]),
            stretch_penalty=rng.choice([0.0, 0.5, 150.0]),
        )
    if rng.random() < 0.5:  # the hand's speed tiers: none, the shipped ones, odd ones
        tiers = rng.choice([(), config.timing.speed_tiers, ((2.0, 0.5), (5.0, 3.0), (9.0, 0.1))])
        timing = dataclasses.replace(
            timing,
            speed_tiers=tiers,
            distances=rng.choice([{}, config.timing.distances]),
            speed_memory_s=rng.choice([math.inf, 0.2, 0.05]),
        )
    if rng.random() < 0.5:  # crossed arms: none, the shipped rule, odd windows and prices
        timing = dataclasses.replace(
            timing,
            cross_window_s=rng.choice([0.0, 0.05, 0.1, config.timing.cross_window_s]),
            cross_penalty=rng.choice([0.0, 0.5, 2.5, config.timing.cross_penalty]),
            cross_home=rng.choice([frozenset(), config.timing.cross_home]),
            cross_positions=rng.choice([{}, config.timing.cross_positions]),
        )
    state = drums.START
    if rng.random() < 0.3:  # a fixed state left by an earlier plan
        t_right = rng.choice([None, -0.02, -0.1])
        t_left = rng.choice([None, -0.01, -0.06])
        state = (
            rng.choice([None, rng.randrange(14)]),
            rng.choice([None, -0.05, -1.0]),
            t_right,
            t_left,
            None if t_right is None else rng.choice(PIECES),
            None if t_left is None else rng.choice(PIECES),
        )
    t = rng.choice([0.0, 3.0])
    groups = []
    for _ in range(rng.randint(0, 10)):
        t += rng.choice([0.0, 0.03, 0.0625, 0.07, 0.08, 0.125, 0.15, 0.25, 2.0])
        n = rng.choice([0, 1, 2, 2, 2])
        pieces = rng.sample(PIECES, n) if rng.random() < 0.8 else [rng.choice(PIECES)] * n
        dts = sorted(rng.choice([0.0, 0.0, 0.01, 0.025, 0.03]) for _ in pieces)
        if dts:
            dts[0] = 0.0
        groups.append(
            HandGroup(
                t,
                tuple(Stroke(p, rng.randint(0, 12), dt) for p, dt in zip(pieces, dts, strict=True)),
            )
        )
    return costs, timing, state, groups


def test_drum_solver_equals_the_plain_dp_on_random_input(config: PlanConfig) -> None:
    rng = random.Random(2024)
    for _ in range(600):
        costs, timing, state, groups = _random_case(rng, config)
        assert drums.solve(costs, timing, state, groups) == _reference_drums(
            costs, timing, state, groups
        )


def test_drum_solver_with_a_beam_equals_the_plain_dp_with_one(config: PlanConfig) -> None:
    """A beam that cuts (layers of more states than it keeps, ties among them) keeps the
    same states in the same order, so the result is the plain DP's with the same cut."""
    rng = random.Random(99)
    cut = 0
    for _ in range(300):
        costs, timing, state, groups = _random_case(rng, config)
        beam = rng.choice([1, 2, 3, 5, 8])
        got = drums.solve(costs, timing, state, groups, beam=beam)
        assert got == _reference_drums(costs, timing, state, groups, beam)
        cut += got != drums.solve(costs, timing, state, groups)
    assert cut > 10  # the beam did cut, and changed results, in many cases


def test_drum_solver_results_do_not_depend_on_earlier_calls(config: PlanConfig) -> None:
    """Compiled options are cached per configuration: another config in between
    (same stroke signatures, other tables) must not leak into the next result."""
    rng = random.Random(7)
    cases = [_random_case(rng, config) for _ in range(60)]
    first = [drums.solve(*case) for case in cases]
    again = [drums.solve(*case) for case in reversed(cases)]
    assert first == list(reversed(again))


def _reference_bass(
    state: bass.BassState,
    groups: Sequence[Sequence[bass.BassOption]],
    fingering: Fingering = bass.DEFAULT_FINGERING,
    gaps: Sequence[float] | None = None,
) -> bass.BassSolution:
    """The plain Viterbi with :func:`virja.plan.bass.transitions` per candidate."""
    best: dict[bass.BassState, float] = {state: 0.0}
    backs = []
    for gi, options in enumerate(groups):
        gap = math.inf if gaps is None else gaps[gi]
        nxt: dict[bass.BassState, float] = {}
        back: dict[bass.BassState, tuple[bass.BassState, int, float]] = {}
        for prev, acc in best.items():
            for k, opt in enumerate(options):
                for c, new in bass.transitions(prev, opt, fingering, gap):
                    if (old := nxt.get(new)) is None or acc + c < old:
                        nxt[new] = acc + c
                        back[new] = (prev, k, c)
        best = nxt
        backs.append(back)
    end = min(best, key=lambda s: best[s])
    choice, costs, states = [], [], []
    cur = end
    for back in reversed(backs):
        prev, k, c = back[cur]
        choice.append(k)
        costs.append(c)
        states.append(cur)
        cur = prev
    return bass.BassSolution(
        tuple(reversed(choice)), tuple(reversed(costs)), tuple(reversed(states)), best[end]
    )


def _random_chords(rng: random.Random, setup: BassSetup) -> list[list[int]]:
    """Up to 12 groups of 1-3 distinct in-range pitches, each high to low."""
    return [
        sorted(
            {bass.fold_into_range(setup, rng.randint(20, 80)) for _ in range(rng.randint(1, 3))},
            reverse=True,
        )
        for _ in range(rng.randint(0, 12))
    ]


def test_bass_solver_equals_the_plain_viterbi_on_random_input(config: PlanConfig) -> None:
    rng = random.Random(5)
    setup = config.bass
    for _ in range(300):
        groups = [bass.group_options(setup, pitches)[1] for pitches in _random_chords(rng, setup)]
        state = rng.choice([None, (0, 3, 2), (3, 12, 10), (1, 1, 1)])
        assert bass.solve(state, groups) == _reference_bass(state, groups)


def test_bass_solver_equals_the_plain_viterbi_with_fingerings_gaps_and_memoised_options(
    config: PlanConfig,
) -> None:
    """As the chain calls it: options from :func:`chord_options` (tuples, memoised per
    fingering), gaps that rush shifts, and fingerings with fractional costs, one after
    another (a memo kept for one fingering must not answer for another)."""
    rng = random.Random(11)
    setup = config.bass
    fingerings = [
        bass.DEFAULT_FINGERING,
        Fingering(shift_cost=0.3, shift_cost_per_fret=0.7, rushed_shift_cost=1.1),
        Fingering(span_frets=1, thumb_span_frets=4, position_cost_per_fret=0.15),
    ]
    for _ in range(300):
        fingering = rng.choice(fingerings)
        groups = [
            bass.chord_options(setup, tuple(pitches))[1] for pitches in _random_chords(rng, setup)
        ]
        gaps = [rng.choice([math.inf, 0.0, 0.03, 0.07, 0.2, 1.0]) for _ in groups]
        state = rng.choice([None, (0, 3, 2), (3, 12, 10), (1, 1, 1)])
        assert bass.solve(state, groups, fingering, gaps) == _reference_bass(
            state, groups, fingering, gaps
        )


def test_drum_solver_with_pins_equals_the_plain_dp(config: PlanConfig) -> None:
    """Live pins (``Stroke.pin``, ``Stroke.switch``: the other hand costs more) in the
    compiled options and the C kernel as in the plain DP's :func:`drums.transition`."""
    rng = random.Random(515)
    pinned = 0
    for _ in range(300):
        costs, timing, state, groups = _random_case(rng, config)
        groups = [
            HandGroup(
                g.time,
                tuple(
                    dataclasses.replace(
                        s,
                        pin=rng.choice([drums.LEFT, drums.RIGHT]),
                        switch=rng.choice([4.0, 34.0, 324.0, 2000.0]),
                    )
                    if rng.random() < 0.5
                    else s
                    for s in g.strokes
                ),
            )
            for g in groups
        ]
        pinned += any(s.pin for g in groups for s in g.strokes)
        assert drums.solve(costs, timing, state, groups) == _reference_drums(
            costs, timing, state, groups
        )
    assert pinned > 100
