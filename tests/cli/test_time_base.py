"""One time base for users: seconds from the start of the input, for recordings too."""

from __future__ import annotations

import json
import logging
import re
from pathlib import Path

import pytest

from virja.cli.main import main
from virja.plan.types import JSON_KEYS, LOG_KEYS, PlannedNote
from virja.rmcp import wire
from virja.rmcp.pcap import PcapWriter

T0_US = 1_795_393_538_000_000  # a recording made in 2026: Unix time inside


def recording(path: Path) -> Path:
    """Snare sixteenths sent half a second ahead, the first packet at T0."""
    with PcapWriter.open(path, local=("127.0.0.1", 50500)) as w:
        for i in range(8):
            sound = T0_US + 500_000 + i * 125_000
            w.write(
                bytes(wire.midi(2, i, sound, bytes([0x99, 38, 100]))),
                ("127.0.0.1", 4000),
                time_us=sound - 500_000,
            )
    return path


def test_plan_of_a_recording_prints_seconds_from_its_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", str(recording(tmp_path / "s.pcap"))]) == 0
    out = capsys.readouterr().out
    assert "seconds from the recording's start" in out
    rows = [
        line.split()
        for line in out.splitlines()
        if line.split()[:2] and line.split()[1:2] == ["drums"]
    ]
    assert [float(r[0]) for r in rows[:2]] == [0.5, 0.625]
    others = [line for line in out.splitlines() if not line.startswith("times:")]
    assert "1795393538" not in "".join(others)  # only the header names session time


def test_render_at_is_seconds_from_the_recordings_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    rec = recording(tmp_path / "s.pcap")
    out_png = tmp_path / "x.png"
    assert main(["render", str(rec), "--out", str(out_png), "--at", "0.6", "--size", "64x36"]) == 0
    out = capsys.readouterr().out
    assert "from 0.60 s" in out and out_png.is_file()
    assert "outside the performance" not in caplog.text  # 0.6 s is in the middle of it
    assert main(["render", str(rec), "--out", str(out_png), "--at", "99", "--size", "64x36"]) == 0
    assert "--at 99.000 s is outside the performance" in caplog.text


def test_plan_json_of_a_recording_counts_from_its_first_packet(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", str(recording(tmp_path / "s.pcap")), "--json"]) == 0
    lines = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert tuple(lines[0]) == JSON_KEYS  # the contract's keys, no other
    assert [x["time"] for x in lines[:3]] == [0.5, 0.625, 0.75]
    assert all(x["impact"] >= x["start"] >= 0.0 for x in lines)


def test_replay_plan_log_counts_from_the_first_packet_and_keeps_session_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "p.jsonl"
    rec = recording(tmp_path / "s.pcap")
    assert main(["replay", str(rec), "--headless", "--plan-log", str(log)]) == 0
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    assert tuple(lines[0]) == LOG_KEYS
    assert [x["time"] for x in lines[:2]] == [0.5, 0.625]
    for x in lines:
        assert x["session_time"] == round(T0_US / 1e6 + x["time"], 6)
        back = PlannedNote.from_json(x)  # on the session clock again
        assert back.time == x["session_time"]
        assert back.impact == pytest.approx(T0_US / 1e6 + x["impact"], abs=1e-6)


def test_export_start_and_end_count_from_the_recordings_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = recording(tmp_path / "s.pcap")
    out = tmp_path / "s.musicxml"
    argv = ["export", str(rec), "--musicxml", str(out), "--start", "0.4", "--end", "0.9"]
    assert main(argv) == 0
    # a recording without BEATs: its bars count from its start (not from 1970: no hang)
    assert "exported 0.50 s (16 samples" in capsys.readouterr().out
    assert out.read_text().count("<measure ") == 2  # 0.5-0.875 s at 120 bpm: bars 1 and 2
    assert main([*argv[:-2], "--end", "0.3"]) == 1
    assert "--end 0.3 is before --start 0.4" in capsys.readouterr().err


def test_follow_camera_shots_are_said_from_the_recordings_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = recording(tmp_path / "s.pcap")
    argv = ["render", str(rec), "--out", str(tmp_path / "x.png"), "--at", "0.6"]
    assert main([*argv, "--size", "64x36", "--camera", "follow"]) == 0
    shots = [x for x in capsys.readouterr().out.splitlines() if x.startswith("follow camera")]
    assert shots and "1795393538" not in shots[0]
    assert re.search(r"shots: \w+ -?0\.\d-\d\.\d s", shots[0]), shots[0]


def test_a_dropped_note_is_logged_at_its_time_from_the_start(
    caplog: pytest.LogCaptureFixture,
) -> None:
    from virja.events import NoteOn
    from virja.plan.planner import OnlinePlanner
    from virja.routing import Router
    from virja.session import Performance

    t0 = T0_US / 1e6
    perf = Performance(router=Router(), planner=OnlinePlanner(), origin_s=t0)
    caplog.set_level(logging.INFO, logger="virja.plan")  # the chains log drops
    for note in (38, 42, 49, 51):  # four hand pieces at once: two hands drop two
        perf.feed(NoteOn(t0 + 1.0, 9, note, 100), now_s=t0)
    perf.finish()
    assert re.search(r"dropped drums note \d+ at 1\.000 s: three_pieces_at_once", caplog.text)


def test_serve_without_a_known_start_counts_from_the_first_motion() -> None:
    """Performance(origin_s=None) and no datagram marked it: the first note's start."""
    import io

    from virja.events import NoteOn
    from virja.plan.planner import OnlinePlanner
    from virja.routing import Router
    from virja.session import Performance

    t0 = T0_US / 1e6
    log = io.StringIO()
    perf = Performance(router=Router(), planner=OnlinePlanner(), plan_log=log, origin_s=None)
    perf.feed(NoteOn(t0 + 1.0, 9, 38, 100), now_s=t0)
    (p,) = perf.finish()
    line = json.loads(log.getvalue())
    assert perf.origin_s == p.start and line["start"] == 0.0
    assert line["session_time"] == round(p.time, 6)
    perf.mark_origin(0.0)  # known already: kept
    assert perf.origin_s == p.start


def test_gltf_of_a_recording_says_its_start_from_the_first_packet(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import struct

    rec = recording(tmp_path / "s.pcap")
    glb = tmp_path / "s.glb"
    assert main(["export", str(rec), "--gltf", str(glb), "--fps", "10"]) == 0
    data = glb.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    extras = json.loads(data[20 : 20 + length])["scenes"][0]["extras"]["virja"]
    assert extras["origin_s"] == T0_US / 1e6
    assert 0.0 <= extras["t0_s"] < 0.5  # the first packet or motion, before the first note
