"""`virja serve` stops cleanly on SIGTERM and SIGINT, and a SIGKILL leaves a readable recording."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from virja.clock import SessionClock
from virja.rmcp import wire
from virja.rmcp.pcap import read_capture

VIRJA = [sys.executable, "-m", "virja"]


def _start(tmp_path: Path, *extra: str) -> tuple[subprocess.Popen[str], int]:
    proc = subprocess.Popen(
        [*VIRJA, "serve", "--headless", "--quiet", "--listen", "127.0.0.1:0", *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    assert proc.stdout is not None
    line = proc.stdout.readline()
    m = re.search(r"listening on 127\.0\.0\.1:(\d+)", line)
    assert m, line
    return proc, int(m.group(1))


def _send_notes(port: int, n: int) -> list[bytes]:
    clock = SessionClock()
    sent = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
        for i in range(n):
            data = bytes(
                wire.midi(2, i, clock.now_us() + 400_000 + i * 100_000, bytes([0x99, 38, 90]))
            )
            tx.sendto(data, ("127.0.0.1", port))
            sent.append(data)
        tx.sendto(b"not rmcp at all", ("127.0.0.1", port))
        sent.append(b"not rmcp at all")
    return sent


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_stops_cleanly_with_a_summary(tmp_path: Path, sig: signal.Signals) -> None:
    plan = tmp_path / "plan.jsonl"
    proc, port = _start(tmp_path, "--plan-log", str(plan), "--duration", "60")
    try:
        _send_notes(port, 5)
        time.sleep(0.5)
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "virja serve: stopped" in out
    assert "datagrams: 6 received, 5 accepted" in out
    assert "too_short 1" in out  # 15 bytes: shorter than the 24-byte header
    assert (
        len(plan.read_text().splitlines()) == 5
    )  # planned notes logged (the rest flushed at stop)


def test_sigkill_leaves_a_readable_recording_of_what_arrived(tmp_path: Path) -> None:
    pcap = tmp_path / "rec.pcap"
    proc, port = _start(tmp_path, "--record", str(pcap), "--duration", "60")
    try:
        sent = _send_notes(port, 20)
        time.sleep(0.5)  # more than the 100 ms flush period
        proc.kill()
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    cap = read_capture(pcap, port=port)
    assert sorted(d.payload for d in cap.datagrams) == sorted(sent)
