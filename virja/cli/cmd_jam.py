"""Play a MIDI keyboard; the virtual bassist and drummer play what you play.

Keys below the split (default C3 = 48) go to the bassist, channel 10 to the
drummer; keys from the split up are yours, drawn by nobody, unless --upper drums
makes them drum strokes (see docs/jam.md for the key table).  Without --port,
virja opens a MIDI input port named "virja" and prints its full name: connect
the keyboard to it (jack_connect, qjackctl, aconnect).

Latency: by default each stroke is drawn at once (the motion's anticipation is
compressed); --delay-ms D puts the picture and the --thru sound off by D so
every motion keeps its full anticipation.

Examples:
  virja jam --list-ports
  virja jam --port Keystation --thru fluidsynth --delay-ms 150
  virja jam --headless --duration 30 --plan-log jam.jsonl
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from virja.cli import rtp_midi
from virja.cli.common import finite_float
from virja.cli.web_option import add_web_arguments, web_settings
from virja.config import section
from virja.errors import ConfigError, InputFileError

if TYPE_CHECKING:
    from virja.jam.live import KeyboardJam
    from virja.jam.options import JamOptions
    from virja.jam.ports import MidiInput, MidiOutput
    from virja.pipeline import PerformanceSettings
    from virja.session import Performance


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--api",
        choices=("jack", "alsa"),
        default=None,
        help="MIDI API (default: the first that works)",
    )
    parser.add_argument(
        "--port",
        default=None,
        metavar="NAME",
        help="connect to the first source port containing NAME",
    )
    parser.add_argument("--list-ports", action="store_true", help="list MIDI ports and exit")
    parser.add_argument(
        "--split",
        default=None,
        metavar="KEY",
        help="lowest key of the upper part, a name or a MIDI number (C3, Bb2, 48); "
        "keys below it play the bass (default C3 = 48)",
    )
    parser.add_argument(
        "--upper",
        choices=("ignore", "drums"),
        default=None,
        help="what the keys from the split up do (default: ignore, the pianist's own part)",
    )
    parser.add_argument(
        "--delay-ms",
        type=finite_float,
        default=None,
        metavar="D",
        help="delay picture and thru sound by D ms so motions keep their anticipation (default 0)",
    )
    parser.add_argument(
        "--thru",
        default=None,
        metavar="PORT",
        help="forward notes to the first synth port containing PORT",
    )
    parser.add_argument(
        "--send", default=None, metavar="HOST:PORT", help="also stream the band's notes as RMCP/1"
    )
    parser.add_argument("--headless", action="store_true", help="no window: plan (and log) only")
    parser.add_argument(
        "--size", default="1280x720", metavar="WxH", help="window size (default 1280x720)"
    )
    parser.add_argument(
        "--hud",
        action="store_true",
        help="show the heads-up display (tempo, bar.beat, chord) from the start; key H toggles it",
    )
    parser.add_argument(
        "--plan-log",
        default=None,
        metavar="FILE.jsonl",
        help="write planned notes (times from the jam's start; session_time: Unix seconds)",
    )
    parser.add_argument(
        "--duration",
        type=finite_float,
        default=None,
        metavar="SECONDS",
        help="stop after this long",
    )
    parser.add_argument("--config", default=None, metavar="FILE.toml", help="configuration file")
    add_web_arguments(parser)
    rtp_midi.add_argument(parser)


def _options(args: argparse.Namespace, doc: dict[str, Any]) -> JamOptions:
    from virja.jam.options import JamOptions

    flags = {
        "api": args.api,
        "port": args.port,
        "split": args.split,
        "upper": args.upper,
        "delay_ms": args.delay_ms,
        "thru": args.thru,
        "send": args.send,
    }
    where = f"{args.config} [jam]" if args.config else "[jam]"
    return JamOptions.merge(section(doc, "jam"), flags, where=where)


def _list_ports(api: str | None) -> int:
    from virja.jam.ports import list_ports, probe_api

    name = probe_api(api)
    for direction, title in (("input", "keyboards (--port)"), ("output", "synths (--thru)")):
        names = list_ports(name, direction)  # type: ignore[arg-type]
        print(f"{name} {title}:")
        for n in names or ["(none)"]:
            print(f"  {n}")
    return 0


@contextlib.contextmanager
def _plan_log(path: str | None) -> Iterator[IO[str] | None]:
    if path is None:
        yield None
        return
    try:
        fh = Path(path).open("w", encoding="utf-8")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise InputFileError(path, f"cannot write plan log: {exc.strerror or exc}") from exc
    with fh:
        yield fh


def jam_settings(
    doc: dict[str, Any], delay_s: float = 0.0, config_path: str | None = None
) -> PerformanceSettings:
    """What a jam's performance is built from (:func:`virja.pipeline.build_performance`).

    Without --delay-ms a key's note is already due when it arrives, so every
    motion is compressed; its shortest stroke is cut to IMMEDIATE_STROKE_S so the
    impact is drawn within a frame of the key (:mod:`virja.plan.immediate`).  With a
    delay at least as long as the longest anticipation the tables are used as they are.
    Events reach the performance already routed by the keyboard split
    (``feed_routed``); its router is there for the Performance's contract only.
    """
    from virja.pipeline import PerformanceSettings
    from virja.plan.config import load_plan_config
    from virja.routing import RoutingConfig

    where = f"{config_path} [routing]" if config_path else "[routing]"
    routing = RoutingConfig.from_dict(section(doc, "routing"), where)
    return PerformanceSettings(load_plan_config(config_path), routing, immediate=delay_s <= 0)


def run(args: argparse.Namespace) -> int:
    from virja.clock import SessionClock
    from virja.config import load_config
    from virja.jam.keyboard import routing_table
    from virja.jam.live import KeyboardJam, RmcpStream
    from virja.jam.ports import MidiInput, MidiOutput, probe_api
    from virja.live.outputs import LiveOutputs, LiveSettings
    from virja.live.viewer import ViewerSpec
    from virja.pipeline import build_performance
    from virja.render.offline import parse_size
    from virja.rmcp.transport import parse_hostport

    if args.duration is not None and args.duration <= 0:
        raise ConfigError("--duration must be > 0")
    size = parse_size(args.size)  # checked before any port opens
    doc = load_config(args.config)
    opts = _options(args, doc)
    if args.list_ports:
        return _list_ports(opts.api)
    send_to = parse_hostport(opts.send) if opts.send else None
    rtp_midi.check(args)

    api = probe_api(opts.api)
    clock = SessionClock()
    with contextlib.ExitStack() as stack, _plan_log(args.plan_log) as log_fh:
        perf = build_performance(
            jam_settings(doc, opts.delay_s, args.config),
            animate=bool(args.web),  # poses here only for the browser; the window animates itself
            plan_log=log_fh,
        )
        perf.origin_s = clock.now_s()  # the plan log counts from the jam's start
        # the window draws in its own process (see virja.live.viewer)
        window = None if args.headless else ViewerSpec(size, "virja jam", opts.fps, hud=args.hud)
        outputs = LiveOutputs.open(perf, LiveSettings(window, web_settings(args)), clock.now_s)
        stack.callback(outputs.close)
        view, web = outputs.viewer, outputs.web
        thru = None
        if opts.thru is not None:
            thru = MidiOutput(api, opts.thru, clock.now_s)
            stack.callback(thru.close)
        stream = None
        if send_to is not None:
            try:
                stream = RmcpStream(*send_to, seq_start=clock.now_us() // 1000)
            except ValueError as exc:
                raise ConfigError(f"--send {opts.send}: {exc}") from exc
            stack.callback(stream.close)
        jam = KeyboardJam(opts.layout, delay_s=opts.delay_s, thru=thru, stream=stream)
        midi_in = MidiInput(api, jam.handle, clock.now_s, port=opts.port)
        stack.callback(midi_in.close)
        rtp = rtp_midi.start_jam(args, clock, jam.handle)  # network keys, as the keyboard's
        if rtp is not None:
            stack.callback(rtp.close)

        where = "connected to" if opts.port else "open, connect your keyboard to"
        print(f"virja jam: {api} input {where} {midi_in.name}")
        if thru is not None:
            print(f"virja jam: thru -> {thru.name} (delay {opts.delay_ms:g} ms)")
        if web is not None:
            print(f"virja jam: web viewer at {web.url}")
        if send_to is not None:
            print(f"virja jam: streaming RMCP/1 to {send_to[0]}:{send_to[1]}")
        for keys, what in routing_table(opts.layout):
            print(f"  {keys}: {what}")
        sys.stdout.flush()

        counts = _loop(perf, jam, midi_in, thru, clock.now_s, opts.fps, args.duration, view, web)
        perf.finish()
    print(
        f"virja jam: {midi_in.received} messages, {counts['bass']} bass and "
        f"{counts['drums']} drum events, {perf.counts['planned']} motions planned, "
        f"{midi_in.reconnects} reconnects"
    )
    if view is not None and view.stats is not None:
        print(f"virja jam: window: {view.stats.frames} frames shown, {view.stats.skipped} skipped")
    return 0


def _loop(
    perf: Performance,
    jam: KeyboardJam,
    midi_in: MidiInput,
    thru: MidiOutput | None,
    now_s: Callable[[], float],
    fps: float,
    duration_s: float | None,
    view: Any = None,
    web: Any = None,
) -> dict[str, int]:
    """The live timer: feed what arrived, commit motions, follow ports; until time or Ctrl-C."""
    counts = {"bass": 0, "drums": 0}
    tick_s = 1.0 / fps
    start = now_s()
    end = None if duration_s is None else start + duration_s
    with contextlib.suppress(KeyboardInterrupt):
        while True:
            now = now_s()
            for arrival in jam.drain():
                performer = arrival.routed.performer
                if performer is None:  # never queued; keeps the type checker honest
                    continue
                counts[performer] += 1
                perf.feed_routed(performer, arrival.routed.event, now_s=arrival.arrival_s)
            perf.advance(now)
            if web is not None:
                web.publish(perf, now)
                forget = getattr(perf.animator, "forget_before", None)
                if forget is not None:
                    forget(now - 20.0)
            if view is not None and view.closed:
                break
            midi_in.poll(now)
            if thru is not None:
                thru.poll(now)
            if end is not None and now >= end:
                break
            next_tick = now + tick_s
            time.sleep(max(0.0, min(next_tick, end or next_tick) - now_s()))
    return counts
