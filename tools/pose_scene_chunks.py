"""`virja bench`'s pose_scene_ms loop chunk by chunk: where its run-to-run spread comes from.

    .venv/bin/python tools/pose_scene_chunks.py [--frames 600] [--label after]

Runs the loop ``virja.bench.pose_scene_ms`` measures (``demo_frames``: the demo played
through whole, then posed and built 120 frames at a time) in this process and prints
its figure (pose + scene ms a frame, as the bench computes it), then for each chunk the
pose and scene ms, the fresh pages it touched (minor faults, ``getrusage``) and the
cyclic collector's runs inside it (``gc.callbacks``: count per generation and ms).

Run it once per fresh process; to compare two trees, run it from outside the checkout
with each tree on ``PYTHONPATH`` in turn (a ``python -c`` in the checkout would import
the checkout's ``virja`` whatever ``PYTHONPATH`` says; a script's own folder comes
first instead, and tools/ holds no ``virja``):

    REPO=$PWD; cd /tmp && for i in 1 2 3; do
      PYTHONPATH=/tmp/before $REPO/.venv/bin/python $REPO/tools/pose_scene_chunks.py --label before
      PYTHONPATH=$REPO $REPO/.venv/bin/python $REPO/tools/pose_scene_chunks.py --label after; done
"""

from __future__ import annotations

import argparse
import gc
import resource
import time
from typing import Any

import virja
import virja.render.chunks as chunks_mod
from virja.bench import demo_frames


def _faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--label", default="", help="a word to start the figure's line with")
    args = ap.parse_args()

    rows: list[tuple[int, float, float, int, dict[int, int], float]] = []
    runs: list[tuple[int, float]] = []
    started: list[float] = []
    inside = [False]

    def collector(phase: str, info: dict[str, Any]) -> None:
        if phase == "start":
            started[:] = [time.perf_counter()]
        elif inside[0] and started:
            runs.append((int(info["generation"]), (time.perf_counter() - started[0]) * 1000))

    real = chunks_mod.FrameChunks.prepare

    def prepare(self: Any, times: Any) -> None:
        pose0, scene0, faults0, runs0 = self.pose_s, self.scene_s, _faults(), len(runs)
        inside[0] = True
        try:
            real(self, times)
        finally:
            inside[0] = False
        mine = runs[runs0:]
        per_gen: dict[int, int] = {}
        for g, _ms in mine:
            per_gen[g] = per_gen.get(g, 0) + 1
        rows.append(
            (
                len(times),
                (self.pose_s - pose0) * 1000,
                (self.scene_s - scene0) * 1000,
                _faults() - faults0,
                per_gen,
                sum(ms for _g, ms in mine),
            )
        )

    chunks_mod.FrameChunks.prepare = prepare  # type: ignore[method-assign]
    gc.callbacks.append(collector)
    loop = demo_frames(args.frames)
    _scene, chunks = next(loop)
    for _scene, _chunks in loop:
        pass
    figure = (chunks.pose_s + chunks.scene_s) / max(chunks.frames, 1) * 1000
    print(f"{args.label} {figure:.3f} ms a frame (pose + scene)  [virja from {virja.__file__}]")
    print("chunk  frames  pose ms  scene ms  fresh pages  collections (gen: count)  their ms")
    for k, (n, pose, scene, faults, per_gen, ms) in enumerate(rows, 1):
        gens = ", ".join(f"{g}: {c}" for g, c in sorted(per_gen.items())) or "-"
        print(f"{k:5d}  {n:6d}  {pose:7.1f}  {scene:8.1f}  {faults:11d}  {gens:24s}  {ms:8.2f}")


if __name__ == "__main__":
    main()
