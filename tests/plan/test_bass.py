"""The bassist's string/fret choice (virja.plan.bass)."""

from __future__ import annotations

import itertools
import random

import pytest

from virja.errors import ConfigError
from virja.plan import bass
from virja.plan.bass_lines import LINES, fingering_table
from virja.plan.config import BassSetup, Fingering, PlanConfig, load_plan_config

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
    # E fret 6 instead: 5 frets of finger travel and a shift of the hand out of position 1
    fg = bass.DEFAULT_FINGERING
    assert bass.path_cost(None, [((0, 1),), ((0, 6),)]) > 5.0 + fg.shift_cost


def test_every_playable_position_is_listed() -> None:
    assert sorted(bass.positions(FOUR, 43)) == [(0, 15), (1, 10), (2, 5), (3, 0)]
    assert bass.positions(FOUR, 28) == [(0, 0)]
    assert bass.positions(FOUR, 63) == [(3, 20)]
    assert bass.positions(FOUR, 27) == []


def test_open_string_on_the_fingers_string_costs_0_and_leaves_the_hand() -> None:
    state = (1, 5, 5)  # first finger on A fret 5, hand in position 5
    assert bass.transition(state, ((1, 0),)) == (0.0, (1, 5, 5))
    assert bass.transition(state, ((3, 0),)) == (2.0, (1, 5, 5))
    # the hand did not jump to fret 0: going back to fret 5 costs only its position
    per = bass.DEFAULT_FINGERING.position_cost_per_fret
    assert bass.path_cost(state, [((1, 0),), ((1, 5),)]) == pytest.approx(4 * per)


def test_notes_inside_the_span_need_no_shift_outside_they_do() -> None:
    fg = Fingering()
    state = (1, 3, 3)  # position 3 covers frets 3-5 (1-2-4 fingering)
    for fret in (3, 4, 5):
        ((cost, after),) = bass.transitions(state, ((2, fret),), fg)
        assert after == (2, fret, 3)
        assert cost == pytest.approx(abs(fret - 3) + 1 + 2 * fg.position_cost_per_fret)
    # fret 6 needs the hand in position 4, 5 or 6: a shift, dearer by distance
    outs = bass.transitions(state, ((2, 6),), fg)
    assert [a[2] for _, a in outs if a] == [4, 5, 6]
    costs = [c for c, _ in outs]
    assert costs == sorted(costs) and costs[0] > 3 + 1 + fg.shift_cost


def test_thumb_position_spans_wider_than_the_lower_positions() -> None:
    fg = Fingering()
    assert bass.hand_positions(fg, 3, 5) == (3,)
    assert bass.hand_positions(fg, 3, 6) == (4, 5, 6)  # no position covers both: the top one
    assert 12 in bass.hand_positions(fg, 12, 15)
    assert fg.span(12) > fg.span(11)


def test_a_shift_without_time_for_it_costs_more() -> None:
    fg = Fingering()
    state = (0, 1, 1)
    slow = bass.transition(state, ((0, 10),), fg, gap_s=1.0)[0]
    fast = bass.transition(state, ((0, 10),), fg, gap_s=0.01)[0]
    assert fast == pytest.approx(slow + fg.rushed_shift_cost)
    # no shift, no hurry
    assert (
        bass.transition(state, ((1, 2),), fg, gap_s=0.01)[0]
        == bass.transition(state, ((1, 2),), fg)[0]
    )


@pytest.mark.parametrize("title", list(LINES))
def test_example_lines_stay_in_low_positions_with_few_shifts(title: str) -> None:
    notes, beats = LINES[title]
    rows = fingering_table(notes, beats)
    assert [r.note for r in rows] == list(notes)
    shifts = sum(r.shifted for r in rows)
    assert shifts <= len(rows) // 3, title  # a chromatic line shifts every third note
    top = max(r.fret for r in rows)
    # only the two-octave scale needs the upper fingerboard (G3 is the G string's 12th fret)
    assert top <= (12 if "two octaves" in title else 7), title
    for r in rows:  # every stopped note lies in its hand position's span
        if r.fret and r.position:
            assert r.position <= r.fret <= r.position + Fingering().span(r.position), r


def test_the_chromatic_octave_no_longer_climbs_one_string() -> None:
    notes, beats = LINES["chromatic C2-C3"]
    rows = fingering_table(notes, beats)
    assert len({r.string for r in rows}) >= 3
    assert max(r.fret for r in rows) <= 5


def test_fingering_table_in_bass_toml_and_its_errors(tmp_path) -> None:  # type: ignore[no-untyped-def]
    cfg = load_plan_config(None)
    assert cfg.bass.fingering.span_frets == 2
    with pytest.raises(ConfigError, match="must be >= 0"):
        Fingering(shift_cost=-1)
    from virja.plan.config import parse_fingering

    with pytest.raises(ConfigError, match="unknown key"):
        parse_fingering({"spann": 2}, "bass.toml")
    with pytest.raises(ConfigError, match="must be an integer"):
        parse_fingering({"span_frets": 2.5}, "bass.toml")


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


def _brute(state: bass.BassState, groups: list[list[bass.BassOption]], gaps: list[float]) -> float:
    return min(
        bass.path_cost(state, list(combo), gaps=gaps) for combo in itertools.product(*groups)
    )


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
        fret = rng.randint(1, 12)
        state: bass.BassState = rng.choice([None, (rng.randrange(4), fret, max(1, fret - 1))])
        gaps = [rng.choice([0.01, 0.1, 0.5]) for _ in groups]
        sol = bass.solve(state, groups, gaps=gaps)
        chosen = [groups[i][k] for i, k in enumerate(sol.choice)]
        assert abs(bass.path_cost(state, chosen, gaps=gaps) - sol.total) < 1e-9
        assert abs(sol.total - _brute(state, groups, gaps)) < 1e-9
        assert abs(sum(sol.costs) - sol.total) < 1e-9
