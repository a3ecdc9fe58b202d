"""Key-to-input and key-to-impact latency through JACK.

A benchmark, not a test.  A second JACK client plays ``--notes`` notes into
virja's input (:class:`virja.jam.ports.MidiInput`, the port ``virja jam``
uses).

- key-to-input: from ``send_message`` to the moment the input's handler stamps it;
- key-to-impact (``--impact``): the whole jam path, as ``virja jam`` runs it in
  its default (immediate) mode: the keyboard split, the scheduler with the
  jam's compressed strokes, the animator, and the full band drawn headless at
  ``--size`` each frame; a note's latency ends when the first frame whose time
  is at or after the note's impact has been drawn.

Prints the median, 95th percentile and worst.

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


def measure_impact(notes: int, gap_s: float, size: tuple[int, int]) -> list[float]:
    """Key-to-impact-drawn latencies (s) through the jam path and the renderer."""
    from virja.cli.cmd_jam import jam_settings
    from virja.jam.keyboard import KeyboardLayout
    from virja.jam.live import KeyboardJam
    from virja.pipeline import build_performance
    from virja.render.camera import PRESETS
    from virja.render.hosts import OffscreenTarget, create_headless_context
    from virja.render.renderer import Renderer
    from virja.render.scene import band_scene, static_scene

    clock = time.perf_counter
    jam = KeyboardJam(KeyboardLayout(), delay_s=0.0, thru=None, stream=None)
    perf = build_performance(jam_settings({}, delay_s=0.0), animate=True)
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    port = MidiInput("jack", jam.handle, clock)
    with quiet_c_stderr():
        out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "latency-sender")
    sent: dict[float, float] = {}  # note time (arrival) -> send time, via the planned note's time
    send_times: list[float] = []
    pending: list[tuple[float, float]] = []  # (impact, note time)
    lat: list[float] = []
    stop = threading.Event()
    lead_s = 0.0  # as virja.render.live.LiveView: draw the pose of when the frame appears

    def player() -> None:
        time.sleep(0.3)
        for i in range(notes):
            send_times.append(clock())
            # alternate a bass key and a drum pad (channel 10)
            msg = [0x90, 36 + i % 12, 100] if i % 2 else [0x99, 38, 100]
            out.send_message(msg)
            time.sleep(gap_s)
        time.sleep(0.3)
        stop.set()

    try:
        out.open_port(out.get_ports().index(port.name))
        thread = threading.Thread(target=player, daemon=True)
        thread.start()
        arrivals: list[float] = []
        while not stop.is_set():
            now = clock()
            for arrival in jam.drain():
                r = arrival.routed
                if r.performer is not None:
                    perf.feed_routed(r.performer, r.event, now_s=arrival.arrival_s)
                    arrivals.append(arrival.arrival_s)
            for p in perf.advance(now):
                pending.append((p.impact, p.time))
            shown = now + lead_s
            renderer.draw([static, band_scene(perf.pose(shown))], PRESETS["front"], target.fbo)
            target.finish()
            drawn = clock()
            lead_s = min(0.1, 0.8 * lead_s + 0.2 * (drawn - now))
            still = []
            for impact, note_time in pending:
                if impact <= shown:
                    sent[note_time] = drawn
                else:
                    still.append((impact, note_time))
            pending[:] = still
        thread.join()
    finally:
        out.delete()
        port.close()
        target.release()
        renderer.release()
        ctx.release()
    # pair each drawn impact with the key that made it: note time = its arrival stamp
    for k, arrival_s in enumerate(arrivals):
        if k < len(send_times) and arrival_s in sent:
            lat.append(sent[arrival_s] - send_times[k])
    return lat


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--notes", type=int, default=300)
    ap.add_argument("--gap-ms", type=float, default=7.0, help="pause between notes")
    ap.add_argument("--server", default=None, help="use this running JACK server")
    ap.add_argument("--rate", type=int, default=48000)
    ap.add_argument("--period", type=int, default=256)
    ap.add_argument(
        "--impact", action="store_true", help="key-to-impact through the whole jam path"
    )
    ap.add_argument("--size", default="1280x720", help="frame size drawn with --impact")
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
        if args.impact:
            w, h = (int(x) for x in args.size.split("x"))
            lat = measure_impact(args.notes, args.gap_ms / 1000.0, (w, h))
        else:
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
    what = f"key-to-impact (drawn at {args.size})" if args.impact else "key-to-input"
    print(f"JACK {what} latency, {len(ms)} of {args.notes} notes")
    if proc is not None:
        print(f"  server: dummy driver, {args.rate} Hz, period {args.period} ({period_ms:.2f} ms)")
    print(f"  median {statistics.median(ms):.2f} ms   p95 {p95:.2f} ms   worst {ms[-1]:.2f} ms")
    print(f"  median in periods: {statistics.median(ms) / period_ms:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
