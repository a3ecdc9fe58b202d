"""Receive RMCP/1 over UDP and draw the band playing what arrives.

Binds 127.0.0.1:50500 by default (anything wider is an explicit --listen);
every datagram goes through the receiver (validation, signing, duplicates,
horizon, lateness), the notes to the scheduler, the motions to the animator,
and the band to a window (or nowhere with --headless).  The window is drawn by
its own process, so no frame ever delays receiving or planning.  Stops on
SIGINT or SIGTERM, on closing the window, or after --duration, printing a
summary: datagrams received and rejected, notes planned and dropped (and why),
frames shown, the clock offset.

examples:
  virja serve --headless --plan-log plan.jsonl --record session.pcap
  virja serve --listen [::]:50500 --group 239.255.50.50
  virja serve --headless --web 127.0.0.1:8080   # watch at http://127.0.0.1:8080/
  virja send virja/demo/blues.mid --to 127.0.0.1:50500   # in another shell
  virja serve --rtp-midi 0.0.0.0:5004 --bass-channel 1     # a Mac's network MIDI (docs/rtp-midi.md)
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import gc
import signal
import sys
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from virja.cli import rtp_midi
from virja.cli.common import (
    add_routing_arguments,
    finite_float,
    open_plan_log,
    performance_settings,
)
from virja.cli.web_option import add_web_arguments, web_settings
from virja.config import load_config
from virja.errors import ConfigError, NotAvailableError
from virja.faults import survive_tick

if TYPE_CHECKING:
    from virja.live.outputs import LiveOutputs, LiveSettings

STATUS_EVERY_S = 5.0
RECORDER_FLUSH_S = 0.1  # the recording is flushed this often while it is open
CLOCK_SYNC_S = 1.0  # with --clock-server, the window's clock follows the estimate this often
WEB_IDLE_S = 0.25  # with --web and nobody watching: how soon a new browser gets its first frame
KEEP_MOTION_S = 20.0  # motions older than this are forgotten by an animator in this process
# receiver drops that are counted after a datagram was accepted (per event or note);
# every other reason rejects the whole datagram
AFTER_ACCEPT = frozenset({"too_late", "beyond_horizon", "queue_full", "unknown_kind"})


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--listen",
        default="127.0.0.1:50500",
        metavar="HOST:PORT",
        help="address to bind (default 127.0.0.1:50500; [::1]:50500 for IPv6)",
    )
    p.add_argument(
        "--group",
        metavar="ADDR",
        help="join this multicast group (e.g. 239.255.50.50); receivers may share it",
    )
    p.add_argument("--headless", action="store_true", help="no window; everything else the same")
    p.add_argument(
        "--audio",
        action="store_true",
        help="play the session's notes through fluidsynth at their time (the sound card's "
        "default output; --audio-driver to choose)",
    )
    p.add_argument(
        "--audio-driver",
        metavar="NAME",
        help="fluidsynth's audio driver: alsa, pulseaudio, jack, ... (default: fluidsynth's)",
    )
    p.add_argument("--soundfont", metavar="FILE.sf2", help="General MIDI soundfont for --audio")
    p.add_argument(
        "--hud",
        action="store_true",
        help="show the heads-up display (tempo, bar.beat, chord) from the start; key H toggles it",
    )
    p.add_argument(
        "--record",
        metavar="FILE.pcap",
        help="record every datagram that arrives (valid or not) as pcap",
    )
    p.add_argument(
        "--plan-log",
        metavar="FILE.jsonl",
        help="write each planned note as one JSON object per line; times in seconds from "
        "the first datagram received (the start of a --record), session_time in Unix seconds",
    )
    p.add_argument(
        "--key-file", metavar="FILE", help="HMAC key: drop unsigned, forged and replayed datagrams"
    )
    p.add_argument(
        "--clock-server",
        metavar="HOST:PORT",
        help="estimate the session clock offset from this peer",
    )
    p.add_argument(
        "--duration",
        type=finite_float,
        metavar="SECONDS",
        help="stop by itself after this long (exit 0)",
    )
    p.add_argument(
        "--horizon",
        type=finite_float,
        default=10.0,
        metavar="SECONDS",
        help="drop events further ahead (default 10)",
    )
    p.add_argument(
        "--lateness-ms",
        type=finite_float,
        default=60.0,
        metavar="MS",
        help="still play notes this late (default 60)",
    )
    p.add_argument(
        "--size", default="1280x720", metavar="WxH", help="window size (default 1280x720)"
    )
    p.add_argument(
        "--fps",
        type=finite_float,
        default=60.0,
        metavar="N",
        help="window frame rate where the display has no vsync (default 60)",
    )
    p.add_argument("--quiet", action="store_true", help="no status line")
    add_web_arguments(p)
    add_routing_arguments(p)
    rtp_midi.add_argument(p)


@dataclass
class Daemon:
    """The live pipeline's state, shared by the receive callback and the tick task."""

    perf: Any
    receiver: Any
    clock: Any
    recorder: Any = None
    clock_client: Any = None
    timer: Any = None
    viewer: Any = None
    late_notes: int = 0
    started_s: float = field(default_factory=time.monotonic)

    def arrived(self, now_us: int) -> None:
        """A datagram arrived: the first is the start of the session (what a recording
        of it starts with), from which the plan log counts its times."""
        self.perf.mark_origin(now_us / 1e6)

    def on_events(self, received: list[Any], now_s: float) -> None:
        from virja.events import NoteOn

        band = False
        for rec in received:
            if self.perf.feed(rec.event, now_s=rec.arrival_s) is not None:
                band = True
            if rec.late and isinstance(rec.event, NoteOn):
                self.late_notes += 1
        if band:  # plan at once; other traffic waits for the next deadline
            self.perf.advance(now_s)
        if self.timer is not None:  # a note may bring the next deadline closer
            self.timer.poke()

    def tick(self) -> None:
        now_us = self.clock.now_us()
        self.perf.advance(now_us / 1e6)
        if self.recorder is not None:
            self.recorder.tick(now_us)

    def status(self) -> str:
        st = self.receiver.stats
        drops = sum(st.dropped.values())
        c = self.perf.counts
        line = (
            f"{st.datagrams} datagrams ({drops} dropped), band notes received: "
            f"{c['notes_bass']} bass, {c['notes_drums']} drums ({self.late_notes} late); "
            f"{c['planned']} motions started"
        )
        if self.clock_client is not None:
            est = self.clock_client.estimator.estimate()
            if est is not None:
                line += f", clock offset {est.offset_us / 1000:+.2f} ms (delay {est.delay_us / 1000:.2f} ms)"
        return line

    def summary(self) -> list[str]:
        st = self.receiver.stats
        c = self.perf.counts
        rejected = {k: v for k, v in st.dropped.items() if k not in AFTER_ACCEPT and v}
        on_arrival = {k: v for k, v in st.dropped.items() if k in AFTER_ACCEPT and v}
        plan = self.perf.planner.report.summary()
        by_planner = {
            k.removeprefix("dropped_"): v for k, v in plan.items() if k.startswith("dropped_") and v
        }
        band = c["notes_bass"] + c["notes_drums"]
        lines = [
            f"datagrams: {st.datagrams} received, {st.accepted} accepted, "
            f"{st.datagrams - st.accepted} rejected" + _reasons(rejected),
            "accepted by kind: "
            + (", ".join(f"{k} {v}" for k, v in sorted(st.by_kind.items())) or "none"),
            f"notes: {band} for the band ({c['notes_bass']} bass, {c['notes_drums']} drums), "
            f"{c['planned']} planned ({self.late_notes} arrived late and were played "
            f"compressed), {plan.get('dropped', 0)} dropped by the scheduler"
            + _reasons(by_planner),
            f"dropped on arrival, never planned: {sum(on_arrival.values())}"
            + _reasons(on_arrival, explain=True),
            f"notes not the band's: {c['notes_not_the_bands']}",
        ]
        if plan.get("moved"):
            lines.append(f"notes moved into the bass's range: {plan['moved']}")
        if self.viewer is not None and self.viewer.stats is not None:
            vs = self.viewer.stats
            lines.append(
                f"window: {vs.frames} frames shown, {vs.skipped} skipped as late"
                + (" (vsync)" if vs.vsync else "")
            )
        if self.clock_client is not None:
            est = self.clock_client.estimator.estimate()
            lines.append(
                "clock offset: "
                + (
                    f"{est.offset_us / 1000:+.3f} ms, delay {est.delay_us / 1000:.3f} ms"
                    if est
                    else "no estimate (no replies)"
                )
            )
        else:
            lines.append("clock offset: 0 (no --clock-server; local clock is the session clock)")
        failed = getattr(self.recorder, "failed", None)
        if failed:
            lines.append(f"recording stopped early: {failed} (what was written is readable)")
        if self.perf.plan_log_failed:
            lines.append(f"plan log stopped early: {self.perf.plan_log_failed}")
        return lines


WHY = {
    "too_late": "notes past --lateness-ms",
    "beyond_horizon": "datagrams past --horizon",
    "queue_full": "events over the queue",
    "unknown_kind": "datagrams of a kind unknown",
}


def _reasons(counts: dict[str, int], *, explain: bool = False) -> str:
    if not counts:
        return ""
    parts = [
        f"{k} {v}" + (f" ({WHY[k]})" if explain and k in WHY else "")
        for k, v in sorted(counts.items())
    ]
    return ": " + ", ".join(parts)


def run(args: argparse.Namespace) -> int:
    return asyncio.run(serve(args))


def _resolve_or_fail(addr: tuple[str, int], option: str) -> None:
    import socket

    try:
        socket.getaddrinfo(addr[0], addr[1], type=socket.SOCK_DGRAM)
    except (OSError, UnicodeError) as exc:
        raise ConfigError(
            f"{option} {addr[0]}:{addr[1]}: cannot resolve: {getattr(exc, 'strerror', None) or exc}"
        ) from None


def _report_clock_failure(task: asyncio.Task[Any]) -> None:
    if task.cancelled():
        return
    exc = task.exception()
    if exc is not None:
        print(f"virja serve: the clock client stopped: {exc}", file=sys.stderr, flush=True)


def live_settings(args: argparse.Namespace, title: str) -> LiveSettings:
    """The window (unless --headless), --web and --audio (its soundfont found now: one
    line when there is none)."""
    from virja.live.outputs import AudioSettings, LiveSettings
    from virja.live.viewer import ViewerSpec
    from virja.render.offline import parse_size
    from virja.render.video import find_soundfont

    audio = None
    if args.audio:
        sf = find_soundfont(args.soundfont)
        if sf is None:
            raise NotAvailableError(
                "--audio needs a General MIDI soundfont: apt-get install fluid-soundfont-gm, "
                "--soundfont FILE.sf2 or VIRJA_SOUNDFONT"
            )
        audio = AudioSettings(sf, args.audio_driver)
    window = None
    if not args.headless:
        window = ViewerSpec(parse_size(args.size), title, args.fps, hud=args.hud)
    return LiveSettings(window=window, web=web_settings(args), audio=audio)


async def serve(args: argparse.Namespace) -> int:
    from virja.clock import SessionClock
    from virja.live.outputs import LiveOutputs
    from virja.live.timer import DeadlineTimer, wake_in
    from virja.pipeline import build_performance
    from virja.rmcp.pcap import PcapWriter
    from virja.rmcp.receiver import Receiver, ReceiverConfig
    from virja.rmcp.signing import load_key
    from virja.rmcp.stamped import open_stamped_listener
    from virja.rmcp.transport import ClockClient, RmcpProtocol, parse_hostport

    load_config(args.config)  # fail early on a bad file
    if args.duration is not None and args.duration <= 0:
        raise ConfigError("--duration must be > 0")
    if args.horizon <= 0 or args.lateness_ms < 0:
        raise ConfigError("--horizon must be > 0 and --lateness-ms >= 0")
    host, port = parse_hostport(args.listen)
    rtp_midi.check(args)  # a bad --rtp-midi fails before anything is bound
    key = load_key(args.key_file) if args.key_file else None
    clock = SessionClock()
    receiver = Receiver(
        ReceiverConfig(horizon_s=args.horizon, lateness_s=args.lateness_ms / 1000, key=key)
    )
    clock_server = parse_hostport(args.clock_server) if args.clock_server else None
    if clock_server is not None:
        _resolve_or_fail(clock_server, "--clock-server")
    # bind first: a port in use must not cost the user an existing plan log or recording
    # RTP-MIDI notes are played at once: the shortest strokes (docs/rtp-midi.md)
    perf = build_performance(performance_settings(args, immediate=bool(args.rtp_midi)))
    perf.keep_planned = False  # a daemon runs for hours: memory stays flat
    if not 1 <= args.fps <= 1000:
        raise ConfigError(f"--fps must be 1-1000, got {args.fps:g}")
    daemon = Daemon(perf=perf, receiver=receiver, clock=clock)
    protocol = RmcpProtocol(receiver, clock, daemon.on_events)
    protocol.on_arrival = daemon.arrived
    transport = await open_stamped_listener(host, port, protocol, clock, group=args.group)
    bound = transport.get_extra_info("sockname")
    rtp = None
    outputs: LiveOutputs | None = None  # the window's process, the browsers, the speakers
    try:
        outputs = LiveOutputs.open(
            perf, live_settings(args, f"virja serve {host}:{port}"), clock.now_s
        )
        rtp = await rtp_midi.start_serve(args, clock, daemon)
        viewer, web, sinks = outputs.viewer, outputs.web, outputs.sinks
        daemon.viewer = viewer
        perf.plan_log = open_plan_log(args.plan_log)
        if args.record:
            recorder = PcapWriter.for_listener(args.record, bound)
            protocol.recorder = daemon.recorder = recorder
            if rtp is not None:
                rtp.recorder = recorder
    except BaseException:
        transport.close()
        if rtp is not None:
            await rtp.close()
        if outputs is not None:
            outputs.close()
        if perf.plan_log is not None:
            perf.plan_log.close()
        raise
    plan_log = perf.plan_log
    # Start-up is over (modules, tables, the motion library, the planner): those
    # objects live as long as the daemon, so they leave the collector's generations.
    # A full collection walking them took about 30 ms (31,000 objects; docs/performance.md),
    # a pause in the middle of a note's planning or a frame; after this it walks only
    # what was made since.  (A frozen object is never collected: only start-up's are.)
    gc.freeze()
    print(
        f"virja serve: listening on {bound[0]}:{bound[1]}"
        + (f", group {args.group}" if args.group else ""),
        flush=True,
    )
    if web is not None:
        print(f"virja serve: web viewer at {web.url}", flush=True)

    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(sig, stop.set)
    tasks: list[asyncio.Task[Any]] = []
    if clock_server is not None:
        daemon.clock_client = ClockClient(clock_server, clock, key=key)
        clock_task = asyncio.create_task(daemon.clock_client.run())
        clock_task.add_done_callback(_report_clock_failure)
        tasks.append(clock_task)
    if args.duration is not None:
        loop.call_later(args.duration, stop.set)
    if viewer is not None:  # the window closed (Esc, Q, its close box): stop
        loop.add_reader(viewer.sentinel, stop.set)
    timer = daemon.timer = DeadlineTimer()

    async def ticker() -> None:
        """Wake at the next motion's start, a status line, a flush; or on a datagram."""
        next_status = time.monotonic() + STATUS_EVERY_S
        while not stop.is_set():
            timer.arm()
            deadlines: list[float] = []  # what a failed tick did not get to: MAX_SLEEP_S
            with survive_tick():  # one tick's exception is reported; the next tick runs
                daemon.tick()
                now_s = clock.now_s()
                deadlines.append(perf.planner.next_deadline())
                if web is not None:  # a frame for the browsers when one is due
                    web.publish(perf, now_s)
                    sinks.forget_before(now_s - KEEP_MOTION_S)
                    deadlines.append(now_s + (1 / web.fps if web.server.viewers else WEB_IDLE_S))
                if daemon.recorder is not None:
                    deadlines.append(now_s + RECORDER_FLUSH_S)
                if viewer is not None and daemon.clock_client is not None:
                    viewer.sync_clock()
                    deadlines.append(now_s + CLOCK_SYNC_S)
                if not args.quiet:
                    if time.monotonic() >= next_status:
                        next_status = time.monotonic() + STATUS_EVERY_S
                        print(f"virja serve: {daemon.status()}", file=sys.stderr, flush=True)
                    deadlines.append(now_s + next_status - time.monotonic())
            await timer.sleep(wake_in(deadlines, clock.now_s()))

    tasks.append(asyncio.create_task(ticker()))
    try:
        await stop.wait()
    finally:
        for t in tasks:
            t.cancel()
        for t in tasks:
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await t
        transport.close()
        if rtp is not None:
            await rtp.close()
        outputs.close_audio()
        if viewer is not None:
            loop.remove_reader(viewer.sentinel)
        # each step on its own: a failure is one warning, and the summary still comes
        with survive_tick():
            daemon.tick()
        with survive_tick():
            perf.finish()  # notes planned ahead of the stop are logged too, as replay logs them
        if daemon.recorder is not None:
            with survive_tick():
                daemon.recorder.close()
        if plan_log is not None:
            with survive_tick():
                plan_log.close()
        outputs.close()  # the window and the web viewer
    print("virja serve: stopped")
    extra = ([web.summary()] if web is not None else []) + (rtp.summary() if rtp else [])
    for line in daemon.summary() + extra:
        print(f"  {line}")
    return 0
