"""End to end on loopback: `virja send` -> `virja serve` (real sockets) -> plan log and
recording -> `virja replay` gives the same plan."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import mido
import pytest

from tests.conftest import save_midi
from virja.plan.types import LOG_KEYS
from virja.rmcp.pcap import read_capture

M = mido.Message
Meta = mido.MetaMessage
VIRJA = [sys.executable, "-m", "virja"]


def short_session(path: Path) -> Path:
    """Two beats at 120 bpm: bass eighths, snare + hi-hat with a snare sixteenth between, a piano."""
    conductor = [Meta("set_tempo", tempo=500_000, time=0)]
    bass = [
        Meta("track_name", name="Bass", time=0),
        M("program_change", channel=1, program=32, time=0),
    ]
    for i, n in enumerate([41, 46, 48, 41]):
        bass += [
            M("note_on", channel=1, note=n, velocity=90, time=0 if i == 0 else 0),
            M("note_off", channel=1, note=n, time=240),
        ]
    drums = []
    for _ in range(4):
        drums += [
            M("note_on", channel=9, note=38, velocity=100, time=0),
            M("note_on", channel=9, note=42, velocity=80, time=0),
        ]
        drums += [
            M("note_off", channel=9, note=38, time=120),
            M("note_off", channel=9, note=42, time=0),
        ]
        drums += [
            M("note_on", channel=9, note=38, velocity=70, time=0),
            M("note_off", channel=9, note=38, time=120),
        ]
    piano = [
        M("program_change", channel=0, program=0, time=0),
        M("note_on", channel=0, note=72, velocity=60, time=0),
        M("note_off", channel=0, note=72, time=480),
    ]
    return save_midi(path, [conductor, bass, drums, piano])


def test_send_serve_record_replay_give_one_plan(tmp_path: Path) -> None:
    mid = short_session(tmp_path / "s.mid")
    plan_live = tmp_path / "live.jsonl"
    pcap = tmp_path / "live.pcap"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    serve = subprocess.Popen(
        [
            *VIRJA,
            "serve",
            "--headless",
            "--quiet",
            "--listen",
            "127.0.0.1:0",
            "--plan-log",
            str(plan_live),
            "--record",
            str(pcap),
            "--duration",
            "6",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert serve.stdout is not None
        first = serve.stdout.readline()
        m = re.search(r"listening on 127\.0\.0\.1:(\d+)", first)
        assert m, first
        port = int(m.group(1))
        sent = subprocess.run(
            [*VIRJA, "send", str(mid), "--to", f"127.0.0.1:{port}", "--start-in", "0.8"],
            capture_output=True,
            text=True,
            timeout=30,
            env=env,
        )
        assert sent.returncode == 0, sent.stderr
        out, err = serve.communicate(timeout=30)
    finally:
        if serve.poll() is None:
            serve.kill()
    assert serve.returncode == 0, err
    assert "0 rejected" in out and "dropped on arrival, never planned: 0" in out, out
    assert "0 dropped by the scheduler" in out, out
    live = [json.loads(line) for line in plan_live.read_text().splitlines()]
    assert all(tuple(obj) == LOG_KEYS for obj in live)
    # times from the first datagram (the recording's first packet), session time beside
    first = min(d.time_us for d in read_capture(pcap, port=None).datagrams) / 1e6
    assert min(o["start"] for o in live) >= 0.0 and max(o["time"] for o in live) < 10.0
    for o in live:
        assert abs(o["session_time"] - o["time"] - first) < 2e-6
    # 4 bass notes, 16 drum notes (8 snare, 4 of them doubled by a hi-hat... all band notes)
    assert sorted(o["performer"] for o in live).count("bass") == 4
    assert sorted(o["performer"] for o in live).count("drums") == 12
    assert not any(o["late"] for o in live)
    for o in live:
        assert abs(o["impact"] - o["time"]) < 0.001
    cap = read_capture(pcap, port=port)
    assert len(cap.datagrams) > 16  # notes, note-offs, beats

    plan_replay = tmp_path / "replay.jsonl"
    rep = subprocess.run(
        [
            *VIRJA,
            "replay",
            str(pcap),
            "--port",
            str(port),
            "--headless",
            "--plan-log",
            str(plan_replay),
        ],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert rep.returncode == 0, rep.stderr
    replayed = [json.loads(line) for line in plan_replay.read_text().splitlines()]
    key = lambda o: (o["time"], o["performer"], o["note"])  # noqa: E731
    assert sorted(replayed, key=key) == sorted(live, key=key)


def test_replay_of_a_capture_without_rmcp_is_a_clear_error(tmp_path: Path) -> None:
    from virja.rmcp.pcap import PcapWriter

    p = tmp_path / "other.pcap"
    with PcapWriter.open(p, local=("127.0.0.1", 9999)) as w:
        w.write(b"hello", ("127.0.0.1", 1234), time_us=1)
    res = subprocess.run(
        [*VIRJA, "replay", str(p), "--headless"], capture_output=True, text=True, timeout=60
    )
    assert res.returncode == 1
    assert "no UDP datagrams to port 50500" in res.stderr
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize(
    "cmd",
    [
        ["render", "nope.mid", "--out", "x.mp4"],
        ["plan", "nope.mid"],
        ["replay", "nope.pcap", "--headless"],
    ],
)
def test_missing_input_is_a_one_line_error(tmp_path: Path, cmd: list[str]) -> None:
    res = subprocess.run([*VIRJA, *cmd], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert res.returncode != 0
    assert "Traceback" not in res.stderr
    assert "nope" in res.stderr
