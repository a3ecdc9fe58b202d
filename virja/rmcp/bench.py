"""Reliability figures under hostile traffic (docs/reliability.md); never asserted in tests.

``python -m virja.rmcp.bench [--scale N]`` runs the live path in process -- the
receiver, the router, the planner, on the real clock, as ``virja serve`` does
per datagram -- under the issue's traffic, while another sender plays a real
bass line, and prints per traffic: the time spent per datagram (median, worst),
the growth of the process's peak RSS, and how many of the bass notes were
planned, and late.

- ``dense``: N x 400 drum datagrams (one note each, the notes 1 ms apart,
  1 s ahead), sent back to back;
- ``act_now``: N x 1,000 datagrams of 1,200 bytes each, full of note-ons
  marked IMMEDIATE, at 1,000 a second;
- ``senders``: N x 65,536 sender ids sending 16 program changes each, from
  40,000 source ports (memory; the state caps, not the budgets, are what holds);
- ``sigterm`` (not by default): a real ``virja serve`` flooded, then SIGTERM.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import time
from array import array
from collections.abc import Iterator
from dataclasses import dataclass

from virja.clock import SessionClock
from virja.plan.planner import OnlinePlanner
from virja.rmcp import wire
from virja.rmcp.receiver import Receiver, ReceiverConfig
from virja.routing import Router
from virja.session import Performance

DEBUG = False
SEQ_AT = 12  # the header's seq field
BASS_SENDER, ATTACKER = 7, 9
BASS_ADDR, ATTACKER_ADDR = ("127.0.0.1", 40001), ("127.0.0.1", 40002)


@dataclass
class Result:
    name: str
    scale: int
    budget: bool
    datagrams: int
    median_ms: float
    worst_ms: float
    tick_worst_ms: float
    rss_growth_mb: float
    rss_quarters: list[float]
    bass_sent: int
    bass_planned: int
    bass_late: int
    drops: dict[str, int]

    def line(self) -> str:
        top = ", ".join(f"{k} {v}" for k, v in sorted(self.drops.items(), key=lambda kv: -kv[1]))
        return (
            f"{self.name}{'' if self.budget else ' (no budget)'} x{self.scale}: {self.datagrams} datagrams, CPU per datagram median "
            f"{self.median_ms:.3f} ms, worst {self.worst_ms:.2f} ms (a tick's worst "
            f"{self.tick_worst_ms:.2f} ms); peak RSS +"
            f"{self.rss_growth_mb:.1f} MB (after each quarter of the attack: "
            f"{', '.join(f'{r:.0f}' for r in self.rss_quarters)} MB); bass {self.bass_planned}/{self.bass_sent} planned, "
            f"{self.bass_late} late; drops: {top or 'none'}"
        )


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _dense(scale: int, now_us: int, seq: Iterator[int]) -> Iterator[bytes]:
    t0 = now_us + 1_000_000
    for i in range(400 * scale):
        msg = bytes([0x99, 38 + i % 3, 100])
        yield bytes(wire.midi(ATTACKER, next(seq), t0 + i * 1000, msg))


def _act_now(n: int, now_us: int) -> list[bytes]:
    """``n`` copies of one 1,200-byte IMMEDIATE datagram of note-ons, seq 0..n-1 (built
    before the clock runs: the bench must not spend the traffic's time making it)."""
    notes = b"".join(bytes([0x99, 36 + i % 10, 100]) for i in range(392))
    one = bytearray(bytes(wire.midi(ATTACKER, 0, now_us, notes, flags=wire.Flags.IMMEDIATE)))
    out = []
    for seq in range(n):
        one[SEQ_AT : SEQ_AT + 4] = seq.to_bytes(4, "big")
        out.append(bytes(one))
    return out


def run(name: str, scale: int, *, budget: bool = True) -> Result:
    clock = SessionClock()
    receiver = Receiver(ReceiverConfig() if budget else ReceiverConfig(budget=None))
    perf = Performance(router=Router(), planner=OnlinePlanner())
    perf.keep_planned = True
    seqs = iter(range(1 << 30))
    bass_seq = iter(range(1 << 30))
    times = array("d")  # 8 bytes a datagram: the bench's own growth
    ticks = array("d")
    rss_at: list[float] = []  # RSS after each quarter of the attack (memory flat?)
    total = {"dense": 400 * scale, "act_now": 1000 * scale}.get(name, 65535 * 16 * scale)
    rss0 = _rss_mb()

    def handle(data: bytes, addr: tuple[str, int]) -> None:
        t = time.thread_time()
        now_us = clock.now_us()
        receiver.receive_datagram(data, addr, now_us=now_us)
        band = False
        for rec in receiver.drain_events():
            if perf.feed(rec.event, now_s=rec.arrival_s) is not None:
                band = True
        if band:
            perf.advance(now_us / 1e6)
        times.append(time.thread_time() - t)
        if DEBUG and times[-1] > 0.005:
            print(f"slow {times[-1] * 1e3:.1f} ms: {len(times)} {addr}")

    start_us = clock.now_us()
    handle(bytes(wire.midi(BASS_SENDER, next(bass_seq), start_us, bytes([0xC0, 33]))), BASS_ADDR)
    # the bass line: a note every 0.125 s, sent 0.5 s ahead, for the traffic's duration
    duration_s = 2.0 if name != "senders" else 1.0
    bass_times = [start_us + 500_000 + i * 125_000 for i in range(int(duration_s * 8))]
    attack: Iterator[bytes]
    if name == "dense":
        attack = iter(_dense(scale, start_us, seqs))
        per_s = 1e9  # back to back
    elif name == "act_now":
        attack = iter(_act_now(1000 * scale, start_us))
        per_s = 1000.0 * scale
    else:
        attack = iter(
            bytes(wire.midi(s, ch, start_us, bytes([0xC0 | ch, 33])))
            for s in range(65536 * scale)
            if s % 65536 != BASS_SENDER
            for ch in range(16)
        )
        per_s = 1e9
    sent_attack = 0
    next_bass = 0
    t_start = time.perf_counter()
    end = t_start + duration_s + 1.5
    done = False  # the attack sent in full
    while time.perf_counter() < end or not done:
        elapsed = time.perf_counter() - t_start
        now_us = clock.now_us()
        while next_bass < len(bass_times) and bass_times[next_bass] - 500_000 <= now_us:
            t_us = bass_times[next_bass]
            note = bytes([0x90, 40 + next_bass % 12, 90])
            handle(bytes(wire.midi(BASS_SENDER, next(bass_seq), t_us, note)), BASS_ADDR)
            next_bass += 1
        if sent_attack < elapsed * per_s:
            data = next(attack, None)
            done = data is None
            if data is not None:
                port = 20000 + sent_attack % 40000 if name == "senders" else ATTACKER_ADDR[1]
                handle(data, (ATTACKER_ADDR[0], port))
                sent_attack += 1
                if sent_attack % (total // 4) == 0:
                    rss_at.append(_rss_mb())
                if sent_attack % 64:
                    continue
        t = time.thread_time()
        perf.advance(clock.now_us() / 1e6)  # the tick
        ticks.append(time.thread_time() - t)
        time.sleep(0.0005)
    perf.finish()
    rss_end = _rss_mb()  # before the summary's own lists
    bass = [p for p in perf.planned if p.performer == "bass"]
    ms = [t * 1000 for t in times]
    drops = dict(receiver.stats.dropped)
    drops.update({k: v for k, v in perf.planner.report.summary().items() if k != "dropped"})
    return Result(
        name,
        scale,
        budget,
        len(times),
        statistics.median(ms),
        max(ms),
        max(ticks, default=0.0) * 1000,
        rss_end - rss0,
        rss_at,
        len(bass_times),
        len(bass),
        sum(p.late for p in bass),
        drops,
    )


def sigterm(scale: int) -> str:
    """A real ``virja serve --headless`` flooded (``scale`` x 400 dense datagrams and
    ``scale`` x 100 act-now ones over a second), then SIGTERM: seconds to exit, the
    exit status, whether the summary came."""
    import os
    import re
    import signal
    import socket
    import subprocess
    import sys

    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "virja",
            "serve",
            "--headless",
            "--quiet",
            "--listen",
            "127.0.0.1:0",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    assert proc.stdout is not None
    m = re.search(r":(\d+)", proc.stdout.readline())
    if m is None:
        proc.kill()
        return "sigterm: the daemon did not start"
    port = int(m.group(1))
    clock = SessionClock()
    now = clock.now_us()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
        for data in _dense(scale, now, iter(range(1 << 30))):
            tx.sendto(data, ("127.0.0.1", port))
        for i, data in enumerate(_act_now(100 * scale, now)):
            tx.sendto(data, ("127.0.0.1", port))
            if i % 10 == 0:
                time.sleep(0.1 / scale)
    t = time.perf_counter()
    proc.send_signal(signal.SIGTERM)
    out, _err = proc.communicate(timeout=600)
    took = time.perf_counter() - t
    return (
        f"sigterm x{scale}: exit {proc.returncode} in {took:.2f} s after SIGTERM, "
        f"summary {'printed' if 'virja serve: stopped' in out else 'MISSING'}"
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m virja.rmcp.bench", description=__doc__)
    p.add_argument("--scale", type=int, default=1, help="traffic multiplier (default 1)")
    p.add_argument(
        "--no-budget",
        action="store_true",
        help="receiver without per-peer budgets (planner bounds only)",
    )
    p.add_argument("traffic", nargs="*", default=["dense", "act_now", "senders"])
    args = p.parse_args(argv)
    for name in args.traffic:
        if name == "sigterm":
            print(sigterm(args.scale), flush=True)
        else:
            print(run(name, args.scale, budget=not args.no_budget).line(), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
