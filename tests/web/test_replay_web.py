"""`virja replay --headless --web` plays a recording in real time to browsers only."""

from __future__ import annotations

import re
import subprocess
import time
from pathlib import Path

from websockets.sync.client import connect

from tests.cli.test_live_session import short_session
from tests.web.conftest import ENV, VIRJA, serve_web
from virja.web.frames import decode_frame


def test_a_recording_replays_to_a_browser_viewer(tmp_path: Path) -> None:
    pcap = tmp_path / "s.pcap"
    with serve_web("--record", str(pcap), "--duration", "4") as served:
        assert served.send(short_session(tmp_path / "s.mid")).returncode == 0
        served.proc.communicate(timeout=30)
    port = str(served.udp_port)
    rep = subprocess.Popen(
        [*VIRJA, "replay", str(pcap), "--port", port, "--headless", "--web", "127.0.0.1:0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
    )
    try:
        assert rep.stdout is not None
        url = None
        while url is None:
            line = rep.stdout.readline()
            assert line, rep.stderr.read() if rep.stderr else ""
            m = re.search(r"web viewer at http://(127\.0\.0\.1:\d+)/", line)
            url = m and m.group(1)
        times = []
        with connect(f"ws://{url}/ws", max_queue=None) as ws:
            deadline = time.monotonic() + 10
            while len(times) < 20 and time.monotonic() < deadline:
                msg = ws.recv(timeout=10)
                if isinstance(msg, bytes):
                    times.append(decode_frame(msg)[1])
        out, err = rep.communicate(timeout=30)
    finally:
        if rep.poll() is None:
            rep.kill()
    assert rep.returncode == 0, err
    assert len(times) == 20 and all(b > a for a, b in zip(times, times[1:], strict=False))
    # frames carry the recording's session time (its receive times), 1/30 s apart
    assert 0.02 < (times[-1] - times[0]) / 19 < 0.08
    assert "notes planned" in out
