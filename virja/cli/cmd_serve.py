"""Receive RMCP/1 over UDP and draw the band playing what arrives.

Binds 127.0.0.1:50500 by default (anything wider is an explicit --listen);
every datagram goes through the receiver (validation, signing, duplicates,
horizon, lateness), the notes to the scheduler, the motions to the animator,
and the band to a window (or nowhere with --headless).  Stops on SIGINT or
SIGTERM, or after --duration, printing a summary: datagrams by kind, drops by
reason, late notes, the clock offset.

examples:
  virja serve --headless --plan-log plan.jsonl --record session.pcap
  virja serve --listen [::]:50500 --group 239.255.50.50
  virja serve --headless --web 127.0.0.1:8080   # watch at http://127.0.0.1:8080/
  virja send virja/demo/blues.mid --to 127.0.0.1:50500   # in another shell
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import signal
import sys
import time
from dataclasses import dataclass, field
from typing import Any

from virja.cli.common import add_routing_arguments, finite_float, make_router, open_plan_log
from virja.cli.web_option import add_web_arguments, open_web
from virja.config import load_config
from virja.errors import ConfigError

STATUS_EVERY_S = 5.0
TICK_S = 0.005
KEEP_MOTION_S = 20.0


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
        "--record",
        metavar="FILE.pcap",
        help="record every datagram that arrives (valid or not) as pcap",
    )
    p.add_argument(
        "--plan-log",
        metavar="FILE.jsonl",
        help="write each planned note as one JSON object per line",
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
    p.add_argument("--quiet", action="store_true", help="no status line")
    add_web_arguments(p)
    add_routing_arguments(p)


@dataclass
class Daemon:
    """The live pipeline's state, shared by the receive callback and the tick task."""

    perf: Any
    receiver: Any
    clock: Any
    recorder: Any = None
    clock_client: Any = None
    late_notes: int = 0
    started_s: float = field(default_factory=time.monotonic)

    def on_events(self, received: list[Any], now_s: float) -> None:
        from virja.events import NoteOn

        band = False
        for rec in received:
            if self.perf.feed(rec.event, now_s=rec.arrival_s) is not None:
                band = True
            if rec.late and isinstance(rec.event, NoteOn):
                self.late_notes += 1
        if band:  # plan at once; other traffic waits for the next tick
            self.perf.advance(now_s)

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
        lines = [
            f"datagrams: {st.datagrams} received, {st.accepted} accepted",
            "by kind: " + (", ".join(f"{k} {v}" for k, v in sorted(st.by_kind.items())) or "none"),
            "dropped: " + (", ".join(f"{k} {v}" for k, v in sorted(st.dropped.items())) or "none"),
            f"notes: {self.perf.counts['planned']} planned, {self.late_notes} arrived late "
            f"(played compressed), {self.perf.counts['notes_not_the_bands']} not the band's",
        ]
        summary = self.perf.planner.report.summary()
        if summary:
            lines.append("scheduler: " + ", ".join(f"{k} {v}" for k, v in summary.items()))
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
        return lines


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


async def serve(args: argparse.Namespace) -> int:
    from virja.clock import SessionClock
    from virja.motion.band import BandAnimator
    from virja.plan.config import load_plan_config
    from virja.plan.planner import OnlinePlanner
    from virja.render.offline import parse_size
    from virja.rmcp.pcap import PcapWriter
    from virja.rmcp.receiver import Receiver, ReceiverConfig
    from virja.rmcp.signing import load_key
    from virja.rmcp.transport import ClockClient, RmcpProtocol, open_listener, parse_hostport
    from virja.session import Performance

    load_config(args.config)  # fail early on a bad file
    if args.duration is not None and args.duration <= 0:
        raise ConfigError("--duration must be > 0")
    if args.horizon <= 0 or args.lateness_ms < 0:
        raise ConfigError("--horizon must be > 0 and --lateness-ms >= 0")
    host, port = parse_hostport(args.listen)
    key = load_key(args.key_file) if args.key_file else None
    clock = SessionClock()
    receiver = Receiver(
        ReceiverConfig(horizon_s=args.horizon, lateness_s=args.lateness_ms / 1000, key=key)
    )
    clock_server = parse_hostport(args.clock_server) if args.clock_server else None
    if clock_server is not None:
        _resolve_or_fail(clock_server, "--clock-server")
    # bind first: a port in use must not cost the user an existing plan log or recording
    perf = Performance(
        router=make_router(args),
        planner=OnlinePlanner(load_plan_config(args.config)),
        animator=BandAnimator(),
    )
    perf.keep_planned = False  # a daemon runs for hours: memory stays flat
    daemon = Daemon(perf=perf, receiver=receiver, clock=clock)
    protocol = RmcpProtocol(receiver, clock, daemon.on_events)
    transport = await open_listener(host, port, protocol, group=args.group)
    bound = transport.get_extra_info("sockname")
    view = web = None
    try:
        web = open_web(args, perf, lambda: clock.now_us() / 1e6)
        if not args.headless:
            from virja.render.live import LiveView

            view = LiveView(parse_size(args.size), title=f"virja serve {host}:{port}")
        perf.plan_log = open_plan_log(args.plan_log)
        if args.record:
            # the recording names the address and port actually bound (port 0 picks one)
            wildcard = bound[0] in ("0.0.0.0", "::")
            local_host = ("::1" if ":" in bound[0] else "127.0.0.1") if wildcard else bound[0]
            recorder = PcapWriter.open(args.record, local=(local_host, bound[1]))
            protocol.recorder = daemon.recorder = recorder
    except BaseException:
        transport.close()
        if view is not None:
            view.close()
        if web is not None:
            web.close()
        if perf.plan_log is not None:
            perf.plan_log.close()
        raise
    plan_log = perf.plan_log
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

    async def ticker() -> None:
        last_status = time.monotonic()
        while not stop.is_set():
            daemon.tick()
            if web is not None:
                web.publish(perf, clock.now_us() / 1e6)
            if view is not None:
                now_s = clock.now_us() / 1e6
                view.frame(perf, now_s)
                if view.closed:
                    stop.set()
            if perf.animator is not None:
                perf.animator.forget_before(clock.now_us() / 1e6 - KEEP_MOTION_S)
            if not args.quiet and time.monotonic() - last_status >= STATUS_EVERY_S:
                last_status = time.monotonic()
                print(f"virja serve: {daemon.status()}", file=sys.stderr, flush=True)
            await asyncio.sleep(TICK_S if view is None else 0)

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
        daemon.tick()
        perf.finish()  # notes planned ahead of the stop are logged too, as replay logs them
        if daemon.recorder is not None:
            daemon.recorder.close()
        if plan_log is not None:
            plan_log.close()
        if view is not None:
            view.close()
        if web is not None:
            web.close()
    print("virja serve: stopped")
    for line in daemon.summary() + ([web.summary()] if web is not None else []):
        print(f"  {line}")
    return 0
