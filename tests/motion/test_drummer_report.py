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


# Windows of MMA jazz (tools/mma_jazz.py seed 1): drum notes of 0.75 s or less,
# shifted to start at 0.5 s, with a hi-hat change 35-49 ms after the note before
# (pedal 44 -> open 46, closed 42 -> open 46).  (time s, note, velocity)
JAZZ_HIHAT_WINDOWS = {
    "jazzcombo_180 14.95-15.70 s": (
        0.333,
        (
            (0.5396, 38, 67), (0.5517, 46, 67), (0.7705, 38, 72), (0.866, 44, 70),
            (0.8798, 36, 69), (0.9007, 46, 78), (1.0899, 42, 88), (1.1021, 44, 74),
            (1.201, 36, 74), (1.2062, 46, 77),
        ),
    ),
    "modernjazz_300 13.15-13.60 s": (
        0.2,
        (
            (0.5542, 44, 66), (0.5552, 51, 72), (0.649, 51, 67), (0.6542, 44, 78),
            (0.7031, 46, 77), (0.75, 44, 68), (0.7542, 51, 77), (0.8458, 51, 77),
            (0.8542, 44, 72), (0.9031, 46, 76),
        ),
    ),
    "bebop_300 13.25-13.45 s": (
        0.2,
        ((0.5469, 46, 70), (0.5531, 44, 87), (0.599, 53, 56), (0.6031, 42, 104), (0.6479, 46, 70)),
    ),
}  # fmt: skip


@pytest.mark.parametrize("window", sorted(JAZZ_HIHAT_WINDOWS))
def test_every_hihat_note_lands_on_its_state_in_mma_jazz(
    library: MotionLibrary, window: str
) -> None:
    """A note followed within lead_s by a change lands on its own state: the cymbals
    start to move only after its impact (issue 15, deliverable 4)."""
    beat_s, window_notes = JAZZ_HIHAT_WINDOWS[window]
    notes = [("drums", NoteOn(t, 9, n, v)) for t, n, v in window_notes]
    planned = plan_notes(notes, ConstantTempo(beat_s))  # type: ignore[arg-type]
    a = BandAnimator(library)
    for p in planned:
        a.add_planned(p)
    kit = default_config().kit
    fig = measure_drummer(a, planned, {n: d.articulation for n, d in kit.notes.items()}, fps=60)
    assert fig.hihat_notes >= 2
    assert fig.hihat_agreement == 1.0
