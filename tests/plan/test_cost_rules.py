"""motions/drum_costs.toml follows the rules written at its top, entry by entry.

The paper gave the snare's four numbers; every other entry (the paper's 15 x 14
and crash 2's rows and columns, issue 15) comes from a piece's position across
the kit and each hand's reach.  Recomputing them here catches a hand-edited
number that no rule gives, and shows that adding crash 2 changed none of the
paper's table.
"""

from __future__ import annotations

from virja.plan.config import PlanConfig
from virja.vocab import HAND_PIECES, HANDS, DrumStroke, MotionKey

# the header of motions/drum_costs.toml
POSITION = {
    "hihat": 0,
    "crash": 1,
    "snare": 1,
    "tom_high": 2,
    "tom_low": 3,
    "tom_floor": 4,
    "crash2": 4,
    "ride": 5,
}
REACH = {
    "left_hand": {
        "snare": 0,
        "crash": 0,
        "hihat": 1,
        "tom_high": 1,
        "tom_low": 2,
        "tom_floor": 4,
        "crash2": 4,
        "ride": 4,
    },
    "right_hand": {p: (1 if p == "snare" else 0) for p in POSITION},
}
TIME_KEEPING = ("hihat", "ride")
HOME_LEFT = ("snare", "crash", "tom_high")  # under the right hand crossed onto the hi-hat


def rule(prev: DrumStroke, nxt: DrumStroke) -> int:
    """The table entry the file's rules give for ``nxt`` after ``prev``."""
    reach = REACH[nxt.limb][nxt.piece]
    if prev.limb == nxt.limb:
        if prev.piece != nxt.piece:
            return max(1, abs(POSITION[prev.piece] - POSITION[nxt.piece])) + reach
        if nxt.piece in TIME_KEEPING:
            return 0 if nxt.limb == "right_hand" else 1 + reach
        return 2 + reach
    if prev.piece == nxt.piece:
        return reach
    left, right = (nxt, prev) if nxt.limb == "left_hand" else (prev, nxt)
    if right.piece == "hihat" and left.piece in HOME_LEFT:
        return reach
    crossed = POSITION[left.piece] > POSITION[right.piece]
    return reach + (3 if crossed else 0)


def _key(name: str) -> DrumStroke:
    key = MotionKey.parse(name)
    assert isinstance(key, DrumStroke)
    return key


def test_every_entry_after_a_motion_follows_the_rules(config: PlanConfig) -> None:
    c = config.costs
    assert set(POSITION) == set(HAND_PIECES)
    wrong = [
        (row, col, c.table[i][j], rule(_key(row), _key(col)))
        for i, row in enumerate(c.motions)
        for j, col in enumerate(c.motions)
        if c.table[i][j] != rule(_key(row), _key(col))
    ]
    assert wrong == []


def test_crash2_is_the_right_hands_crash(config: PlanConfig) -> None:
    c = config.costs
    none = c.table[c.none_row]
    assert none[c.index("crash2", "right_hand")] == 0
    assert none[c.index("crash2", "left_hand")] == 9  # across the body, like the ride
    ride_r = c.index("ride", "right_hand")
    # from the ride, the right hand's next-door crash is cheaper than crash 1 across the kit
    assert c.table[ride_r][c.index("crash2", "right_hand")] == 1
    assert c.table[ride_r][c.index("crash", "right_hand")] == 4
    # mirrored: the left hand over the hi-hat reaches crash 1 as cheaply
    hh_l = c.index("hihat", "left_hand")
    assert c.table[hh_l][c.index("crash", "left_hand")] == 1
    assert len(c.motions) == 2 * len(HAND_PIECES) == len(HANDS) * 8
