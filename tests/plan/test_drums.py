"""The drummer's hand choice (virja.plan.drums) and the kit as data."""

from __future__ import annotations

import itertools
import random

from virja.plan import drums
from virja.plan.config import PlanConfig
from virja.plan.drums import LEFT, RIGHT, HandGroup, Stroke

SD = Stroke("snare", 0)
RD = Stroke("ride", 1)


def test_table_reproduces_the_papers_snare_excerpt(config: PlanConfig) -> None:
    c = config.costs
    sr, sl = c.index("snare", RIGHT), c.index("snare", LEFT)
    assert c.table[sr][sr] == 3
    assert c.table[sr][sl] == 0
    assert c.table[sl][sr] == 1
    assert c.table[sl][sl] == 2
    assert c.table[c.none_row][sr] == 9
    assert c.table[c.none_row][sl] == 0
    assert len(c.table) == 15 and all(len(r) == 14 for r in c.table)


def test_none_row_gives_each_piece_a_zero_cost_hand(config: PlanConfig) -> None:
    c = config.costs
    for piece in ("snare", "hihat", "tom_high", "tom_low", "tom_floor", "ride", "crash"):
        row = c.table[c.none_row]
        assert min(row[c.index(piece, RIGHT)], row[c.index(piece, LEFT)]) == 0


def test_four_snare_sixteenths_from_rest_go_l_r_l_r_cost_2(config: PlanConfig) -> None:
    groups = [HandGroup(i * 0.125, (SD,)) for i in range(4)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert [a[0] for a in sol.assignments] == [LEFT, RIGHT, LEFT, RIGHT]
    assert sol.total == 2.0


def test_snare_sixteenths_with_ride_eighths_snare_left_ride_right(config: PlanConfig) -> None:
    """The paper's experiment 2 at 120 bpm."""
    groups = [
        HandGroup(0.0, (SD, RD)),
        HandGroup(0.125, (SD,)),
        HandGroup(0.25, (SD, RD)),
        HandGroup(0.375, (SD,)),
    ]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert sol.assignments == ((LEFT, RIGHT), (LEFT,), (LEFT, RIGHT), (LEFT,))


def test_a_hand_is_not_asked_to_strike_faster_than_its_minimum_interval(
    config: PlanConfig,
) -> None:
    # four snare strokes 30 ms apart, 70 ms per hand: two hands play three, one is dropped
    groups = [HandGroup(i * 0.03, (SD,)) for i in range(4)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    hands = [a[0] for a in sol.assignments]
    assert hands.count(None) == 1
    played = [(g.time, h) for g, h in zip(groups, hands, strict=True) if h is not None]
    for (t1, h1), (t2, h2) in itertools.pairwise(played):
        assert h1 != h2 or t2 - t1 >= 0.07


def _objective(config: PlanConfig, groups: list[HandGroup], assigns: list[tuple]) -> float | None:  # type: ignore[type-arg]
    """The definition in docs/scheduler.md, written independently of the solver."""
    c, timing = config.costs, config.timing
    seq = []
    total = 0.0
    for g, a in zip(groups, assigns, strict=True):
        played = [(h, s) for s, h in zip(g.strokes, a, strict=True) if h is not None]
        if len({h for h, _ in played}) != len(played):
            return None
        for s, h in zip(g.strokes, a, strict=True):
            if h is None:
                total += c.drop_penalty + 9 - s.priority
        for h, s in sorted(played, key=lambda p: p[0] != LEFT):
            seq.append((g.time, h, s.piece))
    last: dict[str, float] = {}
    for k, (t, h, piece) in enumerate(seq):
        if h in last and t - last[h] < timing.get(piece).min_interval_s - 1e-9:
            return None
        last[h] = t
        if k == 0 or t - seq[k - 1][0] >= timing.rest_s:
            row = c.none_row
        else:
            row = c.index(seq[k - 1][2], seq[k - 1][1])
        total += c.table[row][c.index(piece, h)]
    return total


PIECES = ["snare", "hihat", "tom_high", "tom_low", "tom_floor", "ride", "crash"]


def test_dp_is_optimal_against_brute_force_on_random_sequences(config: PlanConfig) -> None:
    rng = random.Random(99)
    for _ in range(120):
        n = rng.randint(1, 4)
        t = 0.0
        groups = []
        for _ in range(n):
            t += rng.choice([0.03, 0.0625, 0.0625, 0.125, 0.25, 2.0])
            k = rng.choice([1, 1, 2])
            pieces = rng.sample(PIECES, k)
            groups.append(HandGroup(t, tuple(Stroke(p, rng.randint(0, 5)) for p in pieces)))
        sol = drums.solve(config.costs, config.timing, drums.START, groups)
        best = min(
            v
            for combo in itertools.product(*(drums.options(g) for g in groups))
            if (v := _objective(config, groups, list(combo))) is not None
        )
        assert abs(sol.total - best) < 1e-9
        got = _objective(config, groups, list(sol.assignments))
        assert got is not None and abs(got - best) < 1e-9


def test_gm_map_covers_every_percussion_note_35_to_81(config: PlanConfig) -> None:
    pieces = {"kick", "snare", "tom_high", "tom_low", "tom_floor", "hihat", "ride", "crash"}
    for note in range(35, 82):
        dn = config.kit.lookup(note)
        assert dn is not None, note
        assert dn.piece in pieces


def test_feet_and_folded_notes_follow_the_issue(config: PlanConfig) -> None:
    kit = config.kit
    assert kit.notes[35].limb == kit.notes[36].limb == "right_foot"
    assert kit.notes[44].limb == "left_foot" and kit.notes[44].piece == "hihat"
    assert kit.notes[37].piece == "snare" and kit.notes[37].articulation == "rim"
    assert kit.notes[55].piece == kit.notes[52].piece == "crash"
    assert kit.notes[53].piece == "ride"
    assert kit.notes[38].priority < kit.notes[42].priority == kit.notes[51].priority
    assert kit.notes[51].priority < kit.notes[45].priority < kit.notes[49].priority
    assert kit.notes[49].priority < kit.notes[56].priority  # hand percussion last
