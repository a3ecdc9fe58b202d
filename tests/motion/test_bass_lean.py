"""The upright bass leans with its player: about its endpin, a little, the hands with it."""

from __future__ import annotations

import numpy as np
import pytest

from tests.motion.helpers import bass
from virja.events import Beat
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.motion.bassist import CHEST
from virja.motion.clip import MotionLibrary
from virja.motion.metrics import contact_distance
from virja.plan.types import PlannedNote
from virja.render.scene import _bass_table, band_scene, static_scene

LINE = [("E", 3), ("A", 5), ("D", 7), ("G", 9), ("E", 0), ("A", 12), ("G", 5), ("D", 2)]


@pytest.fixture(scope="module")
def played(library: MotionLibrary) -> tuple[BandAnimator, list[PlannedNote]]:
    a = BandAnimator(library)
    for i in range(16):
        a.add_beat(Beat(0.5 * i, 0, i // 4 + 1, i % 4 + 1, 4, 500_000))
    notes = []
    for i, (s, f) in enumerate(LINE):
        # on the beat, where the weight is on one foot (off the beat it passes the centre)
        p = bass(s, f, 0.8 + 0.5 * i, 1.0 + 0.5 * i, velocity=110)
        a.add_planned(p)
        notes.append(p)
    return a, notes


def _angle_deg(m: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(m[:3, :3]) - 1) / 2, -1.0, 1.0))))


def test_the_bass_leans_a_little_about_its_endpin_and_stands_still_before_the_music(
    played: tuple[BandAnimator, list[PlannedNote]],
) -> None:
    a, _ = played
    endpin = a.geometry.bass.endpin
    assert np.allclose(a.pose(0.7).bass_transform, np.eye(4))  # before the first note
    poses = a.poses(np.arange(0.75, 4.75, 1 / 30))
    angles = [_angle_deg(p.bass_transform) for p in poses]
    assert 0.2 < max(angles) < 1.5  # visible, a few tenths of a degree
    for p in poses:
        assert np.allclose(bass_lean.apply(p.bass_transform, endpin), endpin)  # on the floor
    # it goes with the chest: the lean is the chest's move (across the bass) of the pose
    nut = a.geometry.bass.nut["G"]
    moves = np.array([bass_lean.apply(p.bass_transform, nut) - nut for p in poses])
    chest = np.array([p.bass.positions[CHEST] for p in poses])
    chest = chest - chest.mean(axis=0)
    assert np.corrcoef(moves[:, 0], chest[:, 0])[0, 1] > 0.9  # side to side with him
    # continuous: no frame-to-frame jump of the scroll over 5 mm at 30 fps
    assert float(np.linalg.norm(np.diff(moves, axis=0), axis=1).max()) < 0.005


def test_fingers_stay_on_the_leaning_strings_at_every_impact(
    played: tuple[BandAnimator, list[PlannedNote]],
) -> None:
    a, notes = played
    leaned = 0
    for p in notes:
        pluck, fretting = contact_distance(a, p, p.impact)  # against the leaned strings
        assert pluck < 0.002 and (fretting is None or fretting < 0.002), p
        pose = a.pose(p.impact)
        if p.fret:
            still = a.geometry.bass.string_point(str(p.string), p.fret)
            leaned += float(np.linalg.norm(pose.fretting_tip - still)) > 0.002
            # the stopping finger's tip is the fretting fingertip (it leans with the hand)
            tips = pose.bass_fingers[1:8:2, 1]
            assert float(np.linalg.norm(tips - pose.fretting_tip, axis=1).min()) < 1e-6
    assert leaned >= 2  # the lean moves the strings by more than the contact tolerance


def test_the_instrument_is_drawn_where_the_pose_leans_it(
    played: tuple[BandAnimator, list[PlannedNote]],
) -> None:
    a, _ = played
    pose = max(a.poses(np.arange(0.75, 4.75, 0.1)), key=lambda p: _angle_deg(p.bass_transform))
    still = band_scene(a.pose(0.0))
    moved = band_scene(pose)
    # the body, neck and fingerboard move with the lean (boxes: the waist, the fingerboard,
    # the bridge and the tailpiece, drawn after the footboards), and the stage no longer
    # carries them
    assert "box" in moved.models and len(static_scene().packed("box")) == 1  # the floor
    n = len(_bass_table(a.geometry)["box"][0])
    boxes_still = np.concatenate(still.models["box"])[-n:]
    boxes_moved = np.concatenate(moved.models["box"])[-n:]
    assert np.allclose(boxes_moved, pose.bass_transform @ boxes_still)
    assert not np.allclose(boxes_moved, boxes_still, atol=1e-3)


@pytest.mark.parametrize(("bpm", "half"), [(120, False), (150, False), (160, True), (300, True)])
def test_over_150_bpm_the_body_moves_in_half_time(
    library: MotionLibrary, bpm: int, half: bool
) -> None:
    """The weight and the dip go with every beat up to 150 bpm and with every other
    beat above it (a player at 300 bpm does not bob five times a second); the weight
    is still on a foot at a beat."""
    a = BandAnimator(library)
    spb = 60.0 / bpm
    for i in range(16):
        a.add_beat(Beat(spb * i, i // 4, i % 4 + 1, 4, 2, round(spb * 1e6)))
    t = spb * np.array([4.0, 4.5, 5.0, 5.5, 6.0])
    index, phase = a._body_pulse(t)
    if half:
        assert index.tolist() == [2, 2, 2, 2, 3] and np.allclose(phase, [0, 0.25, 0.5, 0.75, 0])
    else:
        assert index.tolist() == [4, 4, 5, 5, 6] and np.allclose(phase, [0, 0.5, 0, 0.5, 0])
