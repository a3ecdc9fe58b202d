"""Measure speed and latency on this machine and print the figures.

Figures (each also as a ratio to its target; >= 1.00x meets it):
  render_fps            the full band at 1280x720 headless, no readback   (target 60)
  render_fps_readback   the same with readback, as for video             (target 30)
  pose_ms               sampling + blending + FK of both players / frame (target 1 ms)
  plan_ms_p99           planning one beat of 16 notes per performer      (target 2 ms)
  rmcp_datagrams_per_s  decode + validate + queue, one core              (target 20000)
  rmcp_latency_ms_p99   loopback datagram to planned note                (target 2 ms)
Benchmarks are never tests: machines here are shared and noisy, so run it a
few times and quote medians.  --quick takes about a third of the time.
"""

from __future__ import annotations

import argparse
import json
import sys


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="one JSON object with every figure")
    p.add_argument("--quick", action="store_true", help="fewer samples (about a third of the time)")


def run(args: argparse.Namespace) -> int:
    from virja.bench import run_all

    def say(msg: str) -> None:
        if not args.json:
            print(f"  measuring {msg} ...", file=sys.stderr, flush=True)

    info, figs = run_all(quick=args.quick, progress=say)
    if args.json:
        out: dict[str, object] = {f.key: round(f.value, 4) for f in figs}
        out["ratios"] = {f.key: round(f.ratio, 3) for f in figs}
        out["targets"] = {f.key: f.target for f in figs}
        out["machine"] = info
        print(json.dumps(out))
        return 0
    print("machine: " + ", ".join(f"{k} {v}" for k, v in info.items()))
    for f in figs:
        verdict = "meets" if f.ratio >= 1 else "misses"
        extra = f"  ({f.note})" if f.note else ""
        print(
            f"{f.key:22s} {f.value:12.3f} {f.unit:12s} target {f.target:g}: {f.ratio:6.2f}x, {verdict}{extra}"
        )
    return 0
