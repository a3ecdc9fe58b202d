"""Crossed arms at short times (timing.toml [hand_cross]), a layer on top of the table."""

from __future__ import annotations

import pytest

from tests.plan.test_cost_rules import HOME_LEFT, POSITION
from virja import tomlconf
from virja.errors import ConfigError
from virja.events import NoteOn
from virja.plan import drums, plan_notes
from virja.plan.config import PlanConfig, parse_timing
from virja.resources import motions_file
from virja.tempo import ConstantTempo
from virja.vocab import Performer

# MMA's Swing1 at 300 bpm (tools/mma_jazz.py seed 1), its drum notes of the first
# 2.45 s less the congas (routed to nobody): ride 51, open hi-hat 46, side-stick 37,
# kick 35.  (time s, note, velocity)
SWING1_300 = (
    (0.001, 51, 56), (0.1312, 51, 52), (0.199, 51, 60), (0.201, 46, 58), (0.2031, 37, 77),
    (0.3302, 51, 60), (0.3969, 35, 70), (0.4, 51, 52), (0.401, 46, 52), (0.5323, 51, 61),
    (0.601, 46, 59), (0.6021, 35, 74), (0.6021, 37, 77), (0.7313, 51, 59), (0.8, 46, 53),
    (0.8, 35, 76), (0.9302, 46, 59), (0.9323, 51, 61), (0.999, 46, 56), (1.0, 35, 70),
    (1.1969, 37, 70), (1.2, 46, 54), (1.2, 35, 73), (1.3323, 51, 58), (1.6, 46, 60),
    (1.601, 37, 68), (1.7302, 46, 60), (1.7312, 51, 61), (1.799, 37, 67), (1.9302, 51, 55),
    (2.0, 51, 53), (2.1323, 51, 58), (2.2, 46, 56), (2.201, 51, 56), (2.2021, 35, 78),
    (2.3312, 46, 56), (2.4, 46, 53), (2.4, 37, 69), (2.4, 51, 57),
)  # fmt: skip


def test_a_stroke_that_crosses_the_arms_soon_after_the_other_hand_pays(
    config: PlanConfig,
) -> None:
    timing = config.timing
    pen = timing.cross_penalty
    assert pen > 30 + 9  # more than a 4.5 m/s move and any row of the table
    assert pen < timing.stretch_penalty  # less than a stretch or a drop
    assert drums.cross_penalty(timing, "ride", "hihat", 0.1) == pen
    assert drums.cross_penalty(timing, "ride", "snare", 0.0) == pen  # both in one group
    assert drums.cross_penalty(timing, "tom_floor", "tom_high", 0.2) == pen
    # the other arm has had time to get out of the way
    assert drums.cross_penalty(timing, "ride", "hihat", timing.cross_window_s + 0.01) == 0.0
    # not crossed: the left hand left of (or level with) the right
    assert drums.cross_penalty(timing, "hihat", "ride", 0.0) == 0.0
    assert drums.cross_penalty(timing, "crash", "snare", 0.0) == 0.0
    assert drums.cross_penalty(timing, "crash2", "tom_floor", 0.0) == 0.0
    # the home posture: the right hand over the left onto the hi-hat
    for left in ("snare", "crash", "tom_high"):
        assert drums.cross_penalty(timing, left, "hihat", 0.0) == 0.0
    assert drums.cross_penalty(timing, "tom_low", "hihat", 0.0) == pen


def test_the_rule_prices_one_hand_against_the_other_hands_last_stroke(
    config: PlanConfig,
) -> None:
    """The left hand to the ride 0.13 s after the right struck the hi-hat pays the
    crossing; the same stroke with the right hand's stroke long gone does not."""
    costs, timing = config.costs, config.timing
    group = drums.HandGroup(1.33, (drums.Stroke("ride", 1),))
    hh_r = costs.index("hihat", drums.RIGHT)
    soon: drums.HandState = (hh_r, 1.2, 1.2, 1.197, "hihat", "snare")
    late: drums.HandState = (hh_r, 1.2, None, 1.197, None, "snare")
    left = (drums.LEFT,)
    got_soon, got_late = (drums.transition(costs, timing, s, group, left) for s in (soon, late))
    assert got_soon is not None and got_late is not None
    assert got_soon[0] - got_late[0] == timing.cross_penalty


def test_swing1_at_300_keeps_the_right_hand_on_the_ride(config: PlanConfig) -> None:
    """MMA Swing1 at 300 bpm, read a beat ahead: no hand stroke leaves the arms crossed
    within the window of the other hand's last stroke (main at 8b7d05b sent the left
    hand to the ride at 1.332 s, 1.731 s and 1.930 s, 132-200 ms after the right hand's
    hi-hat or snare: the sticks met and the left wrist jumped 16 cm a frame), and every
    ride note is the right hand's."""
    seq: list[tuple[Performer, NoteOn]] = [("drums", NoteOn(t, 9, n, v)) for t, n, v in SWING1_300]
    planned = plan_notes(seq, ConstantTempo(0.2), config=config)
    hands = sorted(
        (p.impact, p.limb, p.piece) for p in planned if p.limb in (drums.LEFT, drums.RIGHT)
    )
    assert len(hands) >= 25  # the rest: hi-hat notes to the left foot
    assert [t for t, limb, piece in hands if piece == "ride" and limb == drums.LEFT] == []
    timing = config.timing
    last: dict[str, tuple[float, str]] = {}
    crossed = []
    for t, limb, piece in hands:
        other = drums.RIGHT if limb == drums.LEFT else drums.LEFT
        if other in last and t - last[other][0] <= timing.cross_window_s:
            left, right = (piece, last[other][1]) if limb == drums.LEFT else (last[other][1], piece)
            if timing.crossed(left, right):
                crossed.append(round(t, 3))
        last[limb] = (t, piece)
    assert crossed == []


@pytest.mark.parametrize(
    "bad",
    [
        {"window_s": -0.1},
        {"penalty": -1.0},
        {"positions": {"snare": 1}},
        {"home": {"hihat": ["cowbell"]}},
    ],
)
def test_hand_cross_table_errors(bad: dict[str, object]) -> None:
    path = motions_file("timing.toml", None)
    assert path is not None
    data = tomlconf.read(path)
    table = {**data["hand_cross"], **bad}
    with pytest.raises(ConfigError, match="hand_cross"):
        parse_timing({**data, "hand_cross": table})


def test_the_positions_are_those_of_the_cost_tables_header(config: PlanConfig) -> None:
    """The crossing uses the kit's left-to-right positions that set the table's '+3'."""
    assert config.timing.cross_positions == POSITION
    assert config.timing.cross_home == {("hihat", left) for left in HOME_LEFT}
