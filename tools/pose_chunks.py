"""The render loops' pose + scene cost, paired, and what posing ahead would change.

    .venv/bin/python tools/pose_chunks.py [--rounds 3] [--input virja/demo/blues.mid]
    .venv/bin/python tools/pose_chunks.py --ahead [--input FILE]

Without ``--ahead``: the offline render's loop over the input at 30 fps, in turn
(``--rounds`` times, thread CPU time per frame): planning alone (feed and commit
at each frame time); frame by frame (plus ``band_scene(perf.pose(t))``, the loop
before the chunks); chunked (``render.offline``'s loop: the timer run ahead, each
stretch of frames until the animator's next news posed at once); and 30-frame
chunks of the input planned whole.  Prints each round and the medians.

With ``--ahead``: poses every frame both as the render loop does (the animator
told each note when its motion starts) and with the notes known up to a second
ahead, and counts the frames that differ (the animator is not causal in what
it is told: why the offline chunks end at each piece of news).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from virja.input import load_performance_input
from virja.pipeline import PerformanceSettings, build_performance
from virja.render.chunks import FrameChunks
from virja.render.offline import CHUNK_FRAMES, _Ahead
from virja.render.scene import band_scene
from virja.session import RevealFeeder, frame_times


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--input", default="virja/demo/blues.mid")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ahead", action="store_true", help="count the frames posing ahead changes")
    args = ap.parse_args()
    settings = PerformanceSettings()
    src = load_performance_input(Path(args.input), settings.routing)
    t0, t1 = src.default_span()
    times = list(frame_times(t0, t1, 30.0))
    n = len(times)

    def performance():  # type: ignore[no-untyped-def]
        return build_performance(settings, src, animate=True), RevealFeeder(src.schedule)

    if args.ahead:
        perf, feeder = performance()
        plain = []
        for t in times:
            feeder.until(perf, t)
            perf.advance(t)
            plain.append(perf.pose(t))
        perf, feeder = performance()
        differ, worst, worst_hihat = 0, 0.0, 0.0
        for i in range(0, n, 30):
            chunk = times[i : i + 30]
            for t in chunk:  # everything the next second commits, told now
                feeder.until(perf, t)
                perf.advance(t)
            for k, pose in enumerate(perf.animator.poses(np.array(chunk))):
                want = plain[i + k]
                d = float(np.abs(pose.drums.positions - want.drums.positions).max())
                h = abs(pose.hihat_open - want.hihat_open)
                worst, worst_hihat = max(worst, d), max(worst_hihat, h)
                differ += d > 1e-9 or h > 1e-9
        print(
            f"{differ} of {n} frames differ when the notes are known a second ahead "
            f"(drummer joints up to {worst * 100:.1f} cm, hi-hat openness up to {worst_hihat:.2f})"
        )
        return
    res: dict[str, list[float]] = {"plan": [], "single": [], "chunked": [], "whole30": []}
    for rnd in range(args.rounds):
        perf, feeder = performance()
        s = time.thread_time()
        for t in times:
            feeder.until(perf, t)
            perf.advance(t)
        res["plan"].append((time.thread_time() - s) * 1000 / n)
        perf, feeder = performance()
        s = time.thread_time()
        for t in times:
            feeder.until(perf, t)
            perf.advance(t)
            band_scene(perf.pose(t)).packed("cylinder")
        res["single"].append((time.thread_time() - s) * 1000 / n)
        perf, feeder = performance()
        s = time.thread_time()
        ahead = _Ahead(perf, feeder, times, CHUNK_FRAMES)
        for t in times:
            ahead.scene(t)
        ahead.close()
        res["chunked"].append((time.thread_time() - s) * 1000 / n)
        perf, feeder = performance()
        feeder.until(perf, float("inf"))
        perf.finish()
        whole = FrameChunks(perf.animator)
        s = time.thread_time()
        for i in range(0, n, 30):
            whole.prepare(times[i : i + 30])
        res["whole30"].append((time.thread_time() - s) * 1000 / n)
        print(f"round {rnd + 1}: " + ", ".join(f"{k} {v[-1]:.3f}" for k, v in res.items()))
    med = {k: statistics.median(v) for k, v in res.items()}
    before, after = med["single"] - med["plan"], med["chunked"] - med["plan"]
    print("medians, ms of CPU per frame: " + ", ".join(f"{k} {v:.3f}" for k, v in med.items()))
    print(
        f"pose + scene: frame by frame {before:.3f} ms, chunked {after:.3f} ms "
        f"({before / after:.2f}x less; {ahead.chunks.frames / ahead.chunks.chunks:.2f} frames "
        f"a chunk); 30-frame chunks {med['whole30']:.3f} ms"
    )


if __name__ == "__main__":
    main()
