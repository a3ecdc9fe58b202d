"""The rules that play every kit note (issue 15): each on a neighbourhood of a real
Groove MIDI Dataset take (tests/data/gmd/README.md for the dataset; times are the
take's, in seconds) that dropped a note before the rule.

Read a beat ahead as `virja plan` reads a file; every note must be played at its
own time, by the limb the rule names.
"""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path

import pytest

from virja.cli.cmd_plan import _summary
from virja.events import NoteOn
from virja.input import midi_input
from virja.pipeline import PerformanceSettings, perform
from virja.plan import PlannedNote, PlanReport, plan_notes_with_report
from virja.plan.types import DroppedNote
from virja.tempo import ConstantTempo
from virja.vocab import Performer

T102 = ConstantTempo(60 / 102)


def _plan(notes: list[tuple[float, int, int]]) -> tuple[dict[float, PlannedNote], PlanReport]:
    seq: list[tuple[Performer, NoteOn]] = [("drums", NoteOn(t, 9, n, v)) for t, n, v in notes]
    planned, report = plan_notes_with_report(seq, T102)
    assert report.dropped == ()
    assert len(planned) == len(notes)
    for p in planned:
        assert not p.late and p.impact == p.time
    return {round(p.time, 4): p for p in planned}, report


def test_a_flam_the_other_hand_cannot_reach_is_a_double_by_one_hand() -> None:
    # as in drummer2 session1 take 2 at 4.12-4.16 s: a ride stroke, then two snare
    # notes 12 ms apart; the ride's hand cannot be on the snare 35 ms later, so one hand
    # plays both snare notes (the second on the stroke's rebound) and the ride is kept
    by, _ = _plan([(1.0, 51, 60), (1.035, 38, 72), (1.047, 38, 77)])
    assert by[1.035].limb == by[1.047].limb != by[1.0].limb
    assert by[1.047].cost == 0.0  # the rebound: no stroke of its own


def test_a_hihat_note_goes_to_the_foot_when_both_hands_are_busy() -> None:
    # drummer2 session1 take 2, 4.59-4.88 s: a soft hi-hat note 15 ms before a pedal
    # chick, between a high tom and the ride played together; the hands keep the tom
    # and the ride, the foot's chick takes the hi-hat note
    by, _ = _plan(
        [
            (4.5858, 48, 51),
            (4.5944, 36, 68),
            (4.5968, 48, 57),
            (4.5993, 36, 71),
            (4.6936, 51, 65),
            (4.712, 46, 7),
            (4.7267, 44, 127),
            (4.7377, 48, 77),
            (4.7402, 51, 57),
            (4.7549, 48, 85),
            (4.8603, 51, 77),
            (4.8799, 51, 75),
        ]
    )
    assert by[4.712].limb == "left_foot" and by[4.712].piece == "hihat"
    assert by[4.7377].limb != by[4.7402].limb
    assert by[4.7549].limb == by[4.7377].limb  # a pressed double 17 ms after


def test_one_stroke_heard_twice_across_the_grouping_window() -> None:
    # drummer2 session1 take 2, 8.24-8.28 s: two high-tom notes 7 ms apart fall in two
    # groups (the window starts at the ride 23 ms before): one stroke, heard twice
    by, _ = _plan(
        [(8.2427, 51, 56), (8.2488, 44, 127), (8.2562, 51, 51), (8.266, 48, 73), (8.2734, 48, 72)]
    )
    assert by[8.2734].limb == by[8.266].limb and by[8.2734].cost == 0.0


def test_the_hands_take_two_pieces_before_a_flam() -> None:
    # drummer1 session2 take 111, 19.75-19.78 s: snare (rim), ride, snare 25 ms apart:
    # one hand on the ride, the other plays both snare notes
    by, _ = _plan([(19.7485, 40, 91), (19.761, 51, 92), (19.7735, 38, 70)])
    assert by[19.7485].limb == by[19.7735].limb != by[19.761].limb
    assert by[19.761].piece == "ride"


def test_a_kick_double_faster_than_a_stroke_is_one_press() -> None:
    # drummer9 session1 take 21, 1.84-1.89 s: kick 38 then 76, 49 ms apart (a slide)
    by, report = _plan([(1.84, 36, 38), (1.889, 36, 76), (1.989, 38, 127)])
    assert by[1.889].limb == by[1.84].limb == "right_foot" and by[1.889].cost == 0.0
    assert dict(report.counts or ())["foot_double"] == 1


def test_plan_names_what_the_impossibility_is() -> None:
    drop = DroppedNote("drums", NoteOn(1.0, 9, 49, 10), "three_pieces_at_once")
    lines = _summary([], PlanReport(dropped=(drop,)))
    line = next(x for x in lines if x.startswith("dropped"))
    assert "drums three_pieces_at_once: 1 (three or more hand pieces within 30 ms" in line


DEMOS = sorted((Path(__file__).parents[2] / "virja" / "demo").glob("*.mid"))


@pytest.mark.parametrize("path", DEMOS, ids=[p.stem for p in DEMOS])
def test_the_demos_drop_no_kit_note_and_none_is_late(path: Path) -> None:
    """The bundled MMA sessions, read a beat ahead as `virja plan` reads them."""
    settings = PerformanceSettings()
    perf, planned = perform(settings, midi_input(path, settings.routing, 1.0))
    assert [d for d in perf.planner.report.dropped if d.performer == "drums"] == []
    assert not any(p.late for p in planned if p.performer == "drums")


@pytest.mark.skipif(shutil.which("mma") is None, reason="MMA (Debian package mma) not installed")
def test_generated_fast_swing_at_300_bpm_drops_no_kit_note(tmp_path: Path) -> None:
    """MMA's FastSwing at 300 bpm (tools/mma_jazz.py's song): 8 notes dropped as
    too_fast before the hand's stretch."""
    spec = importlib.util.spec_from_file_location(
        "mma_jazz", Path(__file__).parents[2] / "tools" / "mma_jazz.py"
    )
    assert spec is not None and spec.loader is not None
    mma_jazz = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mma_jazz)
    src = tmp_path / "fast.mma"
    src.write_text(mma_jazz.song("FastSwing", 300))
    out = tmp_path / "fast.mid"
    subprocess.run(["mma", str(src), "-f", str(out)], check=True, capture_output=True)
    settings = PerformanceSettings()
    perf, planned = perform(settings, midi_input(out, settings.routing, 1.0))
    drums = [p for p in planned if p.performer == "drums"]
    assert len(drums) > 100
    assert [d for d in perf.planner.report.dropped if d.performer == "drums"] == []
    assert not any(p.late for p in drums)
