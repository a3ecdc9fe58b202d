"""Where one offline frame's time goes: pose, scene building, GL draw, read-back, encode.

    .venv/bin/python tools/profile_frame.py [--frames 300] [--size 1280x720] [--cprofile]

Runs the demo (virja/demo/blues.mid) frame by frame at 30 fps, timing each
stage alone (the GL draw is closed with ``ctx.finish()`` so its cost is not
moved into the read-back), and prints the median ms per stage.  With
``--cprofile`` it also prints the top functions of the CPU path (pose + scene).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import time

import numpy as np

from virja.bench import _demo_animator
from virja.render.camera import PRESETS
from virja.render.hosts import OffscreenTarget, create_headless_context
from virja.render.offline import parse_size
from virja.render.renderer import Renderer
from virja.render.scene import band_scene, static_scene
from virja.render.video import VideoWriter


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--cprofile", action="store_true")
    args = ap.parse_args()
    size = parse_size(args.size)
    animator, t0, t1 = _demo_animator()
    times = t0 + (np.arange(args.frames) / 30.0) % max(t1 - t0, 1e-3)
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    cam = PRESETS["front"]
    writer = VideoWriter(
        __import__("pathlib").Path("/tmp/virja-profile.mp4"), size, 30.0, bottom_up=True
    )
    stages: dict[str, list[float]] = {
        k: [] for k in ("pose", "scene", "draw", "readback", "encode")
    }
    prof = cProfile.Profile() if args.cprofile else None
    try:
        for t in times.tolist():
            a = time.perf_counter()
            if prof:
                prof.enable()
            pose = animator.pose(t)
            b = time.perf_counter()
            dl = band_scene(pose)
            c = time.perf_counter()
            if prof:
                prof.disable()
            renderer.draw([static, dl], cam, target.fbo)
            ctx.finish()
            d = time.perf_counter()
            raw = target.read_raw_rgb()
            e = time.perf_counter()
            writer.write_raw(raw)
            f = time.perf_counter()
            for k, dt in zip(stages, (b - a, c - b, d - c, e - d, f - e), strict=True):
                stages[k].append(dt * 1000)
    finally:
        writer.close()
        target.release()
        renderer.release()
        ctx.release()
    total = 0.0
    for k, ms in stages.items():
        med = statistics.median(ms[5:])
        total += med
        print(f"{k:9s} {med:8.3f} ms median")
    print(f"{'sum':9s} {total:8.3f} ms  ({1000 / total:.1f} frames/s serial)")
    if prof:
        pstats.Stats(prof).sort_stats("cumulative").print_stats(25)


if __name__ == "__main__":
    main()
