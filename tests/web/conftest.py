"""Helpers for the viewer's end-to-end tests: a demo excerpt and a running `virja serve --web`."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import mido

VIRJA = [sys.executable, "-m", "virja"]
DEMO = Path(__file__).resolve().parents[2] / "virja" / "demo" / "blues.mid"
ENV = dict(os.environ, PYTHONUNBUFFERED="1")


def demo_excerpt(path: Path, seconds: float) -> Path:
    """The bundled demo cut after ``seconds`` (tempo map and track names kept): real music,
    a short test.  Notes sounding at the cut end within two seconds."""
    mf = mido.MidiFile(str(DEMO))
    tempos = [(0, 500_000)]
    ticks = 0
    for msg in mf.tracks[0]:
        ticks += msg.time
        if msg.type == "set_tempo":
            tempos.append((ticks, msg.tempo))

    def seconds_at(tick: int) -> float:
        t, last_tick, tempo = 0.0, 0, 500_000
        for at, new in tempos:
            if at > tick:
                break
            t += mido.tick2second(at - last_tick, mf.ticks_per_beat, tempo)
            last_tick, tempo = at, new
        return t + mido.tick2second(tick - last_tick, mf.ticks_per_beat, tempo)

    out = mido.MidiFile(type=mf.type, ticks_per_beat=mf.ticks_per_beat)
    for track in mf.tracks:
        kept, ticks, prev = mido.MidiTrack(), 0, 0
        for msg in track:
            ticks += msg.time
            t = seconds_at(ticks)
            ending = msg.type == "note_off" or (msg.type == "note_on" and msg.velocity == 0)
            if msg.type == "end_of_track" or t > seconds + (2.0 if ending else 0.0):
                continue
            kept.append(msg.copy(time=ticks - prev))
            prev = ticks
        out.tracks.append(kept)
    out.save(str(path))
    return path


@dataclass
class Served:
    proc: subprocess.Popen[str]
    udp_port: int
    url: str

    def send(self, mid: Path) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [*VIRJA, "send", str(mid), "--to", f"127.0.0.1:{self.udp_port}", "--start-in", "0.5"],
            capture_output=True,
            text=True,
            timeout=90,
            env=ENV,
        )


@contextmanager
def serve_web(*extra: str) -> Iterator[Served]:
    proc = subprocess.Popen(
        [*VIRJA, "serve", "--headless", "--quiet", "--listen", "127.0.0.1:0"]
        + ["--web", "127.0.0.1:0", *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
    )
    try:
        assert proc.stdout is not None
        first, second = proc.stdout.readline(), proc.stdout.readline()
        m = re.search(r"listening on 127\.0\.0\.1:(\d+)", first)
        w = re.search(r"web viewer at (http://127\.0\.0\.1:\d+/)", second)
        assert m and w, first + second + (proc.stderr.read() if proc.stderr else "")
        yield Served(proc, int(m.group(1)), w.group(1))
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
