"""`virja serve --clock-server` estimates its offset from a `virja send` that answers clocks."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

from tests.cli.test_live_session import short_session

VIRJA = [sys.executable, "-m", "virja"]


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_serve_reports_the_offset_estimated_from_the_sender(tmp_path: Path) -> None:
    mid = short_session(tmp_path / "s.mid")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    clock_port = _free_port()
    serve = subprocess.Popen(
        [
            *VIRJA,
            "serve",
            "--headless",
            "--quiet",
            "--listen",
            "127.0.0.1:0",
            "--clock-server",
            f"127.0.0.1:{clock_port}",
            "--duration",
            "5",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    send = None
    try:
        assert serve.stdout is not None
        m = re.search(r":(\d+)", serve.stdout.readline())
        assert m
        port = int(m.group(1))
        send = subprocess.Popen(
            [
                *VIRJA,
                "send",
                str(mid),
                "--to",
                f"127.0.0.1:{port}",
                "--bind",
                f"127.0.0.1:{clock_port}",
                "--start-in",
                "2",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        out, err = serve.communicate(timeout=30)
        s_out, s_err = send.communicate(timeout=30)
    finally:
        for p in (serve, send):
            if p is not None and p.poll() is None:
                p.kill()
        time.sleep(0)
    assert serve.returncode == 0, err
    assert send.returncode == 0, s_err
    assert f"answering clock requests on 127.0.0.1:{clock_port}" in s_out
    m = re.search(r"answered (\d+) clock requests", s_out)
    assert m and int(m.group(1)) >= 2
    # both on one host's clock: the estimated offset is tiny
    m = re.search(r"clock offset: ([+-][0-9.]+) ms, delay ([0-9.]+) ms", out)
    assert m, out
    assert abs(float(m.group(1))) < 5.0
