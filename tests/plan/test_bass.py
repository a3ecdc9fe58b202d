"""The bassist's string/fret choice (virja.plan.bass)."""

from __future__ import annotations

import itertools
import random

from virja.plan import bass
from virja.plan.config import BassSetup, PlanConfig, load_plan_config

FOUR = BassSetup((("E", 28), ("A", 33), ("D", 38), ("G", 43)), 20, 4)


def test_paper_example_f_then_b_flat_goes_to_a_string_cost_1_not_5() -> None:
    groups = [
        bass.group_options(FOUR, [29])[1],  # F1: only E fret 1
        bass.group_options(FOUR, [34])[1],  # B-flat1: E fret 6 or A fret 1
    ]
    sol = bass.solve(None, groups)
    chosen = [groups[i][k] for i, k in enumerate(sol.choice)]
    assert chosen == [((0, 1),), ((1, 1),)]
    assert sol.total == 1.0
    assert bass.path_cost(None, [((0, 1),), ((0, 6),)]) == 5.0


def test_every_playable_position_is_listed() -> None:
    assert sorted(bass.positions(FOUR, 43)) == [(0, 15), (1, 10), (2, 5), (3, 0)]
    assert bass.positions(FOUR, 28) == [(0, 0)]
    assert bass.positions(FOUR, 63) == [(3, 20)]
    assert bass.positions(FOUR, 27) == []


def test_open_string_on_the_fingers_string_costs_0_and_leaves_the_hand() -> None:
    state = (1, 5)  # finger on A fret 5
    assert bass.transition(state, ((1, 0),)) == (0.0, (1, 5))
    assert bass.transition(state, ((3, 0),)) == (2.0, (1, 5))
    # the hand did not jump to fret 0: going back to fret 5 costs nothing
    assert bass.path_cost(state, [((1, 0),), ((1, 5),)]) == 0.0


def test_open_string_is_preferred_over_its_stopped_twin() -> None:
    # D2 after A1 fret 3 (C2): open D costs 2 (strings), A fret 5 costs 2 (frets);
    # G1 at E fret 3 then D2: open D costs 2, A fret 5 costs 3
    groups = [bass.group_options(FOUR, [31])[1], bass.group_options(FOUR, [38])[1]]
    sol = bass.solve(None, groups)
    assert groups[1][sol.choice[1]] == ((2, 0),)


def test_notes_out_of_range_are_moved_by_octaves() -> None:
    assert bass.fold_into_range(FOUR, 16) == 28
    assert bass.fold_into_range(FOUR, 27) == 39
    assert bass.fold_into_range(FOUR, 70) == 58
    assert bass.fold_into_range(FOUR, 40) == 40


def test_double_stop_on_two_strings_within_the_span() -> None:
    kept, options = bass.group_options(FOUR, [45, 40])
    assert kept == 2
    for (s1, f1), (s2, f2) in options:
        assert s1 != s2
        assert f1 == 0 or f2 == 0 or abs(f1 - f2) <= 4
    # F#1 and F1 are both playable only on the E string: no double stop, melody kept
    kept, options = bass.group_options(FOUR, [30, 29])
    assert kept == 1
    assert options == [((0, 2),)]


def test_five_string_and_high_c_tunings_from_config(tmp_path) -> None:  # type: ignore[no-untyped-def]
    cfg = tmp_path / "c.toml"
    cfg.write_text('[plan]\nbass_tuning = "six"\nbass_frets = 24\n')
    c: PlanConfig = load_plan_config(cfg)
    assert [n for n, _ in c.bass.strings] == ["B", "E", "A", "D", "G", "C"]
    assert c.bass.lowest == 23 and c.bass.highest == 48 + 24
    assert bass.positions(c.bass, 23) == [(0, 0)]


def _brute(state: bass.BassState, groups: list[list[bass.BassOption]]) -> float:
    return min(bass.path_cost(state, list(combo)) for combo in itertools.product(*groups))


def test_dp_is_optimal_against_brute_force_on_random_sequences() -> None:
    rng = random.Random(1234)
    for _ in range(150):
        n = rng.randint(1, 6)
        groups = []
        for _ in range(n):
            if rng.random() < 0.2:
                pitches = sorted(rng.sample(range(28, 64), 2), reverse=True)
            else:
                pitches = [rng.randint(28, 63)]
            groups.append(bass.group_options(FOUR, pitches)[1])
        state: bass.BassState = rng.choice([None, (rng.randrange(4), rng.randint(1, 12))])
        sol = bass.solve(state, groups)
        chosen = [groups[i][k] for i, k in enumerate(sol.choice)]
        assert abs(bass.path_cost(state, chosen) - sol.total) < 1e-9
        assert abs(sol.total - _brute(state, groups)) < 1e-9
        assert abs(sum(sol.costs) - sol.total) < 1e-9
