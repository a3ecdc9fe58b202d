"""The live loop's pose of one frame in a simulated jam: what a key's latency pays twice.

A benchmark, not a test.  Keys as ``tools/jack_latency.py --impact`` plays them (a
snare pad and a bass key in turn, ``--gap-ms`` apart) are fed to the jam's performance
on a simulated clock, a frame every ``--frame-ms``; each frame's ``perf.pose`` is timed
(no JACK, no GL).  Prints the median with and without a key fed in the frame's turn.

Runs against an older tree too, for bisecting (``git archive COMMIT virja motions | tar
-x -C /tmp/X``, then ``PYTHONPATH=/tmp/X``): before ``virja.pipeline`` the jam built its
performance in ``virja.cli.cmd_jam``.

    .venv/bin/python tools/jam_pose.py --seconds 8
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any


def jam_performance() -> Any:
    """The performance ``virja jam`` builds without --delay-ms."""
    try:
        from virja.cli.cmd_jam import jam_settings
        from virja.pipeline import build_performance
    except ImportError:  # trees before pipeline.build_performance (2026-11-23 05:10)
        from virja.cli import cmd_jam

        return cmd_jam.build_performance({}, plan_log=None, animate=True, delay_s=0.0)  # type: ignore[attr-defined]
    return build_performance(jam_settings({}, delay_s=0.0), animate=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--seconds", type=float, default=8.0, help="simulated jam length")
    ap.add_argument("--gap-ms", type=float, default=120.0, help="between keys")
    ap.add_argument("--frame-ms", type=float, default=14.0, help="between frames")
    ap.add_argument("--lead-ms", type=float, default=13.7, help="a frame shows now + lead")
    args = ap.parse_args()

    from virja.jam.keyboard import KeyboardLayout, decode, route

    perf = jam_performance()
    layout = KeyboardLayout()
    t = 100.0  # session seconds
    end = t + args.seconds
    next_key = t + 0.3
    i = 0
    plain: list[float] = []
    after_key: list[float] = []
    while t < end:
        fed = False
        if t >= next_key:
            msg = bytes([0x90, 36 + i % 12, 100]) if i % 2 else bytes([0x99, 38, 100])
            r = route(decode(msg, time_s=t), layout)
            if r is not None and r.performer is not None:
                perf.feed_routed(r.performer, r.event, now_s=t)
                fed = True
            i += 1
            next_key += args.gap_ms / 1000.0
        perf.advance(t)
        a = time.perf_counter()
        perf.pose(t + args.lead_ms / 1000.0)
        (after_key if fed else plain).append(time.perf_counter() - a)
        t += args.frame_ms / 1000.0
    print(
        f"pose of one frame: median {statistics.median(plain) * 1000:.2f} ms "
        f"({len(plain)} frames), {statistics.median(after_key) * 1000:.2f} ms in the frame "
        f"after a key ({len(after_key)})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
