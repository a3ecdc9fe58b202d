"""Objective evaluation of method B on synthetic teachers (figures for docs/dance.md).

Builds three teachers of distinct styles (bounce, sway, kick), each with its
own music; teaches a database per teacher (``--parts``); generates motion for
new music with each; prints beat alignment (generated motion against the new
music's beats, with a control of beats shifted by half a median interval) and
the style-inheritance accuracy of a nearest-centroid classifier trained on the
captures.  Also prints the beat-extraction / AR benchmark.

    .venv/bin/python tools/dance_eval.py [--parts legs] [--seed 0] [--json]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from virja.dance import bench, evaluate
from virja.dance.beats import extract_beats
from virja.dance.database import teach
from virja.dance.generate import generate
from virja.dance.synth_capture import STYLES, make_teacher, random_boundaries
from virja.dance.synth_music import music


def evaluate_all(parts: str, seed: int, h: int | None = None) -> dict[str, object]:
    teachers = {}
    generated = {}
    align: dict[str, dict[str, float]] = {}
    rng = np.random.default_rng(seed)
    new_beats = 0.5 + np.cumsum(rng.uniform(0.3, 1.0, 60))
    new_music = music(
        new_beats, new_beats[-1] + 0.5, rng.integers(0, 3, 59).tolist(), seed=seed + 100
    )
    found = extract_beats(new_music)
    half = float(np.median(np.diff(found))) / 2
    n_segments = {}
    for i, style in enumerate(sorted(STYLES)):
        t = make_teacher(
            style, random_boundaries(40, np.random.default_rng(seed + i)), seed=seed + i
        )
        colours = np.random.default_rng(seed + 10 + i).integers(0, 3, len(t.beats_s) - 1).tolist()
        x = music(t.beats_s, t.bvh.n_frames / 30 + 0.3, colours, seed=seed + 20 + i)
        db = teach(t.bvh, x, parts)  # type: ignore[arg-type]
        n_segments[style] = len(db.segments)
        g = generate(db, new_music, h=h)
        teachers[style] = t.bvh
        generated[style] = g.bvh
        align[style] = {
            "teacher_vs_own_beats": evaluate.beat_align_bvh(t.bvh, t.beats_s),
            "generated_vs_music_beats": evaluate.beat_align_bvh(g.bvh, found.tolist()),
            "generated_vs_shifted_beats": evaluate.beat_align_bvh(g.bvh, (found + half).tolist()),
        }
    report = evaluate.style_accuracy(teachers, generated)
    return {
        "parts": parts,
        "seed": seed,
        "h": h,
        "segments": n_segments,
        "beat_align": align,
        "style_accuracy": report.accuracy,
        "style_per_teacher": report.per_teacher,
        "style_confusion": report.confusion,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--parts", default="legs", choices=["legs", "arms", "all"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    ap.add_argument(
        "--h", type=int, default=None, help="join window (default: 2 x shortest segment, paper)"
    )
    args = ap.parse_args()
    result = evaluate_all(args.parts, args.seed, args.h)
    result["bench"] = bench.run()
    if args.json:
        print(json.dumps(result, indent=1))
        return
    print(f"parts={args.parts} seed={args.seed} segments={result['segments']}")
    for style, s in result["beat_align"].items():  # type: ignore[attr-defined]
        print(f"  {style:7s} " + "  ".join(f"{k}={v:.3f}" for k, v in s.items()))
    print(
        f"  style accuracy {result['style_accuracy']:.3f}  per teacher {result['style_per_teacher']}"
    )
    print(f"  bench {result['bench']}")


if __name__ == "__main__":
    main()
