"""Where one offline frame's time goes: planning, pose, scene building, GL draw,
read-back, encode.

    .venv/bin/python tools/profile_frame.py [--frames 300] [--size 1280x720] [--cprofile]

Runs the demo (virja/demo/blues.mid) through the offline render's own frame path
(``virja.bench.demo_frames``: the timer run ahead, the band posed and its
instances built a stretch of frames at a time until the animator's next news),
then draws each frame at 30 fps, timing each stage alone (the GL draw is closed
with ``ctx.finish()`` so its cost is not moved into the read-back), and prints
the mean ms per frame of the CPU stages (a chunk's cost is spread over its
frames) and the median of the GL ones.  With ``--cprofile`` it also prints the
top functions of the CPU path (planning, pose, scene).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import time
from pathlib import Path

from virja.bench import demo_frames
from virja.render.camera import PRESETS
from virja.render.hosts import OffscreenTarget, create_headless_context
from virja.render.offline import parse_size
from virja.render.renderer import Renderer
from virja.render.scene import static_scene
from virja.render.video import VideoWriter


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--cprofile", action="store_true")
    args = ap.parse_args()
    size = parse_size(args.size)
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    cam = PRESETS["front"]
    writer = VideoWriter(Path("/tmp/virja-profile.mp4"), size, 30.0, bottom_up=True)
    cpu = {"plan + feed": 0.0, "pose": 0.0, "scene": 0.0}
    gl: dict[str, list[float]] = {k: [] for k in ("draw", "readback", "encode")}
    prof = cProfile.Profile() if args.cprofile else None
    frames = chunks_done = 0
    chunks = None
    loop = demo_frames(args.frames)
    try:
        while True:
            a = time.perf_counter()
            profiling = prof if prof is not None and frames > 0 else None
            if profiling is not None:
                profiling.enable()
            before = (chunks.pose_s, chunks.scene_s) if chunks is not None else (0.0, 0.0)
            try:
                dl, chunks = next(loop)
            except StopIteration:
                break
            finally:
                if profiling is not None:
                    profiling.disable()
            b = time.perf_counter()
            pose_s, scene_s = chunks.pose_s - before[0], chunks.scene_s - before[1]
            if frames:  # the first frame builds the performance (loads the motions): left out
                cpu["pose"] += pose_s
                cpu["scene"] += scene_s
                cpu["plan + feed"] += (b - a) - pose_s - scene_s
            renderer.draw([static, dl], cam, target.fbo)
            ctx.finish()
            c = time.perf_counter()
            raw = target.read_raw_rgb()
            d = time.perf_counter()
            writer.write_raw(raw)
            e = time.perf_counter()
            for k, dt in zip(gl, (c - b, d - c, e - d), strict=True):
                gl[k].append(dt * 1000)
            frames += 1
            chunks_done = chunks.chunks
    finally:
        writer.close()
        target.release()
        renderer.release()
        ctx.release()
    total = 0.0
    print(
        f"{frames} frames, posed in {chunks_done} chunks ({frames / max(chunks_done, 1):.1f} a chunk)"
    )
    for k, s in cpu.items():
        ms = s / max(frames - 1, 1) * 1000
        total += ms
        print(f"{k:12s} {ms:8.3f} ms mean per frame")
    for k, ms_list in gl.items():
        med = statistics.median(ms_list[5:] or ms_list)
        total += med
        print(f"{k:12s} {med:8.3f} ms median")
    print(f"{'sum':12s} {total:8.3f} ms  ({1000 / total:.1f} frames/s serial)")
    if prof:
        pstats.Stats(prof).sort_stats("cumulative").print_stats(30)


if __name__ == "__main__":
    main()
