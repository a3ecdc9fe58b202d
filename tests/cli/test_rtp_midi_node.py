"""Against an independent RTP-MIDI implementation: node-rtpmidi (npm ``rtpmidi``,
installed by tools/setup.sh into tools/node), two peers at once, invites `virja serve
--rtp-midi`, syncs and sends notes; every note is planned once, recorded, replayed
to the same plan and drawn.  Skipped only where ``node`` is absent (CI installs it)."""

from __future__ import annotations

import json
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
NODE_DIR = ROOT / "tools" / "node"
VIRJA = [sys.executable, "-m", "virja"]
WAIT_S = 30.0

pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")

# drums on channel 10; the bassist on channel 1 (--bass-channel 1); a pianist's note
# on channel 2 nobody plays; one step through Session.sendMessage with a timestamp,
# the others bundled with running status; a SysEx that must be skipped
PLAN = [
    {"after_ms": 50, "messages": [[0x99, 36, 100]]},
    {"after_ms": 120, "messages": [[0x99, 38, 90], [0x99, 42, 70]], "deltas": [0, 0]},
    {"after_ms": 120, "messages": [[0x90, 40, 100], [0x91, 72, 60]], "deltas": [0, 0]},
    {
        "after_ms": 120,
        "messages": [[0xF0, 0x7D, 1, 2, 0xF7], [0x99, 38, 110], [0x80, 40, 0]],
        "deltas": [0, 0, 0],
    },
    {"after_ms": 150, "messages": [[0x90, 43, 90], [0x99, 46, 80]], "deltas": [0, 0]},
]
# (channel 1-16 as the plan log writes it, note)
BAND_NOTES = Counter([(10, 36), (10, 38), (10, 42), (1, 40), (10, 38), (1, 43), (10, 46)])


def free_even_port() -> int:
    for _ in range(200):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as a:
            a.bind(("127.0.0.1", 0))
            p = a.getsockname()[1] & ~1
        try:
            with (
                socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s0,
                socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s1,
            ):
                s0.bind(("127.0.0.1", p))
                s1.bind(("127.0.0.1", p + 1))
                return p
        except OSError:
            continue
    raise RuntimeError("no free even port pair")


def read_until(proc: subprocess.Popen[str], needle: str) -> str:
    """The first line of ``proc``'s output holding ``needle`` (bounded wait)."""
    assert proc.stdout is not None
    end = time.monotonic() + WAIT_S
    while time.monotonic() < end:
        line = proc.stdout.readline()
        if needle in line:
            return line
        if not line and proc.poll() is not None:
            break
    raise AssertionError(f"never printed {needle!r}")


def test_node_rtpmidi_notes_are_planned_once_recorded_replayed_and_drawn(tmp_path: Path) -> None:
    assert (NODE_DIR / "node_modules" / "rtpmidi").is_dir(), "run tools/setup.sh (npm ci)"
    plan_path, log, rec = tmp_path / "plan.json", tmp_path / "plan.jsonl", tmp_path / "s.pcap"
    # two peers at once: both sessions open together; the first plays its part
    # and stays (a last, unplayed note later), the second plays the same part after
    # it (a drummer cannot strike one kick twice at the same moment: the scheduler
    # would merge them)
    plan_path.write_text(json.dumps([*PLAN, {"after_ms": 3000, "messages": [[0x91, 72, 60]]}]))
    (tmp_path / "later.json").write_text(json.dumps([{**PLAN[0], "after_ms": 2500}, *PLAN[1:]]))
    serve = subprocess.Popen(
        [*VIRJA, "serve", "--headless", "--quiet", "--listen", "127.0.0.1:0", "--rtp-midi", "0"]
        + ["--plan-log", str(log), "--record", str(rec), "--bass-channel", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = read_until(serve, "RTP-MIDI session 'virja' on 127.0.0.1:")
        port = int(line.split("127.0.0.1:")[1].split()[0])
        local = [free_even_port()]
        while len(local) < 2:  # two peers at once, each on its own port pair
            p = free_even_port()
            if abs(p - local[0]) > 1:
                local.append(p)
        peers = [
            subprocess.Popen(
                ["node", str(NODE_DIR / "rtp_peer.js"), "127.0.0.1", str(port)]
                + [str(p), str(path)],
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            for p, path in zip(local, (plan_path, tmp_path / "later.json"), strict=True)
        ]
        outputs = [peer.communicate(timeout=WAIT_S) for peer in peers]
        for peer, (_o, e) in zip(peers, outputs, strict=True):
            assert peer.returncode == 0, e
        time.sleep(0.3)  # the BYs and the last plans
    finally:
        serve.send_signal(signal.SIGINT)
        out, err = serve.communicate(timeout=WAIT_S)
    assert serve.returncode == 0, err
    assert "Traceback" not in err
    assert "RTP-MIDI: " in out and "2 sessions opened, 2 ended" in out
    assert "2 SysEx skipped" in out and "RTP-MIDI dropped: none" in out

    sent = sorted(
        (json.loads(x) for o, _e in outputs for x in o.splitlines() if '"sent_us"' in x),
        key=lambda step: step["sent_us"],
    )
    assert len(sent) == 2 * len(PLAN) + 1
    planned = [json.loads(x) for x in log.read_text().splitlines()]
    both = BAND_NOTES + BAND_NOTES
    assert Counter((p["channel"], p["note"]) for p in planned) == both  # each once
    first_s, last_s = sent[0]["sent_us"] / 1e6, sent[-1]["sent_us"] / 1e6
    for p in planned:  # played at once: on arrival, the impact a short stroke later
        assert first_s - 0.01 <= p["session_time"] <= last_s + 1.0
        assert 0 < p["impact"] - p["time"] <= 0.1

    replay_log = tmp_path / "replay.jsonl"
    res = subprocess.run(
        [*VIRJA, "replay", str(rec), "--headless", "--plan-log", str(replay_log)]
        + ["--bass-channel", "1"],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert res.returncode == 0, res.stderr
    assert "RTP-MIDI on ports" in res.stdout
    assert [json.loads(x) for x in replay_log.read_text().splitlines()] == planned

    # drawn: the frame at the second snare's impact differs from the rest pose before it
    frames = tmp_path / "frames"
    res = subprocess.run(
        [*VIRJA, "replay", str(rec), "--out", str(frames), "--size", "160x90", "--fps", "10"]
        + ["--bass-channel", "1"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    from virja.render.images import decode_png_rgb

    t0 = min(p["start"] for p in planned)
    snare = [p for p in planned if p["note"] == 38][-1]
    at = round((snare["impact"] - t0) * 10)
    rest = decode_png_rgb((frames / "frame_00000.png").read_bytes())
    hit = decode_png_rgb((frames / f"frame_{at:05d}.png").read_bytes())
    changed = np.any(np.abs(rest.astype(int) - hit.astype(int)) > 24, axis=-1)
    assert changed.sum() > 20
