"""The drummer's motion figures (virja.motion.drummer_report) and `motion-report --json`."""

from __future__ import annotations

import json
from pathlib import Path

import mido
import numpy as np
import pytest

from tests.conftest import save_midi
from virja.cli.main import main
from virja.events import NoteOn
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.drummer_report import _runs, _segment_distance, measure_drummer
from virja.plan import default_config, plan_notes
from virja.tempo import ConstantTempo

M = mido.Message
Meta = mido.MetaMessage


def test_runs_counts_each_stretch_of_touching_frames_once() -> None:
    assert _runs(np.array([], dtype=bool)) == 0
    assert _runs(np.array([0, 1, 1, 0, 1, 0, 0, 1], dtype=bool)) == 3
    assert _runs(np.array([1, 1, 1], dtype=bool)) == 1


def test_segment_distance_against_known_cases() -> None:
    p0, p1 = np.array([[0.0, 0, 0]] * 3), np.array([[1.0, 0, 0]] * 3)
    q0 = np.array([[0.5, 1, 0], [2.0, 0, 0], [0.5, -1, 1]])
    q1 = np.array([[0.5, 2, 0], [3.0, 0, 0], [0.5, 1, 1]])
    d = _segment_distance(p0, p1, q0, q1)
    assert np.allclose(d, [1.0, 1.0, 1.0])


def test_hihat_agreement_and_speeds_on_a_groove(library: MotionLibrary) -> None:
    """Closed hi-hat eighths with kick and snare: every figure is measured, finite."""
    notes = []
    for i in range(8):
        notes.append(("drums", NoteOn(1.0 + 0.25 * i, 9, 42, 80)))
        if i % 4 == 0:
            notes.append(("drums", NoteOn(1.0 + 0.25 * i, 9, 36, 100)))
        if i % 4 == 2:
            notes.append(("drums", NoteOn(1.0 + 0.25 * i, 9, 38, 100)))
    planned = plan_notes(notes, ConstantTempo(0.5))  # type: ignore[arg-type]
    a = BandAnimator(library)
    for p in planned:
        a.add_planned(p)
    kit = default_config().kit
    fig = measure_drummer(a, planned, {n: d.articulation for n, d in kit.notes.items()}, fps=60)
    assert fig.hihat_notes == 8
    assert fig.hihat_agreement is not None and 0.0 <= fig.hihat_agreement <= 1.0
    assert 0.0 < fig.wrist_speed_p99 <= fig.wrist_speed_max < 50.0
    assert 0.0 < fig.hand_jump_30fps_m < 1.0
    assert fig.torso_range_deg >= 0.0
    assert set(fig.collisions) >= {"stick-stick", "stick-snare", "stick-ride", "leg-snare"}
    out = fig.to_json()
    assert json.loads(json.dumps(out)) == out


def test_crash2_accents_over_a_ride_pattern_touch_nothing(library: MotionLibrary) -> None:
    """Crash 2 hangs over the low tom beside the ride: the right hand going ride ->
    crash 2 -> low tom -> ride strikes each and passes under none of them."""
    notes = []
    for i in range(16):
        t = 1.0 + 0.25 * i
        if i % 8 == 0:
            notes += [("drums", NoteOn(t, 9, 57, 110)), ("drums", NoteOn(t, 9, 36, 100))]
        elif i % 8 == 1:
            notes.append(("drums", NoteOn(t, 9, 45, 90)))  # low tom, under crash 2's side
        else:
            notes.append(("drums", NoteOn(t, 9, 51, 80)))
    planned = plan_notes(notes, ConstantTempo(0.5))  # type: ignore[arg-type]
    crash2 = [p for p in planned if p.note == 57]
    assert len(crash2) == 2 and {(p.piece, p.limb) for p in crash2} == {("crash2", "right_hand")}
    a = BandAnimator(library)
    for p in planned:
        a.add_planned(p)
    kit = default_config().kit
    fig = measure_drummer(a, planned, {n: d.articulation for n, d in kit.notes.items()}, fps=120)
    assert {k: fig.collisions[k] for k in ("stick-crash2", "stick-ride", "stick-tom_low")} == {
        "stick-crash2": 0,
        "stick-ride": 0,
        "stick-tom_low": 0,
    }


def test_motion_report_json_gives_every_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    conductor = [Meta("set_tempo", tempo=500_000, time=0)]
    drums = []
    for note in (42, 38, 42, 63, 44, 46):
        drums += [
            M("note_on", channel=9, note=note, velocity=90, time=240),
            M("note_off", channel=9, note=note, time=0),
        ]
    path = save_midi(tmp_path / "g.mid", [conductor, drums])
    assert main(["motion-report", str(path), "--json", "--fps", "30"]) == 0
    doc = json.loads(capsys.readouterr().out)
    d = doc["drums"]
    for key in (
        "contact_max_mm",
        "timing_max_ms",
        "wrist_speed_p99_m_s",
        "wrist_speed_max_m_s",
        "hand_jump_30fps_m",
        "torso_range_deg",
        "collisions",
        "hihat_agreement",
        "dropped",
        "routed_to_nobody",
    ):
        assert key in d, key
    assert d["notes"] == 5 and d["routed_to_nobody"] == {"Open Hi Conga": 1}
    assert d["contact_max_mm"] < 10.0
    assert d["dropped"] == {}


def test_an_open_hihat_at_the_instant_of_the_pedal_is_counted_apart(
    library: MotionLibrary,
) -> None:
    """MMA's swing writes the open hi-hat (46) at the instant of the pedal (44): no
    pair of cymbals is both; those two notes are counted apart, the rest agree."""
    notes = [("drums", NoteOn(1.0 + 0.5 * i, 9, 42, 80)) for i in range(4)]
    notes += [("drums", NoteOn(3.0, 9, 46, 80)), ("drums", NoteOn(3.0, 9, 44, 70))]
    planned = plan_notes(notes, ConstantTempo(0.5))  # type: ignore[arg-type]
    a = BandAnimator(library)
    for p in planned:
        a.add_planned(p)
    kit = default_config().kit
    fig = measure_drummer(a, planned, {n: d.articulation for n, d in kit.notes.items()}, fps=60)
    assert fig.hihat_contradictory == 2
    assert fig.hihat_notes == 4 and fig.hihat_agreement == 1.0
    assert fig.to_json()["hihat_contradictory"] == 2
