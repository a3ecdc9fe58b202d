"""Where a stroke lands: impact poses turned about the stick's tip (virja.motion.drummer_landing)."""

from __future__ import annotations

import numpy as np

from virja.motion import drummer_clear
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.drummer_landing import (
    Arm,
    crosses_over,
    crossing,
    over,
    reached,
    stick_ends,
    tip,
    under,
)


def _row(a: BandAnimator, library: MotionLibrary, name: str) -> np.ndarray:
    """The impact row (grip, rotation, elbow) of clip ``name``, as the hands take it."""
    clip = library[name]
    pose = a.hands._clip_pose(clip, int(round(clip.impact_s * clip.fps)))
    return np.concatenate([pose.grip, pose.rot, pose.elbow])


def _apart(r: np.ndarray, other: np.ndarray) -> tuple[float, float, float]:
    a0, a1 = (e[None] for e in stick_ends(r))
    b0, b1 = (e[None] for e in stick_ends(other))
    pa, pb = drummer_clear.segment_closest(a0, a1, b0, b1)
    return float(np.linalg.norm(pa - pb)), float(pa[0, 1]), float(pb[0, 1])


def _setup(library: MotionLibrary) -> tuple[Arm, Arm, np.ndarray, np.ndarray]:
    a = BandAnimator(library)
    left = _row(a, library, "tom_high_left_hand")
    right = _row(a, library, "hihat_right_hand")
    return a.hands._arm["left_hand"], a.hands._arm["right_hand"], left, right


def test_the_clips_land_the_left_on_the_high_tom_into_the_right_stick_on_the_hihat(
    library: MotionLibrary,
) -> None:
    """The case the two rules are for: the two impact poses' sticks 1 mm apart."""
    _l_arm, _r_arm, left, right = _setup(library)
    assert _apart(left, right)[0] < drummer_clear.STICK_TRIGGER_M


def test_under_lowers_the_left_under_the_right_stick_its_tip_where_it_was(
    library: MotionLibrary,
) -> None:
    l_arm, _r_arm, left, right = _setup(library)
    got = under(l_arm, left, [right], 0.12)
    d, y_left, y_right = _apart(got, right)
    assert d >= drummer_clear.STICK_CLEAR_M and y_left < y_right
    assert np.allclose(tip(got), tip(left), atol=1e-9)  # contact unchanged
    assert l_arm.wrist(got)[1] < l_arm.wrist(left)[1] - 0.01
    # a right stroke that does not cross it changes nothing; nor one allowed no reach
    far = right.copy()
    far[:3] += np.array([0.5, 0.0, 0.0])
    assert under(l_arm, left, [far], 0.12) is left
    assert under(l_arm, left, [right], 0.0) is left


def test_over_raises_the_larger_lift_and_only_it(library: MotionLibrary) -> None:
    l_arm, r_arm, left, right = _setup(library)
    up = over(l_arm, left, 0.2, [(right, 0.1)], False, 0.12)
    d, y_left, y_right = _apart(up, right)
    assert d >= drummer_clear.STICK_CLEAR_M and y_left > y_right
    assert np.allclose(tip(up), tip(left), atol=1e-9)
    assert crosses_over(up, [right]) and not crosses_over(right, [up])
    # seen from the right's build the same pair leaves the right where it is
    assert over(r_arm, right, 0.1, [(left, 0.2)], True, 0.12) is right


def test_reached_turns_the_wrist_toward_a_far_piece_only_when_short_of_time(
    library: MotionLibrary,
) -> None:
    a = BandAnimator(library)
    arm = a.hands._arm["right_hand"]
    snare = _row(a, library, "snare_right_hand")
    crash = _row(a, library, "crash_right_hand")
    way = float(np.linalg.norm(arm.wrist(snare) - arm.wrist(crash)))
    assert reached(arm, snare, crash, way / 2.5 + 0.01, 1.0, 2.5, 0.12) is snare
    short = reached(arm, snare, crash, 0.1, 1.0, 2.5, 0.12)
    assert np.allclose(tip(short), tip(snare), atol=1e-9)
    moved = float(np.linalg.norm(arm.wrist(short) - arm.wrist(snare)))
    assert 0.01 < moved < 0.13  # max_m of the way square to the stick (a turn: an arc)
    nearer = np.linalg.norm(arm.wrist(short) - arm.wrist(crash))
    assert nearer < way


def test_a_right_stroke_on_the_left_s_own_tom_does_not_cross_it(library: MotionLibrary) -> None:
    """Crossed over the left's hand (the right on the hi-hat) counts; the right's tip
    meeting the left's on the tom both play does not (the left is not under it)."""
    a = BandAnimator(library)
    left = _row(a, library, "tom_high_left_hand")
    hihat = _row(a, library, "hihat_right_hand")
    tom = _row(a, library, "tom_high_right_hand")
    assert len(crossing(left, [hihat])) == 1
    assert crossing(left, [tom]) == []


def test_under_goes_lower_by_the_wrist_s_rise_as_far_as_the_reach_allows(
    library: MotionLibrary,
) -> None:
    l_arm, _r_arm, left, right = _setup(library)
    base = under(l_arm, left, [right], 0.12)
    deeper = under(l_arm, left, [right], 0.12, extra_m=0.03)
    assert l_arm.wrist(deeper)[1] < l_arm.wrist(base)[1] - 0.02
    assert _apart(deeper, right)[0] >= drummer_clear.STICK_CLEAR_M + 0.03 - 1e-9
    assert np.allclose(tip(deeper), tip(left), atol=1e-9)
    # more than the reach: the least that clears the stick, not nothing
    assert under(l_arm, left, [right], 0.12, extra_m=1.0) is not left
