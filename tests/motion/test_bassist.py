"""The bassist's fingers, living body and vibrato (virja.motion.bassist)."""

from __future__ import annotations

import numpy as np

from tests.motion.helpers import bass
from virja import quat
from virja.events import Beat, NoteOff
from virja.geometry import GEOMETRY
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.metrics import contact_distance
from virja.motion.pose import LEFT_FINGER_BONES
from virja.motion.skeleton import SKELETON

B = GEOMETRY.bass


def _note(string: str, fret: int, impact: float, pos: int | None = None):  # type: ignore[no-untyped-def]
    p = bass(string, fret, impact - 0.2, impact)
    if pos is not None:
        from dataclasses import replace

        p = replace(p, motion=replace(p.motion, position=pos))
    return p


def _left_tips(a: BandAnimator, t: float) -> np.ndarray:
    bones = a.pose(t).bass_fingers
    return bones[1:8:2, 1]  # the four fingers' tips, index first


def test_the_stopping_finger_is_on_the_string_the_others_hover(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    p = _note("A", 4, 1.2, pos=2)  # position 2: index on 2, middle on 3, little on 4
    a.add_planned(p)
    tips = _left_tips(a, 1.2)
    target = B.string_point("A", 4)
    dist = np.linalg.norm(tips - target, axis=1)
    assert dist[3] < 0.01  # the little finger stops fret 4
    assert dist[:3].min() > 0.015  # index and middle lie a semitone and a tone lower
    # index over fret 2 (along the string, toward the nut)
    along = B.string_dir("A")
    assert float((tips[0] - tips[3]) @ along) < -0.05


def test_fingers_lift_at_the_note_off_and_for_an_open_string(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    p = _note("D", 3, 1.2, pos=3)
    a.add_planned(p)
    pressing = _left_tips(a, 1.5)
    a.note_off("bass", NoteOff(1.6, 0, p.note))
    lifted = _left_tips(a, 1.7)
    assert float(((lifted - pressing) @ B.front).min()) > 0.005  # all off the string
    b = BandAnimator(library)
    b.add_planned(_note("D", 3, 1.2, pos=3))
    b.add_planned(_note("G", 0, 1.7))  # an open string: the fingers lift, the G rings
    assert float(((_left_tips(b, 1.8) - _left_tips(b, 1.5)) @ B.front).min()) > 0.005
    assert b.pose(1.8).string_vibration["G"] > 0.0


def test_index_and_middle_pluck_in_turn(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    notes = [_note("A", 0, 1.0 + 0.5 * i) for i in range(4)]
    for p in notes:
        a.add_planned(p)
    plucking = []
    for p in notes:
        pose = a.pose(p.impact)
        right = pose.bass_fingers[LEFT_FINGER_BONES:]
        tips = right[[1, 3], 1]  # index tip, middle tip
        plucking.append(int(np.argmin(np.linalg.norm(tips - pose.plucking_tip, axis=1))))
    assert plucking == [0, 1, 0, 1]


def test_the_body_moves_with_the_beat_and_the_hands_stay_on_the_strings(
    library: MotionLibrary,
) -> None:
    a = BandAnimator(library)
    for i in range(12):
        a.add_beat(Beat(0.5 * i, i // 4, i % 4 + 1, 4, 0, 500_000))
    notes = [
        _note(s, f, 0.5 + 0.5 * i)
        for i, (s, f) in enumerate([("E", 1), ("A", 3), ("D", 5), ("G", 7)] * 2)
    ]
    for p in notes:
        a.add_planned(p)
    chest = SKELETON.index("Chest")
    rots = np.array([a.pose(float(t)).bass.rotations[chest] for t in np.arange(0.5, 4.5, 1 / 30)])
    spread = max(quat.angle_between(rots[i], rots).max() for i in range(0, len(rots), 5))
    assert np.degrees(spread) >= 3.0
    for p in notes:
        pluck, fret = contact_distance(a, p, p.impact)
        assert pluck < 0.01 and fret is not None and fret < 0.01


def test_vibrato_on_a_long_note_only(library: MotionLibrary) -> None:
    long_, short = BandAnimator(library), BandAnimator(library)
    long_.add_planned(_note("G", 5, 1.0))
    short.add_planned(_note("G", 5, 1.0))
    short.add_planned(_note("G", 7, 1.3))
    ts = np.arange(1.3, 1.9, 0.01)
    moves = [
        np.ptp([a.pose(float(t)).fretting_tip @ B.string_dir("G") for t in ts])
        for a in (long_, short)
    ]
    assert 0.002 < moves[0] < 0.01
    assert long_.pose(1.0).fretting_tip is not None
    assert np.linalg.norm(long_.pose(1.0).fretting_tip - B.string_point("G", 5)) < 0.01
