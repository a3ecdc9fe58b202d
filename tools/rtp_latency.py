"""Note-sent-to-impact-drawn latency through RTP-MIDI, with node-rtpmidi as the sender.

A benchmark, not a test.  node-rtpmidi (tools/node/rtp_peer.js) invites an
in-process RTP-MIDI listener (:class:`virja.rtpmidi.transport.Listener`, the
one ``virja serve --rtp-midi`` runs, drawing on the same asyncio loop, as serve
did before its window moved to a viewer process), syncs, and sends ``--notes`` notes ``--gap-ms`` apart,
alternating a snare on channel 10 and a bass note on channel 1.  Each note
goes the serve path: the session host, the router, the scheduler with the
jam's immediate strokes, the animator, and the full band drawn headless at
``--size`` each frame (the pose of the moment the frame appears, as the live
view draws it).  A note's latency runs from node's send time (Unix time from
``performance.timeOrigin + performance.now()``) to the end of drawing the
first frame whose time is at or after the note's impact.  Also printed: sent
to received (the network and the codec).

Prints the median, 95th percentile and worst.

    .venv/bin/python tools/rtp_latency.py --notes 100 --gap-ms 120
"""

from __future__ import annotations

import argparse
import asyncio
import json
import socket
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _free_even_port() -> int:
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(("127.0.0.1", 0))
            p = s.getsockname()[1] & ~1
        try:
            with (
                socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as a,
                socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as b,
            ):
                a.bind(("127.0.0.1", p))
                b.bind(("127.0.0.1", p + 1))
                return p
        except OSError:
            continue


async def measure(
    notes: int, gap_s: float, size: tuple[int, int], draw: bool = True
) -> tuple[list[float], list[float], list[float]]:
    from virja.clock import SessionClock
    from virja.pipeline import PerformanceSettings, build_performance
    from virja.render.camera import PRESETS
    from virja.render.hosts import OffscreenTarget, create_headless_context
    from virja.render.renderer import Renderer
    from virja.render.scene import band_scene, static_scene
    from virja.routing import RoutingConfig
    from virja.rtpmidi.recording import to_received
    from virja.rtpmidi.transport import Listener

    clock = SessionClock()
    routing = RoutingConfig.from_dict({"channels": {"1": "bass"}}, "[routing]")
    # RTP-MIDI notes are played at once: the shortest strokes, as `serve --rtp-midi`
    perf = build_performance(PerformanceSettings(routing=routing, immediate=True), animate=True)
    arrivals: list[float] = []
    pending: list[tuple[float, float]] = []  # (impact, note time) of motions not drawn yet

    def on_messages(messages: list, now_s: float) -> None:  # type: ignore[type-arg]
        for rec in to_received(messages):
            if perf.feed(rec.event, now_s=rec.arrival_s) is not None:
                arrivals.append(rec.arrival_s)
        pending.extend((p.impact, p.time) for p in perf.advance(now_s))

    listener = Listener(clock, on_messages)
    _host, port = await listener.start("127.0.0.1", 0)
    plan = [
        {
            "after_ms": round(gap_s * 1000),
            "messages": [[0x99, 38, 100] if i % 2 else [0x90, 40, 100]],
        }
        for i in range(notes)
    ]
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    drawn_at: dict[float, float] = {}  # note time -> when its impact was drawn
    with tempfile.TemporaryDirectory() as tmp:
        plan_path = Path(tmp) / "plan.json"
        plan_path.write_text(json.dumps(plan))
        node = await asyncio.create_subprocess_exec(
            "node", str(ROOT / "tools" / "node" / "rtp_peer.js"), "127.0.0.1", str(port),
            str(_free_even_port()), str(plan_path),
            stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.DEVNULL,
        )  # fmt: skip
        out_task = asyncio.create_task(node.communicate())
        lead_s = 0.0
        frame_s: list[float] = []
        while not out_task.done():
            now = clock.now_us() / 1e6
            for p in perf.advance(now):
                pending.append((p.impact, p.time))
            shown = now + lead_s
            if draw:
                renderer.draw([static, band_scene(perf.pose(shown))], PRESETS["front"], target.fbo)
                target.finish()
            else:
                await asyncio.sleep(0.001)
            drawn = clock.now_us() / 1e6
            frame_s.append(drawn - now)
            lead_s = min(0.1, 0.8 * lead_s + 0.2 * (drawn - now))
            still = []
            for impact, note_time in pending:
                if impact <= shown:
                    drawn_at[note_time] = drawn
                else:
                    still.append((impact, note_time))
            pending[:] = still
            await asyncio.sleep(0)
        stdout, _ = out_task.result()
    await listener.close()
    target.release()
    renderer.release()
    ctx.release()
    sent = [json.loads(x)["sent_us"] / 1e6 for x in stdout.decode().splitlines() if "sent_us" in x]
    if len(sent) != len(arrivals):
        raise SystemExit(f"sent {len(sent)} notes, {len(arrivals)} arrived")
    received = [a - s for a, s in zip(arrivals, sent, strict=True)]
    impact = [drawn_at[a] - s for a, s in zip(arrivals, sent, strict=True) if a in drawn_at]
    return received, impact, frame_s


def _report(what: str, lat: list[float], unit: str = "notes") -> None:
    if not lat:
        print(f"{what}: none")
        return
    ms = sorted(x * 1000 for x in lat)
    p95 = ms[min(len(ms) - 1, round(0.95 * (len(ms) - 1)))]
    print(
        f"{what}: {len(ms)} {unit}, median {statistics.median(ms):.1f} ms, "
        f"p95 {p95:.1f} ms, worst {ms[-1]:.1f} ms"
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--notes", type=int, default=100)
    ap.add_argument("--gap-ms", type=float, default=120.0)
    ap.add_argument("--size", default="1280x720", help="frame size drawn")
    ap.add_argument(
        "--no-draw", action="store_true", help="poll every 1 ms instead of drawing (the path alone)"
    )
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    received, impact, frames = asyncio.run(
        measure(args.notes, args.gap_ms / 1000, (w, h), draw=not args.no_draw)
    )
    _report("sent-to-received", received)
    drawn = "polled every 1 ms" if args.no_draw else f"drawn at {args.size}"
    _report(f"sent-to-impact ({drawn})", impact)
    _report("one turn of the loop (a frame drawn, or a poll)", frames, "turns")
    return 0


if __name__ == "__main__":
    sys.exit(main())
