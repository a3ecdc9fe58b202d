"""Measure speed and latency on this machine and print the figures.

Figures (each as a ratio to its target; >= 1.00x meets it):
  rmcp_datagrams_per_s     decode + validate + queue, one core                 (target 50000)
  rmcp_latency_ms_p99      loopback datagram to planned note                   (target 2 ms)
  plan_ms_p99              planning one beat of 16 notes per performer         (target 1 ms)
  pose_ms                  sampling + blending + FK of both players / frame    (target 1 ms)
  pose_scene_ms            pose and building the frame's instances / frame     (target 0.5 ms)
                           both as the render loops do it: the offline render's
                           loop over the demo, posing each stretch of frames until
                           the animator's next news at once, amortised per frame
                           (one frame at a time, and 30-frame chunks, beside it)
  gl_draw_ms               GL draw of one 1280x720 frame until finished        (1.5x the fps before)
  render_fps               the full band at 1280x720 headless, no readback     (1.5x the fps before)
                           (posed and built as the offline render does)
  render_fps_readback      the same with readback, as for video                (1.5x the fps before)
  offline_realtime_factor  `virja render` of the demo to .mp4 with sound       (target 2x)
  jam_key_to_impact_ms     key through JACK to the frame showing its impact    (target 35 ms)
The machines here are shared and noisy: a fixed reference workload is timed
through the run, and each CPU figure is also given corrected by how much slower
that reference ran than on the quiet machine ("load-corrected").  Benchmarks are
never tests: run it a few times and quote medians.  --quick takes about a third
of the time (and renders 8 s of the demo, not all of it).
"""

from __future__ import annotations

import argparse
import json
import math
import sys


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="one JSON object with every figure")
    p.add_argument("--quick", action="store_true", help="fewer samples (about a third of the time)")
    p.add_argument("--no-jam", action="store_true", help="skip the JACK key-to-impact figure")
    p.add_argument("--no-offline", action="store_true", help="skip the offline render of the demo")


def run(args: argparse.Namespace) -> int:
    from virja.bench import run_all

    def say(msg: str) -> None:
        if not args.json:
            print(f"  measuring {msg} ...", file=sys.stderr, flush=True)

    info, figs = run_all(
        quick=args.quick, progress=say, jam=not args.no_jam, offline=not args.no_offline
    )
    if args.json:
        out: dict[str, object] = {
            f.key: (round(f.value, 4) if math.isfinite(f.value) else None) for f in figs
        }
        out["ratios"] = {f.key: round(f.ratio, 3) for f in figs if math.isfinite(f.value)}
        out["load_corrected_ratios"] = {
            f.key: round(r, 3) for f in figs if (r := f.ref_ratio) is not None
        }
        out["targets"] = {f.key: round(f.target, 4) for f in figs}
        out["notes"] = {f.key: f.note for f in figs if f.note}
        out["machine"] = info
        print(json.dumps(out))
        return 0
    print("machine: " + ", ".join(f"{k} {v}" for k, v in info.items()))
    for f in figs:
        extra = f"  ({f.note})" if f.note else ""
        if not math.isfinite(f.value):
            print(f"{f.key:24s} {'-':>12s} {f.unit:12s} target {f.target:g}{extra}")
            continue
        verdict = "meets" if f.ratio >= 1 else "misses"
        ref = f.ref_ratio
        corrected = f"; load-corrected {ref:.2f}x" if ref is not None else ""
        print(
            f"{f.key:24s} {f.value:12.3f} {f.unit:12s} target {f.target:.4g}: "
            f"{f.ratio:6.2f}x, {verdict}{corrected}{extra}"
        )
    return 0
