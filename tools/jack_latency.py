"""Key-to-input latency through JACK: how long a note takes from a sender to virja's handler.

A benchmark, not a test.  A second JACK client plays ``--notes`` notes into
virja's input (:class:`virja.jam.ports.MidiInput`, the port ``virja jam``
uses); each note's latency is the time from ``send_message`` to the moment the
input's handler stamps it.  Prints the median, 95th percentile and worst.

JACK MIDI moves once per period, so expect figures of the order of one to two
periods (``--period`` frames at ``--rate`` Hz; 256 at 48 kHz is 5.3 ms).

By default it starts its own server with the dummy driver (no sound card
needed) and stops it at the end; ``--server NAME`` uses a running one instead.

    .venv/bin/python tools/jack_latency.py --notes 500
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import threading
import time

import rtmidi

from virja.jam.ports import MidiInput, quiet_c_stderr


def _start_jackd(name: str, rate: int, period: int) -> subprocess.Popen[bytes]:
    jackd = shutil.which("jackd")
    if jackd is None:
        sys.exit("jackd is not installed (apt-get install jackd2)")
    env = dict(os.environ, JACK_NO_AUDIO_RESERVATION="1")
    cmd = [jackd, "-n", name, "--no-realtime", "-d", "dummy", "-r", str(rate), "-p", str(period)]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)


def _wait_for_server(timeout_s: float = 10.0) -> None:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        try:
            with quiet_c_stderr():
                rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "latency-ping").delete()
            return
        except rtmidi.RtMidiError:
            time.sleep(0.05)
    sys.exit("the JACK server did not come up")


def measure(notes: int, gap_s: float) -> list[float]:
    """Latencies in seconds of ``notes`` notes sent ``gap_s`` apart."""
    arrivals: dict[int, float] = {}
    got = threading.Event()

    def handler(data: bytes, arrival_s: float) -> None:
        arrivals[len(arrivals)] = arrival_s
        got.set()

    port = MidiInput("jack", handler, time.perf_counter)
    with quiet_c_stderr():
        out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "latency-sender")
    sent: list[float] = []
    try:
        out.open_port(out.get_ports().index(port.name))
        time.sleep(0.2)  # let the connection settle before the first note
        for i in range(notes):
            got.clear()
            sent.append(time.perf_counter())
            out.send_message([0x90, 36 + i % 24, 100])
            got.wait(timeout=1.0)
            time.sleep(gap_s)
    finally:
        out.delete()
        port.close()
    return [arrivals[i] - sent[i] for i in range(min(len(sent), len(arrivals)))]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--notes", type=int, default=300)
    ap.add_argument("--gap-ms", type=float, default=7.0, help="pause between notes")
    ap.add_argument("--server", default=None, help="use this running JACK server")
    ap.add_argument("--rate", type=int, default=48000)
    ap.add_argument("--period", type=int, default=256)
    args = ap.parse_args()

    proc = None
    if args.server is None:
        name = f"virja-latency-{os.getpid()}"
        proc = _start_jackd(name, args.rate, args.period)
        os.environ["JACK_DEFAULT_SERVER"] = name
    else:
        os.environ["JACK_DEFAULT_SERVER"] = args.server
    try:
        _wait_for_server()
        lat = measure(args.notes, args.gap_ms / 1000.0)
    finally:
        if proc is not None:
            proc.terminate()
            proc.wait(timeout=5)
    if not lat:
        print("no note arrived")
        return 1
    ms = sorted(x * 1000.0 for x in lat)
    period_ms = 1000.0 * args.period / args.rate
    p95 = ms[min(len(ms) - 1, int(0.95 * len(ms)))]
    print(f"JACK key-to-input latency, {len(ms)} of {args.notes} notes")
    if proc is not None:
        print(f"  server: dummy driver, {args.rate} Hz, period {args.period} ({period_ms:.2f} ms)")
    print(f"  median {statistics.median(ms):.2f} ms   p95 {p95:.2f} ms   worst {ms[-1]:.2f} ms")
    print(f"  median in periods: {statistics.median(ms) / period_ms:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
