"""`virja plan` on a MIDI file and on a pcap recording (virja.cli.cmd_plan)."""

from __future__ import annotations

import json
from pathlib import Path

import mido
import pytest

from virja.cli.main import main
from virja.plan.types import JSON_KEYS, PlannedNote
from virja.rmcp import wire
from virja.rmcp.pcap import PcapWriter


def _song(path: Path) -> Path:
    mf = mido.MidiFile(type=1)
    bass = mido.MidiTrack()
    mf.tracks.append(bass)
    bass.append(mido.MetaMessage("track_name", name="Bass"))
    bass.append(mido.Message("program_change", program=32, channel=0))
    for n in (29, 34, 16):
        bass.append(mido.Message("note_on", note=n, velocity=90, channel=0, time=0))
        bass.append(mido.Message("note_off", note=n, velocity=0, channel=0, time=480))
    drums = mido.MidiTrack()
    mf.tracks.append(drums)
    for i in range(4):
        drums.append(
            mido.Message("note_on", note=38, velocity=100, channel=9, time=0 if i == 0 else 120)
        )
        if i % 2 == 0:
            drums.append(mido.Message("note_on", note=51, velocity=100, channel=9, time=0))
    mf.save(path)
    return path


def test_json_lines_have_exactly_the_planned_note_keys(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    song = _song(tmp_path / "song.mid")
    assert main(["plan", str(song), "--json"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 9
    notes = [PlannedNote.from_json(json.loads(line)) for line in lines]
    assert all(tuple(json.loads(line)) == JSON_KEYS for line in lines)
    snare = [p for p in notes if p.piece == "snare"]
    assert {p.limb for p in snare} == {"left_hand"}
    bass = sorted((p for p in notes if p.performer == "bass"), key=lambda p: p.time)
    assert [(p.string, p.fret) for p in bass[:2]] == [("E", 1), ("A", 1)]


def test_table_and_summary_report_moved_notes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    song = _song(tmp_path / "song.mid")
    assert main(["plan", str(song)]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].startswith(f"{song}: ") and "-> drummer" in out  # the routing report first
    header = next(line for line in lines if line.startswith("time"))
    assert header.split()[:3] == ["time", "performer", "note"]
    assert "bass: 3 notes planned" in out
    assert "drums: 6 notes planned" in out
    assert "moved by octaves: 1; 16 -> 28" in out


def test_bad_config_is_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    song = _song(tmp_path / "song.mid")
    cfg = tmp_path / "c.toml"
    cfg.write_text('[plan]\nbass_tuning = "seven"\n')
    assert main(["plan", str(song), "--config", str(cfg)]) == 1
    err = capsys.readouterr().err
    assert "unknown bass tuning 'seven'" in err and "Traceback" not in err


def test_pcap_recording_is_planned_from_capture_times(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t0 = 1_700_000_000_000_000
    rec = tmp_path / "s.pcap"
    with PcapWriter.open(rec, local=("127.0.0.1", 50500)) as w:
        for i in range(4):  # snare sixteenths, each sent half a second ahead
            sound = t0 + 500_000 + i * 125_000
            d = wire.midi(2, i, sound, bytes([0x99, 38, 100]))
            w.write(bytes(d), ("127.0.0.1", 4000), time_us=sound - 500_000)
    assert main(["plan", str(rec), "--json"]) == 0
    notes = [PlannedNote.from_json(json.loads(x)) for x in capsys.readouterr().out.splitlines()]
    assert [p.limb for p in sorted(notes, key=lambda p: p.time)] == [
        "left_hand", "right_hand", "left_hand", "right_hand",
    ]  # fmt: skip
    assert all(not p.late and abs(p.impact - p.time) < 1e-3 for p in notes)


def test_plan_of_a_file_is_the_plan_render_draws(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`plan` goes through the same pipeline as render (virja.pipeline): the file's
    beats reach the planner, so in 6/8 (beats of an eighth) the leads are render's too."""
    take = Path(__file__).parents[1] / "data/gmd/drummer6_session1_3_rock_80_beat_6-8.mid"
    assert main(["plan", str(take), "--json"]) == 0
    planned = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    log = tmp_path / "render.jsonl"
    argv = ["render", str(take), "--out", str(tmp_path / "f.png"), "--at", "0.5"]
    assert main([*argv, "--size", "64x36", "--no-audio", "--plan-log", str(log)]) == 0
    drawn = [json.loads(line) for line in log.read_text().splitlines()]
    assert len(planned) == 147
    assert [{k: d[k] for k in JSON_KEYS} for d in drawn] == planned
