"""The drummer's hand choice (virja.plan.drums) and the kit as data."""

from __future__ import annotations

import dataclasses
import itertools
import random

import pytest

from virja.plan import drums
from virja.plan.config import PlanConfig, Timing
from virja.plan.drums import LEFT, RIGHT, HandGroup, Stroke
from virja.vocab import HAND_PIECES

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
    # the paper's 15 x 14 and crash 2's two motions (rows and columns)
    assert len(c.table) == 17 and all(len(r) == 16 for r in c.table)


def test_none_row_gives_each_piece_a_zero_cost_hand(config: PlanConfig) -> None:
    c = config.costs
    for piece in HAND_PIECES:
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
    # four snare strokes 6 ms apart, a hand's double takes 30 ms, 15 ms at a stretch
    # (a pressed double): one is dropped
    assert config.timing.get("snare").min_interval_s == 0.03
    assert config.timing.stretch_gap("snare", "snare") == 0.015
    groups = [HandGroup(i * 0.006, (SD,)) for i in range(4)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    hands = [a[0] for a in sol.assignments]
    assert hands.count(None) == 1
    played = [(g.time, h) for g, h in zip(groups, hands, strict=True) if h is not None]
    for (t1, h1), (t2, h2) in itertools.pairwise(played):
        assert h1 != h2 or t2 - t1 >= 0.015 - 1e-9
    # 12 ms apart: alternating hands, 24 ms per hand, is a pressed double at a stretch
    groups = [HandGroup(i * 0.012, (SD,)) for i in range(4)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert [a[0] for a in sol.assignments] == [LEFT, RIGHT, LEFT, RIGHT]
    assert sol.total == 2 + 2 * config.timing.stretch_penalty  # two stretched strokes


def test_the_stretch_is_only_taken_where_a_note_would_be_dropped(config: PlanConfig) -> None:
    # without the stretch the same plan (the paper's sixteenths at 120 bpm need none)
    plain = dataclasses.replace(config.timing, stretch_interval_s=None)
    groups = [HandGroup(i * 0.125, (SD,)) for i in range(4)]
    a = drums.solve(config.costs, config.timing, drums.START, groups)
    b = drums.solve(config.costs, plain, drums.START, groups)
    assert a == b
    # ride and high tom, then the tom again 30.6 ms later (GMD drummer2 session1 take 2,
    # 1.04 s): no hand can play it in the tom's 35 ms, the left hand does at a stretch
    tom = Stroke("tom_high", 2)
    groups = [HandGroup(0.0, (RD, tom)), HandGroup(0.0306, (tom,)), HandGroup(0.1, (RD,))]
    dropped = drums.solve(config.costs, plain, drums.START, groups).assignments
    assert None in [h for a in dropped for h in a]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert None not in [h for a in sol.assignments for h in a]


def test_moving_between_pieces_takes_longer_the_farther_they_are(config: PlanConfig) -> None:
    timing = config.timing
    assert timing.gap("snare", "snare") == 0.03  # a rebound double
    near, far = timing.gap("snare", "tom_high"), timing.gap("ride", "crash")
    assert 0.03 < near < timing.gap("snare", "hihat") < far
    assert 0.12 < far < 0.25  # 0.86 m of stick tip at a forearm's speed
    # ride then crash 100 ms later: the ride hand cannot get there, the other hand takes it
    groups = [HandGroup(0.0, (RD,)), HandGroup(0.1, (Stroke("crash", 3),))]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert sol.assignments == ((RIGHT,), (LEFT,))


def test_the_time_keeping_hand_keeps_the_hihat_and_ties_go_right(config: PlanConfig) -> None:
    """Closed hi-hat eighths at 280 bpm: one hand keeps time (it used to alternate)."""
    hh = Stroke("hihat", 1)
    groups = [HandGroup(i * 60 / 280 / 2, (hh,)) for i in range(16)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert {a[0] for a in sol.assignments} == {RIGHT}
    # and with the backbeat on the snare, the left hand takes the snare
    groups = [HandGroup(i * 0.25, (hh, SD) if i % 2 else (hh,)) for i in range(8)]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    assert all(a[0] == RIGHT for a in sol.assignments)
    assert all(a[1] == LEFT for a in sol.assignments if len(a) == 2)


def test_a_flam_in_one_group_takes_both_hands_each_at_its_time(config: PlanConfig) -> None:
    flam = HandGroup(1.0, (Stroke("snare", 0), Stroke("snare", 3, dt=0.02)))
    after = HandGroup(1.045, (SD,))  # 45 ms after the grace note, 25 ms after the main
    sol = drums.solve(config.costs, config.timing, drums.START, [flam, after])
    a0, a1 = sol.assignments
    assert None not in a0 and set(a0) == {LEFT, RIGHT}
    # the hand free soonest plays the next note: the one that played at 1.0, not 1.02
    assert a1[0] == a0[0]


def _objective(config: PlanConfig, groups: list[HandGroup], assigns: list[tuple]) -> float | None:  # type: ignore[type-arg]
    """The definition in docs/scheduler.md, written independently of the solver."""
    c, timing = config.costs, config.timing
    seq = []
    total = 0.0
    for g, a in zip(groups, assigns, strict=True):
        played = [(h, s) for s, h in zip(g.strokes, a, strict=True) if h is not None]
        if len({h for h, _ in played}) != len(played):
            return None
        for i, (s, h) in enumerate(zip(g.strokes, a, strict=True)):
            pair = len(g.strokes) == 2 and a[1 - i] is not None
            if h is None and pair and g.strokes[1 - i].piece == s.piece:
                total += timing.stretch_penalty  # a flam by one hand, at a stretch
                continue
            if h is None:
                total += c.drop_penalty + 9 - s.priority
        for h, s in sorted(played, key=lambda p: p[0] != LEFT):
            seq.append((g.time, h, s.piece))
        total += _crossing(timing, g.time, {h: s.piece for h, s in played}, seq)
    last: dict[str, tuple[float, str]] = {}
    for k, (t, h, piece) in enumerate(seq):
        if h in last and t - last[h][0] < timing.stretch_gap(last[h][1], piece) - 1e-9:
            return None
        if h in last:  # the hand at a stretch, at speed
            total += drums.stroke_penalty(timing, last[h][1], piece, t - last[h][0])
        last[h] = (t, piece)
        if k == 0 or t - seq[k - 1][0] >= timing.rest_s:
            row = c.none_row
        else:
            row = c.index(seq[k - 1][2], seq[k - 1][1])
        total += c.table[row][c.index(piece, h)]
    return total


def _crossing(timing: Timing, t: float, group: dict[str, str], seq: list) -> float:  # type: ignore[type-arg]
    """Crossed arms at short times (timing.toml [hand_cross]): the left hand's piece
    right of the right hand's after this group (``group``: hand -> piece, already in
    ``seq``), the other hand's stroke in the group or less than the window before."""
    if len(group) == 2:
        left, right, since = group[LEFT], group[RIGHT], 0.0
    elif len(group) == 1:
        ((hand, piece),) = group.items()
        other = RIGHT if hand == LEFT else LEFT
        before = [(tt, pc) for tt, h, pc in seq[:-1] if h == other]
        if not before:
            return 0.0
        since = t - before[-1][0]
        left, right = (piece, before[-1][1]) if hand == LEFT else (before[-1][1], piece)
    else:
        return 0.0
    pos = timing.cross_positions
    home = (right, left) in timing.cross_home
    if since < timing.cross_window_s - 1e-9 and not home and pos[left] > pos[right]:
        return timing.cross_penalty
    return 0.0


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
    pieces = {*HAND_PIECES, "kick"}
    for note in range(35, 82):
        dn = config.kit.lookup(note)
        assert dn is not None, note
        assert dn.piece in pieces | {"none"}
    # what no kit drummer plays goes to nobody
    for note in (39, 54, 56, *range(60, 82)):
        assert config.kit.notes[note].piece == "none", note
    for note in (27, 28, 29, 30, 32, 33, 34, 82, 83, 84, 85, 86, 87):  # GS/XG extras
        assert config.kit.notes[note].piece == "none", note


def test_the_groove_midi_datasets_td_pitches_are_kit_pieces(config: PlanConfig) -> None:
    """Roland TD-11 pitches as the Groove MIDI Dataset records them (its README)."""
    kit = config.kit.notes
    expect = {
        22: ("hihat", "closed_edge"),
        26: ("hihat", "open_edge"),
        40: ("snare", "rim"),
        50: ("tom_high", "rim"),
        47: ("tom_low", "rim"),
        58: ("tom_floor", "rim"),
        55: ("crash", "edge"),
        52: ("crash2", "edge"),  # the TD-11's second crash, on the right
        53: ("ride", "bell"),
        59: ("ride", "edge"),
    }
    for note, (piece, art) in expect.items():
        assert (kit[note].piece, kit[note].articulation) == (piece, art), note


def test_feet_and_folded_notes_follow_the_issue(config: PlanConfig) -> None:
    kit = config.kit
    assert kit.notes[35].limb == kit.notes[36].limb == "right_foot"
    assert kit.notes[44].limb == "left_foot" and kit.notes[44].piece == "hihat"
    assert kit.notes[37].piece == "snare" and kit.notes[37].articulation == "side_stick"
    assert kit.notes[55].piece == kit.notes[49].piece == "crash"  # crash 1, front left
    assert kit.notes[52].piece == kit.notes[57].piece == "crash2"  # crash 2, on the right
    assert kit.notes[57].priority == kit.notes[49].priority
    assert kit.notes[53].piece == "ride"
    assert kit.notes[38].priority < kit.notes[42].priority == kit.notes[51].priority
    assert kit.notes[51].priority < kit.notes[45].priority < kit.notes[49].priority
    assert kit.notes[49].priority < kit.notes[56].priority  # nobody's percussion last


def test_a_move_pays_for_the_speed_it_needs_by_tiers(config: PlanConfig) -> None:
    """[hand_speed]: distance between the strike points / time since the hand's stroke."""
    timing = config.timing
    far = timing.distances[("hihat", "snare")]
    assert 0.35 < far < 0.45
    pen = [drums.stroke_penalty(timing, "hihat", "snare", far / v) for v in (2.0, 3.5, 5, 6.5)]
    assert pen == [0.0, 4.0, 30.0, 150.0]
    # 10 m/s of tip, the wrist past 8 m/s: beyond a drummer's hands (round 9), dearer
    # than four drops, so the plan drops a note rather than make such a move
    top = drums.stroke_penalty(timing, "ride", "snare", 0.066)
    assert top == 5000.0
    assert top > 4 * (config.costs.drop_penalty + 9)
    # a rebound on one piece pays no speed, only the stretch below its min_interval_s
    assert drums.stroke_penalty(timing, "snare", "snare", 0.05) == 0.0
    assert drums.stroke_penalty(timing, "snare", "snare", 0.02) == timing.stretch_penalty
    # a stretch costs at least the stretch's penalty, whatever the speed tier says
    gap = timing.gap("snare", "tom_high")
    assert drums.stroke_penalty(timing, "snare", "tom_high", gap - 0.002) >= 150.0
    # a hand's stroke is remembered as long as a tier can charge it: memory_s
    # (and the crossing window, round 8: both 0.3 s)
    assert timing.max_gap == timing.speed_memory_s == timing.cross_window_s == 0.3
    assert 0.93 < timing.distances[("ride", "hihat")] < 0.96
    assert drums.stroke_penalty(timing, "ride", "hihat", 0.305) == 0.0  # 3.1 m/s, forgotten
    assert drums.stroke_penalty(timing, "ride", "hihat", 0.29) == 4.0  # 3.2 m/s
    assert drums.stroke_penalty(timing, "ride", "crash", 0.26) == 4.0  # 3.3 m/s


def test_at_300_bpm_the_hand_with_time_takes_the_snare_not_the_crossing_one(
    config: PlanConfig,
) -> None:
    """MMA Swing1 at 300 bpm: ride with the right, then snare and open hi-hat together
    66 ms after the ride.  With a flat stretch the right hand crossed 0.5 m from the ride
    to the snare in 66 ms; now the left hand (on the snare) takes it and the foot the
    hi-hat, or the left hand the hi-hat; the right hand stays on the ride."""
    ride, snare = Stroke("ride", 5), Stroke("snare", 6)
    hh = Stroke("hihat", 3, foot=True)
    groups = [
        HandGroup(0.0, (ride, snare)),
        HandGroup(0.130, (hh, Stroke("ride", 5, dt=0.002))),
        HandGroup(0.198, (snare, Stroke("hihat", 3, dt=0.001, foot=True))),
        HandGroup(0.330, (hh, ride)),
    ]
    sol = drums.solve(config.costs, config.timing, drums.START, groups)
    for g, a in zip(groups, sol.assignments, strict=True):
        for s, h in zip(g.strokes, a, strict=True):
            if s.piece == "snare":
                assert h == LEFT
            if s.piece == "ride":
                assert h == RIGHT
    flat = dataclasses.replace(config.timing, speed_tiers=())
    sol = drums.solve(config.costs, flat, drums.START, groups)
    assert sol.assignments[2][0] == RIGHT  # what the flat stretch chose: the crossing


def test_hand_speed_table_errors() -> None:
    from virja import tomlconf
    from virja.errors import ConfigError
    from virja.plan.config import parse_timing
    from virja.resources import motions_file

    path = motions_file("timing.toml", None)
    assert path is not None
    data = tomlconf.read(path)
    assert parse_timing(data).speed_tiers[0] == (3.0, 4.0)
    for bad in (
        {"speeds_m_s": [3.0, 2.0], "penalties": [1.0, 2.0]},
        {"speeds_m_s": [3.0], "penalties": [1.0, 2.0]},
        {"speeds_m_s": [0.0], "penalties": [1.0]},
        {"speeds_m_s": [3.0], "penalties": [-1.0]},
        {"speeds_m_s": [3.0], "penalties": [1.0], "memory_s": 0.0},
    ):
        with pytest.raises(ConfigError, match="hand_speed"):
            parse_timing({**data, "hand_speed": bad})


def test_hand_stretch_one_hand_doubles_are_hand_pieces_at_most_a_stretch() -> None:
    from virja import tomlconf
    from virja.errors import ConfigError
    from virja.plan.config import parse_timing
    from virja.resources import motions_file

    path = motions_file("timing.toml", None)
    assert path is not None
    data = tomlconf.read(path)
    timing = parse_timing(data)
    assert timing.one_hand_doubles == {"hihat", "ride", "crash", "crash2"}
    assert timing.one_hand_double_penalty == 0.0
    stretch = data["hand_stretch"]
    for bad in (
        {"one_hand_doubles": ["ride", "cowbell"]},
        {"one_hand_double_penalty": -1.0},
        {"one_hand_double_penalty": stretch["penalty"] + 1},
    ):
        with pytest.raises(ConfigError, match="hand_stretch"):
            parse_timing({**data, "hand_stretch": {**stretch, **bad}})
    plain = {k: v for k, v in stretch.items() if not k.startswith("one_hand")}
    assert parse_timing({**data, "hand_stretch": plain}).one_hand_doubles == frozenset()
