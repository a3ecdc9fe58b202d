"""The fretting forearm stays behind the neck for every string and fret of four-, five- and
six-string basses (issue 16: a six-string's high C above fret 10 took it across the
fingerboard's edge)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.motion.helpers import bass
from virja.geometry import ALL_BASS_STRINGS
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.motion.bassist import (
    BOARD_HALF_WIDTH_M,
    WRIST_OVER_MAX_M,
    forearm_over_board_m,
    neck_frame,
)
from virja.motion.clip import MotionLibrary
from virja.motion.metrics import contact_distance
from virja.motion.skeleton import SKELETON

TUNINGS = {
    "four": ("E", "A", "D", "G"),
    "five": ("B", "E", "A", "D", "G"),
    "six": ALL_BASS_STRINGS,
}
FRETS = range(1, 21)
GAP_S = 0.5  # one note every half second, each string up the neck and down again


@pytest.mark.parametrize("tuning", sorted(TUNINGS))
def test_the_forearm_stays_behind_the_neck_over_the_whole_grid(
    library: MotionLibrary, tuning: str
) -> None:
    strings = TUNINGS[tuning]
    a = BandAnimator(library)
    a.use_bass_strings(strings)
    grid = [(s, f) for s in strings for f in (*FRETS, *reversed(FRETS))]
    notes = []
    for i, (s, f) in enumerate(grid):
        p = bass(s, f, 1.0 + GAP_S * i - 0.3, 1.0 + GAP_S * i)
        a.add_planned(p)
        notes.append(p)
    # every impact, and three frames of each move between two notes
    impacts = np.array([p.impact for p in notes])
    between = (impacts[:-1, None] + GAP_S * np.array([0.25, 0.5, 0.75])[None]).ravel()
    times = np.sort(np.concatenate([impacts, between]))
    neck = neck_frame(a.geometry)
    worst: dict[tuple[str, int], float] = {}
    held = {float(p.impact): (p.string, p.fret) for p in notes}
    current = grid[0]
    for pose in a.poses(times):
        current = held.get(pose.time_s, current)
        own = bass_lean.apply(bass_lean.inverse(pose.bass_transform), pose.bass.positions)
        elbow = own[SKELETON.index("LeftForeArm")]
        wrist = own[SKELETON.index("LeftHand")]
        over = float(forearm_over_board_m(neck, elbow, wrist))
        worst[current] = max(worst.get(current, 0.0), over)
        # the elbow out behind the neck, on its E side
        assert neck.coords(elbow)[2] < -0.05, (tuning, current, pose.time_s)
        assert neck.coords(elbow)[1] > BOARD_HALF_WIDTH_M, (tuning, current, pose.time_s)
    # at most a wrist's edge over the board (the high C beyond fret 12: the hand reaches
    # across 4-5 cm of board from the E side), never the forearm across it
    bad = {k: round(v * 1e3, 1) for k, v in worst.items() if v > WRIST_OVER_MAX_M}
    assert not bad, f"forearm over the fingerboard (mm): {bad}"
    if tuning != "six":  # only the high C needs the wrist's edge over the board
        assert max(worst.values()) == 0.0
    # and the fingers still stop their strings
    for p in notes[:: max(len(notes) // 12, 1)]:
        _, fretting = contact_distance(a, p, p.impact)
        assert fretting is not None and fretting < 0.01, (p.string, p.fret)
