"""The follow camera: shots from the music, no shot too short, moves not jumps."""

from __future__ import annotations

import numpy as np
import pytest

from virja.render.camera import PRESETS, Camera
from virja.render.director import Shot, camera_at, lerp_camera, plan_shots
from virja.vocab import Performer


def groove(t0: float, t1: float) -> list[tuple[float, Performer, int]]:
    """Ride on every beat and walking bass at 120 bpm, a snare on 2 and 4."""
    notes: list[tuple[float, Performer, int]] = []
    for k in range(int((t1 - t0) * 2)):
        t = t0 + k * 0.5
        notes += [(t, "drums", 51), (t, "bass", 40)]
        if k % 2:
            notes.append((t, "drums", 38))
    return notes


def test_a_drum_fill_cuts_to_the_drummer() -> None:
    notes = groove(0.0, 30.0)
    fill = [(12.0 + i * 0.0625, "drums", 45 if i % 2 else 38) for i in range(32)]  # 2 s of 16ths
    shots = plan_shots(sorted(notes + fill), 0.0, 30.0)  # type: ignore[arg-type]
    during = [s for s in shots if s.start_s <= 13.0 < s.end_s]
    assert during and during[0].name == "drums"
    assert during[0].start_s <= 12.25 and during[0].end_s >= 14.0  # the fill, and a beat after


def test_shots_cover_the_span_and_none_is_too_short() -> None:
    shots = plan_shots(groove(0.0, 60.0), 0.0, 60.0, min_shot_s=2.0)
    assert shots[0].start_s == 0.0 and shots[-1].end_s == 60.0
    for a, b in zip(shots, shots[1:], strict=False):
        assert a.end_s == b.start_s and a.name != b.name
    assert all(s.end_s - s.start_s >= 2.0 for s in shots)
    assert {s.name for s in shots} >= {"front", "bass", "drums"}  # it goes round the band


def test_no_notes_is_the_front_preset() -> None:
    shots = plan_shots([], 0.0, 5.0)
    assert camera_at(shots, 2.0) == PRESETS["front"]


def test_a_cut_is_a_short_eased_move() -> None:
    shots = [Shot(0.0, 5.0, "front"), Shot(5.0, 10.0, "bass")]
    assert camera_at(shots, 4.99) == PRESETS["front"]
    assert camera_at(shots, 5.0) == PRESETS["front"]  # eased: starts where it was
    assert camera_at(shots, 5.6) == PRESETS["bass"]
    eyes = np.array([camera_at(shots, 5.0 + i / 30).eye for i in range(20)])
    steps = np.linalg.norm(np.diff(eyes, axis=0), axis=1)
    assert steps.max() < 0.25  # metres per frame at 30 fps: a move, not a jump


def test_yaw_goes_the_short_way_round() -> None:
    a = Camera(yaw_deg=350.0)
    b = Camera(yaw_deg=10.0)
    assert lerp_camera(a, b, 0.5).yaw_deg % 360 == pytest.approx(0.0)
