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

Prints the median, 95th percentile and worst.  ``--stages`` (with ``--impact``) also
prints where a key's time goes, stage by stage (:data:`STAGES`: JACK to the handler's
stamp, the wait for the frame in progress, planning, committing, the wait for the frame
that poses the impact, that frame's pose, scene and draw), and the frames' pose, scene
and draw with and without a note fed in their loop turn, and where in the loop's turn
the keys were sent.

The keys come from a process of their own, as a keyboard's would (``--sender process``).
Until round 8 they came from a thread of the measured process (``--sender thread``):
each send then waited for the frame loop to let go of the GIL, so most keys went out
just after a turn began and waited for the whole turn, not half of it on average; the
longer the frames, the more that overstated the latency (docs/performance.md, "Key to
impact through JACK").

JACK MIDI moves once per period, so expect figures of the order of one to two
periods (``--period`` frames at ``--rate`` Hz; 256 at 48 kHz is 5.3 ms).

By default it starts its own server with the dummy driver (no sound card
needed) and stops it at the end; ``--server NAME`` uses a running one instead.

    .venv/bin/python tools/jack_latency.py --notes 500
    .venv/bin/python tools/jack_latency.py --impact --notes 100 --gap-ms 120 --stages
"""

from __future__ import annotations

import argparse
import bisect
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import rtmidi

from virja.jam.ports import MidiInput, quiet_c_stderr

if TYPE_CHECKING:
    from virja.session import Performance


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


# The stages of one key's way to the screen, in the order they happen (each ends at the
# stamp named; the first starts at the key sent).  Their sum is the key's latency.
STAGES: tuple[tuple[str, str], ...] = (
    ("jack", "sent -> stamped by the input's handler"),
    ("wait", "stamped -> drained (the frame in progress)"),
    ("feed", "drained -> routed and planned (feed_routed)"),
    ("advance", "-> committed to the animator (advance)"),
    ("to_frame", "-> start of the first frame posing the impact"),
    ("pose", "that frame's pose (perf.pose)"),
    ("scene", "that frame's scene (band_scene)"),
    ("draw", "that frame drawn until finished"),
)


@dataclass
class NoteStamps:
    """Clock stamps (s) of one key on its way to the screen."""

    sent: float = math.nan
    stamped: float = math.nan
    drained: float = math.nan
    fed: float = math.nan
    committed: float = math.nan
    impact: float = math.nan  # the planned impact (its time on the session clock)
    frame: float = math.nan  # the first frame posing the impact: its start
    posed: float = math.nan
    built: float = math.nan
    drawn: float = math.nan
    lead: float = math.nan  # that frame's lead (shown = frame + lead)

    def stages(self) -> dict[str, float]:
        marks = (self.sent, self.stamped, self.drained, self.fed, self.committed)
        marks += (self.frame, self.posed, self.built, self.drawn)
        return {name: b - a for (name, _), a, b in zip(STAGES, marks[:-1], marks[1:], strict=True)}

    @property
    def latency(self) -> float:
        return self.drawn - self.sent


@dataclass
class ImpactRun:
    """What :func:`measure_impact` saw: one :class:`NoteStamps` a key whose impact was
    drawn, and the frames' (pose, scene, draw) seconds, marked when a note was fed in the
    frame's loop turn (its pose is the first to hold that note)."""

    notes: list[NoteStamps]
    frames: list[tuple[bool, float, float, float]] = field(default_factory=list)
    turns: list[float] = field(default_factory=list)  # when each loop turn began

    def send_phases(self) -> list[float]:
        """Where in the loop turn then in progress each key was sent (0: as the turn
        began, 1: as it ended).  A keyboard's keys fall anywhere (even); keys sent at
        the loop's own pauses cluster."""
        out = []
        for n in self.notes:
            k = bisect.bisect_right(self.turns, n.sent) - 1
            if 0 <= k < len(self.turns) - 1:
                out.append((n.sent - self.turns[k]) / (self.turns[k + 1] - self.turns[k]))
        return out

    def turns_to_drain(self) -> list[float]:
        """Each key's wait from sent to drained, in lengths of the loop turn it was sent in
        (about half a turn plus JACK's period for keys sent at random moments)."""
        out = []
        for n in self.notes:
            k = bisect.bisect_right(self.turns, n.sent) - 1
            if 0 <= k < len(self.turns) - 1:
                out.append((n.drained - n.sent) / (self.turns[k + 1] - self.turns[k]))
        return out

    @property
    def latencies(self) -> list[float]:
        return [n.latency for n in self.notes]


def jam_performance() -> Performance:
    """The performance ``virja jam`` builds in its default (immediate) mode."""
    from virja.cli.cmd_jam import jam_settings
    from virja.pipeline import build_performance

    return build_performance(jam_settings({}, delay_s=0.0), animate=True)


def play(port_name: str, notes: int, gap_s: float, clock: Callable[[], float]) -> list[float]:
    """Send ``notes`` keys to ``port_name`` ``gap_s`` apart, alternately a drum pad
    (channel 10) and a bass key; returns when each was sent (``clock``)."""
    with quiet_c_stderr():
        out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "latency-sender")
    sent: list[float] = []
    try:
        out.open_port(out.get_ports().index(port_name))
        time.sleep(0.3)  # let the connection settle before the first note
        for i in range(notes):
            msg = [0x90, 36 + i % 12, 100] if i % 2 else [0x99, 38, 100]
            sent.append(clock())
            out.send_message(msg)
            time.sleep(gap_s)
    finally:
        out.delete()
    return sent


class _Sender:
    """Plays the keys (:func:`play`) while the frame loop runs; ``sending()`` until done,
    then ``times`` holds when each key was sent.

    ``process`` (the default): from a process of its own, as a keyboard plays.
    ``thread``: from a thread of the measured process, as before round 8: each send
    waits for the frame loop to let go of the GIL, so the keys go out at the loop's own
    pauses, not at random moments of its frames (docs/performance.md).
    """

    def __init__(self, how: str, port_name: str, notes: int, gap_s: float) -> None:
        self.times: list[float] = []
        self._child: subprocess.Popen[str] | None = None
        self._thread: threading.Thread | None = None
        if how == "thread":
            self._thread = threading.Thread(
                target=lambda: self.times.extend(play(port_name, notes, gap_s, time.monotonic)),
                daemon=True,
            )
            self._thread.start()
            return
        cmd = [sys.executable, os.path.abspath(__file__), "--play-to", port_name]
        cmd += ["--notes", str(notes), "--gap-ms", repr(gap_s * 1000.0)]
        self._child = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)

    def sending(self) -> bool:
        if self._thread is not None:
            return self._thread.is_alive()
        assert self._child is not None and self._child.stdout is not None
        if self._child.poll() is None:
            return True
        out = self._child.stdout.read()
        if self._child.returncode != 0 or not out.strip():
            sys.exit(f"the sender process failed (exit {self._child.returncode})")
        self.times = json.loads(out)
        return False

    def close(self) -> None:
        if self._child is not None and self._child.poll() is None:
            self._child.kill()
            self._child.wait()


def measure_impact(
    notes: int, gap_s: float, size: tuple[int, int], sender: str = "process"
) -> ImpactRun:
    """Key-to-impact-drawn latencies (s) through the jam path and the renderer, with the
    stamps of each stage (:data:`STAGES`); the keys played by ``sender``
    (:class:`_Sender`)."""
    from virja.jam.keyboard import KeyboardLayout
    from virja.jam.live import KeyboardJam
    from virja.render.camera import PRESETS
    from virja.render.hosts import OffscreenTarget, create_headless_context
    from virja.render.renderer import Renderer
    from virja.render.scene import band_scene, static_scene

    clock = time.monotonic  # system-wide: the sender process's stamps compare
    jam = KeyboardJam(KeyboardLayout(), delay_s=0.0, thru=None, stream=None)
    perf = jam_performance()
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    port = MidiInput("jack", jam.handle, clock)
    # a key's note time is its arrival stamp (no delay): it names the key from the
    # handler to the planned note
    stamps: dict[float, NoteStamps] = {}
    pending: list[tuple[float, float]] = []  # (impact, note time)
    frames: list[tuple[bool, float, float, float]] = []
    turns: list[float] = []
    lead_s = 0.0  # as virja.render.live.LiveView: draw the pose of when the frame appears
    keys = _Sender(sender, port.name, notes, gap_s)

    try:
        arrivals: list[float] = []
        stop_at = math.inf
        while clock() < stop_at:
            if stop_at == math.inf and not keys.sending():
                stop_at = clock() + 0.3  # the last impact's frames
            now = clock()
            turns.append(now)
            fed = False
            for arrival in jam.drain():
                r = arrival.routed
                if r.performer is not None:
                    got = NoteStamps(stamped=arrival.arrival_s, drained=clock())
                    perf.feed_routed(r.performer, r.event, now_s=arrival.arrival_s)
                    got.fed = clock()
                    stamps[arrival.arrival_s] = got
                    arrivals.append(arrival.arrival_s)
                    fed = True
            committed = perf.advance(now)
            done = clock()
            for p in committed:
                pending.append((p.impact, p.time))
                if p.time in stamps:
                    stamps[p.time].committed = done
                    stamps[p.time].impact = p.impact
            frame = clock()
            shown = frame + lead_s
            pose = perf.pose(shown)
            posed = clock()
            scene = band_scene(pose)
            built = clock()
            renderer.draw([static, scene], PRESETS["front"], target.fbo)
            target.finish()
            drawn = clock()
            frames.append((fed, posed - frame, built - posed, drawn - built))
            lead = lead_s
            lead_s = min(0.1, 0.8 * lead_s + 0.2 * (drawn - now))
            still = []
            for impact, note_time in pending:
                if impact <= shown:
                    if note_time in stamps:
                        s = stamps[note_time]
                        s.frame, s.posed, s.built, s.drawn, s.lead = (
                            frame,
                            posed,
                            built,
                            drawn,
                            lead,
                        )
                else:
                    still.append((impact, note_time))
            pending[:] = still
    finally:
        keys.close()
        port.close()
        target.release()
        renderer.release()
        ctx.release()
    # pair each key sent with its arrival, in order
    drawn_notes = []
    for k, arrival_s in enumerate(arrivals):
        s = stamps[arrival_s]
        if k < len(keys.times) and not math.isnan(s.drawn):
            s.sent = keys.times[k]
            drawn_notes.append(s)
    return ImpactRun(drawn_notes, frames, turns)


def _p95(xs: list[float]) -> float:
    ys = sorted(xs)
    return ys[min(len(ys) - 1, int(0.95 * len(ys)))]


def print_stages(run: ImpactRun) -> None:
    """Median and p95 per stage (ms), and the frames' costs with and without a note fed."""
    print("  stages (ms; medians need not add up to the total's):    median     p95")
    per = [n.stages() for n in run.notes]
    for name, what in STAGES:
        xs = [s[name] * 1000.0 for s in per]
        print(f"    {name:<9} {what:<48} {statistics.median(xs):7.2f} {_p95(xs):7.2f}")
    stroke = statistics.median(n.impact - n.stamped for n in run.notes) * 1000.0
    lead = statistics.median(n.lead for n in run.notes) * 1000.0
    print(f"    (stamped -> planned impact {stroke:.2f}; that frame's lead {lead:.2f})")
    phases = run.send_phases()
    if phases:
        quarters = [0, 0, 0, 0]
        for ph in phases:
            quarters[min(3, int(ph * 4))] += 1
        print(f"  keys sent in each quarter of the loop turn in progress: {quarters}")
        turns = statistics.median(run.turns_to_drain())
        print(f"  sent -> drained: median {turns:.2f} loop turns")
    for fed, label in ((True, "a note fed"), (False, "no note fed")):
        rows = [f[1:] for f in run.frames if f[0] is fed]
        if rows:
            pose, scene, draw = (statistics.median(c) * 1000.0 for c in zip(*rows, strict=True))
            print(
                f"  frames with {label} ({len(rows)}): pose {pose:.2f}  scene {scene:.2f}  "
                f"draw {draw:.2f} ms (medians)"
            )


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
    ap.add_argument("--stages", action="store_true", help="with --impact: the median of each stage")
    ap.add_argument(
        "--sender",
        choices=("process", "thread"),
        default="process",
        help="with --impact: play the keys from a process of their own (as a keyboard), "
        "or from a thread of the measured process (before round 8)",
    )
    ap.add_argument("--play-to", default=None, help=argparse.SUPPRESS)  # the sender process
    args = ap.parse_args()
    if args.play_to is not None:
        print(json.dumps(play(args.play_to, args.notes, args.gap_ms / 1000.0, time.monotonic)))
        return 0

    proc = None
    if args.server is None:
        name = f"virja-latency-{os.getpid()}"
        proc = _start_jackd(name, args.rate, args.period)
        os.environ["JACK_DEFAULT_SERVER"] = name
    else:
        os.environ["JACK_DEFAULT_SERVER"] = args.server
    run = None
    try:
        _wait_for_server()
        if args.impact:
            w, h = (int(x) for x in args.size.split("x"))
            run = measure_impact(args.notes, args.gap_ms / 1000.0, (w, h), args.sender)
            lat = run.latencies
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
    if args.stages and run is not None:
        print_stages(run)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
