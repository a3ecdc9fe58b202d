"""Replay a pcap recording of RMCP traffic through the same receiver and scheduler.

The recorded datagrams are fed at their recorded receive times (a virtual
clock), so --plan-log gives the plan the live daemon made.  With --out the
band is rendered headless to a video or PNG frames (as `virja render`); with
--headless nothing is drawn (plan log and summary only, as fast as possible);
otherwise it plays in a window in real time (and with --web to browsers,
window or not).  Reads pcaps written by
`virja serve --record`, tcpdump or Wireshark (pcap and pcapng).  RTP-MIDI
sessions in the recording (`serve --rtp-midi`) are found by their invitation
and replayed through the same session host, their notes played at once as live.

examples:
  virja replay session.pcap --headless --plan-log replay.jsonl
  virja replay session.pcap --out session.mp4
  virja replay capture.pcapng --port 50600
  virja replay session.pcap --headless --web      # watch at http://127.0.0.1:8080/
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

from virja.cli.common import (
    SAMPLE_CHOICES,
    add_routing_arguments,
    finite_float,
    open_plan_log,
    performance_settings,
)
from virja.cli.web_option import add_web_arguments, web_settings
from virja.errors import ConfigError, InputFileError
from virja.render.camera import PRESETS

if TYPE_CHECKING:
    from virja.input import PerformanceInput
    from virja.live.outputs import LiveSettings
    from virja.pipeline import PerformanceSettings
    from virja.session import Performance


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("input", metavar="FILE.pcap", help="a pcap or pcapng recording")
    p.add_argument(
        "--port", type=int, default=None, help="RMCP UDP port in the capture (default 50500)"
    )
    p.add_argument("--key-file", metavar="FILE", help="HMAC key, as the live daemon had it")
    p.add_argument(
        "--plan-log",
        metavar="FILE.jsonl",
        help="write the plan, one JSON object per note (times from the recording's first "
        "packet; session_time: Unix seconds)",
    )
    p.add_argument("--headless", action="store_true", help="draw nothing: plan and summary only")
    p.add_argument(
        "--hud",
        action="store_true",
        help="heads-up display (tempo, bar.beat, chord): in the window (key H toggles it) "
        "and in --out renders",
    )
    p.add_argument(
        "--out", metavar="OUT", help="render to a video (.mp4/.mkv/.mov), a folder or NAME.png"
    )
    p.add_argument(
        "--as-live",
        action="store_true",
        help="with --out: draw each frame knowing only what the live window would know at its time "
        "(motions learned as they start); default: the whole input known, as motion-report "
        "and export see it",
    )
    p.add_argument("--size", default="1280x720", metavar="WxH")
    p.add_argument("--fps", type=finite_float, default=30.0)
    p.add_argument("--camera", choices=sorted(PRESETS), default="front")
    p.add_argument("--no-audio", action="store_true")
    p.add_argument("--soundfont", metavar="FILE.sf2")
    p.add_argument(
        "--samples",
        type=int,
        default=1,
        choices=SAMPLE_CHOICES,
        help="multisampling (default 1 = off)",
    )
    from virja.cli.cmd_render import add_dancer_argument

    add_dancer_argument(p)
    add_web_arguments(p)
    add_routing_arguments(p)


def run(args: argparse.Namespace) -> int:
    from virja.input import pcap_input

    if args.port is not None and not 1 <= args.port <= 65535:
        raise ConfigError(f"--port must be 1-65535, got {args.port}")
    if args.dancer and not args.out:
        raise ConfigError("--dancer draws into a rendering: give --out too")
    settings = performance_settings(args)
    request = None
    if args.out:
        from virja.cli.cmd_render import check_outputs, render_request

        # the whole recording: replay has no --at, --start, --end or --bvh
        request = render_request(args, settings, span=False)
        check_outputs(request)  # before the work
    src = pcap_input(Path(args.input), settings.routing, port=args.port, key_file=args.key_file)
    for line in src.report:
        print(line)
    if not src.schedule:
        raise InputFileError(args.input, "the recording holds no valid RMCP events")
    if request is not None:
        from virja.cli.cmd_render import render_input

        return render_input(src, request)
    return play(src, settings, args)


def play(src: PerformanceInput, settings: PerformanceSettings, args: argparse.Namespace) -> int:
    from virja.pipeline import build_performance
    from virja.session import run_schedule

    plan_log = open_plan_log(args.plan_log)
    perf = build_performance(settings, src, plan_log=plan_log)
    try:
        if args.headless and not args.web:
            run_schedule(perf, src.schedule)
        else:
            play_live(perf, src, args)
    finally:
        if plan_log is not None:
            plan_log.close()
    print(
        f"replayed {len(src.schedule)} events: {perf.counts['planned']} notes planned "
        f"({perf.counts['planned_late']} late), {perf.counts['notes_not_the_bands']} not the band's"
    )
    return 0


WINDOW_CHECK_S = 0.1  # the replay notices a closed window within this long


def live_settings(args: argparse.Namespace) -> LiveSettings:
    """The window (unless --headless) and --web of a replay in real time."""
    from virja.live.outputs import LiveSettings
    from virja.live.viewer import ViewerSpec
    from virja.render.offline import parse_size

    window = None
    if not args.headless:
        window = ViewerSpec(  # --fps is the video's rate; the window follows the display
            parse_size(args.size),
            f"virja replay {Path(args.input).name}",
            samples=args.samples,
            camera=args.camera,
            hud=args.hud,
        )
    return LiveSettings(window=window, web=web_settings(args))


def play_live(perf: Performance, src: PerformanceInput, args: argparse.Namespace) -> None:
    """The recording in real time: this process feeds and plans, sleeping to the next
    reveal, motion start or web frame; the window's own process draws (as in `serve`);
    with --web the browsers' frames are posed here by an animator of our own."""
    from virja.live.outputs import LiveOutputs
    from virja.live.timer import wake_in
    from virja.session import RevealFeeder

    feeder = RevealFeeder(src.schedule)
    t0, t1 = src.default_span()
    wall0 = [time.monotonic()]

    def now_s() -> float:
        return float(t0 + (time.monotonic() - wall0[0]))

    outputs = LiveOutputs.open(perf, live_settings(args), now_s)
    viewer, web = outputs.viewer, outputs.web
    try:
        if web is not None:
            print(f"virja replay: web viewer at {web.url}", flush=True)
        wall0[0] = time.monotonic()  # the recording starts once the window is open
        if viewer is not None:
            viewer.sync_clock()
        while viewer is None or not viewer.closed:
            t = now_s()
            if t > t1:
                break
            feeder.until(perf, t)
            perf.advance(t)
            reveal = src.schedule[feeder.next].at_s if not feeder.done else math.inf
            deadlines = [reveal, perf.planner.next_deadline(), t1, t + WINDOW_CHECK_S]
            if web is not None:
                web.publish(perf, t)
                outputs.sinks.forget_before(t - 20.0)
                deadlines.append(t + 1 / web.fps)
            time.sleep(wake_in(deadlines, now_s()))
    finally:
        outputs.close()
    feeder.until(perf, math.inf)
    perf.finish()
