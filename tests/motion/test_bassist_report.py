"""The bassist's figures in `virja motion-report` (virja.motion.bassist_report)."""

from __future__ import annotations

import json
from pathlib import Path

import mido
import numpy as np
import pytest

from tests.conftest import save_midi
from virja.cli.main import main
from virja.events import NoteOn
from virja.geometry import GEOMETRY
from virja.motion.band import BandAnimator
from virja.motion.bassist_report import _in_board, _in_body, measure_bassist
from virja.motion.metrics import measure
from virja.plan import plan_notes
from virja.tempo import ConstantTempo

WALK = (29, 33, 36, 38, 39, 38, 36, 33, 34, 38, 41, 44)


def _walk(tmp_path: Path, bpm: float) -> Path:
    msgs: list[mido.Message | mido.MetaMessage] = [
        mido.MetaMessage("track_name", name="Bass"),
        mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(bpm)),
    ]
    for n in WALK:
        msgs.append(mido.Message("note_on", note=n, velocity=96, channel=1, time=0))
        msgs.append(mido.Message("note_off", note=n, velocity=0, channel=1, time=440))
        msgs.append(mido.Message("note_off", note=n + 12, velocity=0, channel=1, time=40))
    return save_midi(tmp_path / f"walk{bpm:g}.mid", [msgs])


@pytest.mark.parametrize("bpm", [120.0, 300.0])
def test_a_walking_line_meets_the_targets(bpm: float) -> None:
    spb = 60.0 / bpm
    notes = [("bass", NoteOn(1.0 + i * spb, 1, n, 96)) for i, n in enumerate(WALK)]
    planned = plan_notes(notes, ConstantTempo(spb))  # type: ignore[arg-type]
    a = BandAnimator()
    for p in planned:
        a.add_planned(p)
    figs = measure_bassist(a, planned, measure(a, planned, fps=30.0, timing=False))
    assert figs is not None
    assert figs.notes == len(WALK)
    assert figs.contacts_over == 0 and figs.collision_frames == 0
    assert figs.side_share == 1.0
    assert figs.wrist_max <= 8.0 and figs.jump_max_m <= 0.15
    assert figs.torso_range_deg >= 3.0
    stopped = [p for p in planned if p.fret]
    assert figs.stopped == len(stopped) and figs.shifts <= len(stopped) // 3


def test_the_board_and_the_body_are_solid_and_the_strings_are_outside() -> None:
    b = GEOMETRY.bass
    on_string = b.string_point("D", 5)
    assert not _in_board(on_string[None], _animator())[0]
    behind = on_string - 0.015 * b.front
    assert _in_board(behind[None], _animator())[0]
    assert _in_body(b.body_centre[None], _animator())[0]
    beside = on_string + 0.2 * np.cross(b.axis, b.front)
    assert not _in_board(beside[None], _animator())[0]


def _animator() -> BandAnimator:
    return BandAnimator()


def test_motion_report_prints_the_bassists_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mid = _walk(tmp_path, 200.0)
    assert main(["motion-report", str(mid), "--fps", "30"]) == 0
    out = capsys.readouterr().out
    assert "bassist: 12 notes" in out
    assert "fretting hand on the correct side: 100.0 %" in out
    assert "hand shifts:" in out
    assert "MISS" not in out.split("bassist:")[1]
    err = capsys.readouterr().err
    assert main(["motion-report", str(mid), "--fps", "30", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["bass"]["figures"]["side_share"] == 1.0 and doc["bass"]["meets_targets"]
    del err


def test_motion_report_says_it_is_working_and_gives_verdicts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mid = _walk(tmp_path, 200.0)
    assert main(["motion-report", str(mid), "--fps", "30"]) == 0
    out, err = capsys.readouterr()
    assert "motion-report: measuring" in err and "motion-report: done in" in err
    continuity = next(line for line in out.splitlines() if line.startswith("continuity"))
    assert "[ok" in continuity or "[MISS" in continuity
    drummer = out.split("drummer:")[1].split("bassist:")[0].splitlines()[1:]
    assert drummer and all(line.rstrip().endswith(("ok", "MISS")) for line in drummer)
