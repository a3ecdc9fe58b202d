"""Flood the daemon: N RMCP datagrams a second for S seconds on loopback; is anything lost?

A benchmark, not a test (issue target: no loss at 5,000 datagrams a second
sustained for a minute).  It starts `virja serve --headless --record` on
127.0.0.1 and sends, from one socket, a busy session's traffic:

- the band: bass and drum 16th notes at 200 bpm (note-ons and note-offs, a
  beat ahead), as `tools/soak.py` sends them;
- everyone else, filling the rate: a pianist's notes and sustain pedal, and
  pitch-bend and controller streams, from senders 10-19 on channels 1-8 (not
  the band's: they go through the receiver and the router, not the scheduler).

At the end it stops the daemon with SIGTERM and compares: datagrams sent,
datagrams the daemon counted as received, and datagrams in the recording.

    .venv/bin/python tools/flood.py --rate 5000 --seconds 60
"""

from __future__ import annotations

import argparse
import os
import random
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from soak import free_udp_port, parse_summary, read_rss_kb, stop, wait_listening  # noqa: E402

from virja.clock import SessionClock  # noqa: E402
from virja.rmcp import wire  # noqa: E402
from virja.rmcp.pcap import read_capture  # noqa: E402


def band_messages(step: int) -> list[tuple[int, bytes]]:
    """(sender, MIDI bytes) for one 16th step: bass on 8ths, hi-hat every step, kick/snare."""
    out = [(2, bytes([0x99, 42, 80]))]
    if step % 4 == 0:
        out.append((2, bytes([0x99, 36 if step % 8 == 0 else 38, 100])))
    if step % 2 == 0:
        out.append((1, bytes([0x90, 28 + (step * 5) % 19, 90])))
    return out


def other_message(i: int) -> tuple[int, bytes]:
    """Someone else's message: piano notes, pedal, pitch bend, mod wheel."""
    sender = 10 + i % 10
    ch = i % 8
    if ch == 1:  # keep channel 2 free: the band's bass listens there
        ch = 2
    k = i % 4
    if k == 0:
        return sender, bytes([0x90 | ch, 60 + i % 24, 70])
    if k == 1:
        return sender, bytes([0x80 | ch, 60 + (i - 1) % 24, 0])
    if k == 2:
        return sender, bytes([0xE0 | ch, i % 128, (i // 128) % 128])
    return sender, bytes([0xB0 | ch, 1 if i % 8 == 3 else 64, i % 128])


def main() -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--rate", type=float, default=5000.0, help="datagrams per second (5000)")
    ap.add_argument("--seconds", type=float, default=60.0, help="how long (60)")
    ap.add_argument("--bpm", type=float, default=200.0)
    ap.add_argument(
        "--invalid-share",
        type=float,
        default=0.0,
        help="fraction of the other traffic that is junk: random bytes, and valid-looking "
        "datagrams from ever new sender ids (the receiver's per-sender state must stay bounded)",
    )
    args = ap.parse_args()
    if not (0 < args.rate <= 50_000 and 0 < args.seconds <= 600):
        ap.error("--rate must be in (0, 50000] and --seconds in (0, 600]")
    clock = SessionClock()
    port = free_udp_port()
    work = Path(tempfile.mkdtemp(prefix="virja-flood-"))
    pcap = work / "flood.pcap"
    out_path = work / "serve.out"
    with out_path.open("wb") as out_fh:
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "virja",
                "serve",
                "--headless",
                "--quiet",
                "--listen",
                f"127.0.0.1:{port}",
                "--record",
                str(pcap),
                "--duration",
                str(args.seconds + 60),
            ],
            stdout=out_fh,
            stderr=subprocess.STDOUT,
            env=dict(os.environ, PYTHONUNBUFFERED="1"),
        )
    if not wait_listening(proc, out_path, 60):
        print("daemon did not start")
        proc.kill()
        return 1
    spb = 60.0 / args.bpm
    step_s = spb / 4
    seqs: dict[int, int] = {}
    junk_rng = random.Random(1)
    sent = 0
    band = 0
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    start = time.perf_counter()
    t0_us = clock.now_us()
    next_step = 0
    other_i = 0
    max_behind = 0.0
    rss: list[int] = []
    last_sample = start
    total = int(args.rate * args.seconds)
    try:
        # the bass's channel is an acoustic bass (GM 32): the router gives it to the bassist
        tx.sendto(bytes(wire.midi(1, 0, clock.now_us(), bytes([0xC0, 32]))), ("127.0.0.1", port))
        seqs[1] = 1
        sent += 1
        while sent < total:
            now = time.perf_counter()
            due = min(total, int((now - start) * args.rate) + 1)
            max_behind = max(max_behind, (due - sent) / args.rate)
            while sent < due:
                elapsed_us = clock.now_us() - t0_us
                if elapsed_us >= next_step * step_s * 1e6:
                    msgs = band_messages(next_step)
                    time_us = t0_us + round((next_step * step_s + spb) * 1e6)  # a beat ahead
                    next_step += 1
                    band += len(msgs)
                elif junk_rng.random() < args.invalid_share:
                    other_i += 1
                    if other_i % 2:
                        tx.sendto(
                            junk_rng.randbytes(junk_rng.randrange(0, 64)), ("127.0.0.1", port)
                        )
                    else:  # a valid datagram from a sender never seen before
                        fresh = 20 + other_i % 60000
                        d = wire.midi(fresh, 0, clock.now_us() + 20_000, bytes([0xB0, 7, 100]))
                        tx.sendto(bytes(d), ("127.0.0.1", port))
                    sent += 1
                    continue
                else:
                    msgs = [other_message(other_i)]
                    other_i += 1
                    time_us = clock.now_us() + 20_000
                for sender, msg in msgs:
                    seq = seqs.get(sender, 0)
                    seqs[sender] = seq + 1
                    tx.sendto(bytes(wire.midi(sender, seq, time_us, msg)), ("127.0.0.1", port))
                    sent += 1
            if now - last_sample >= 2.0:
                last_sample = now
                kb = read_rss_kb(proc.pid)
                if kb is not None:
                    rss.append(kb)
            time.sleep(0.001)
        elapsed = time.perf_counter() - start
        time.sleep(1.0)
    finally:
        tx.close()
    rc, killed = stop(proc)
    summary = parse_summary(out_path.read_text(errors="replace"))
    cap = read_capture(pcap, port=port)
    print(
        f"sent {sent} datagrams in {elapsed:.1f} s ({sent / elapsed:.0f}/s; {band} band notes), sender at most {max_behind * 1000:.1f} ms behind schedule"
    )
    print(
        f"daemon: exit {rc}{' (killed)' if killed else ''}, {summary.received} received, {summary.accepted} accepted, drops {dict(summary.dropped) or 'none'}, {summary.planned} notes planned"
    )
    print(f"recording: {len(cap.datagrams)} datagrams")
    if rss:
        print(f"RSS (KB): first {rss[0]}, max {max(rss)}, last {rss[-1]}")
    lost = sent - summary.received
    print(f"lost: {lost} ({lost / max(sent, 1):.3%})")
    if rss and max(rss) - rss[0] > 10_000:
        print("memory grew by more than 10 MB")
        return 1
    return 0 if lost == 0 and len(cap.datagrams) == sent and rc == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
