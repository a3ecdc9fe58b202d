"""Beat extraction on a rendered jazz set: F-measure (70 ms) against the files' quarter notes.

Builds the set (virja.dance.jazz_set: eleven accompaniments, 60-300 bpm,
rendered by fluidsynth with the GM soundfont) into --set (kept between
runs), extracts beats from every WAV as `virja beats` does and prints, per
clip, F, precision, recall and the median offset of the matched beats.

    .venv/bin/python tools/beat_eval.py [--set /tmp/virja-jazz] [--k 1.5] [--no-periodicity]
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from virja.dance.audio import read_audio_8k  # noqa: E402
from virja.dance.beat_score import beat_score  # noqa: E402
from virja.dance.beats import BeatParams, extract_beats  # noqa: E402
from virja.dance.jazz_set import build_set  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--set", default="/tmp/virja-jazz", help="folder of the rendered set")
    ap.add_argument("--k", type=float, default=None, help="threshold k (MADs above the median)")
    ap.add_argument("--window-s", type=float, default=None, help="local threshold window (s)")
    ap.add_argument("--no-periodicity", action="store_true", help="the paper's rule alone")
    ap.add_argument("--json", action="store_true", help="print the scores as JSON")
    args = ap.parse_args()
    params = BeatParams(periodicity=not args.no_periodicity)
    if args.k is not None:
        params = replace(params, k_mad=args.k)
    if args.window_s is not None:
        params = replace(params, local_window_s=args.window_s)
    manifest = build_set(args.set)
    rows = []
    for clip in json.loads(manifest.read_text(encoding="utf-8"))["clips"]:
        audio = read_audio_8k(manifest.parent / clip["wav"])
        est = extract_beats(audio, params)
        s = beat_score(est.tolist(), clip["beats"])
        rows.append({"name": clip["name"], "bpm": clip["bpm"], **s.__dict__})
    mean_f = float(np.mean([r["f"] for r in rows]))
    if args.json:
        print(json.dumps({"mean_f": mean_f, "clips": rows}, indent=1))
        return 0
    print(f"{'clip':<12} {'bpm':>4} {'F':>5} {'P':>5} {'R':>5} {'offset ms':>9}")
    for r in rows:
        print(
            f"{r['name']:<12} {r['bpm']:>4.0f} {r['f']:5.2f} {r['precision']:5.2f} "
            f"{r['recall']:5.2f} {1000 * r['median_offset_s']:9.0f}"
        )
    print(f"mean F {mean_f:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
