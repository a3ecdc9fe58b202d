"""Honest evaluation of method B on synthetic teachers and rendered jazz (docs/dance.md).

Three teachers of distinct styles (bounce, sway, kick) are captured twice
(seeds differ): the *training* capture and its music teach a database
(``--parts``), the *held-out* capture is only used to judge.  Each database
dances to jazz clips of the rendered set (virja.dance.jazz_set; beats
extracted as `virja dance` does).  Printed per teacher and clip:

- BeatAlign (sigma 0.05 s, mean over the music's beats = the files' own
  quarter notes) of the dance, and its controls: the dance against beats
  shifted by half a beat, a dance of segments drawn at random among the
  length-matched ones, and the teacher's training capture against its own beats;
- the feature distance (evaluate.feature_distance) of the dance to the
  teacher's held-out capture and to the other teachers' held-out captures,
  beside the training capture's own distance to its held-out capture;
- distinct segments used, the most reused, the share of interpolated frames.

    .venv/bin/python tools/dance_eval.py [--parts legs] [--seed 0] [--clips walk_132,bop_240]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from virja.dance import evaluate  # noqa: E402
from virja.dance.audio import read_audio_8k  # noqa: E402
from virja.dance.database import teach  # noqa: E402
from virja.dance.generate import generate  # noqa: E402
from virja.dance.jazz_set import DEFAULT_SET, build_set  # noqa: E402
from virja.dance.synth_capture import STYLES, make_teacher, random_boundaries  # noqa: E402
from virja.dance.synth_music import music  # noqa: E402


def capture(style: str, seed: int) -> tuple[object, np.ndarray, list[float]]:
    t = make_teacher(style, random_boundaries(40, np.random.default_rng(seed)), seed=seed)
    colours = np.random.default_rng(seed + 10).integers(0, 3, len(t.beats_s) - 1).tolist()
    x = music(t.beats_s, t.bvh.n_frames / 30 + 0.3, colours, seed=seed + 20)
    return t.bvh, x, list(t.beats_s)


def evaluate_all(parts: str, seed: int, clips: list[str], jazz: Path) -> dict[str, object]:
    manifest = json.loads(build_set(jazz).read_text(encoding="utf-8"))
    songs = {c["name"]: c for c in manifest["clips"] if c["name"] in clips}
    styles = sorted(STYLES)
    train = {s: capture(s, seed + 100 * i) for i, s in enumerate(styles)}
    held = {s: capture(s, seed + 100 * i + 50)[0] for i, s in enumerate(styles)}
    held_f = {s: evaluate.motion_features(b) for s, b in held.items()}  # type: ignore[arg-type]
    ref = np.concatenate(list(held_f.values()))
    rows = []
    for s in styles:
        bvh, x, own_beats = train[s]
        db = teach(bvh, x, parts)  # type: ignore[arg-type]
        teacher_align = evaluate.beat_align_bvh(bvh, own_beats)  # type: ignore[arg-type]
        copy_fd = evaluate.feature_distance(evaluate.motion_features(bvh), held_f[s], ref)  # type: ignore[arg-type]
        for name, clip in songs.items():
            audio = read_audio_8k(jazz / clip["wav"])
            beats = list(clip["beats"])
            half = 30.0 / float(clip["bpm"])
            g = generate(db, audio)
            r = generate(db, audio, random_choice=np.random.default_rng(seed))
            gf = evaluate.motion_features(g.bvh)
            rows.append(
                {
                    "teacher": s,
                    "clip": name,
                    "segments_in_db": len(db.segments),
                    "align": evaluate.beat_align_bvh(g.bvh, beats),
                    "align_half_beat_shifted": evaluate.beat_align_bvh(
                        g.bvh, [b + half for b in beats]
                    ),
                    "align_random_segments": evaluate.beat_align_bvh(r.bvh, beats),
                    "align_teacher_own": teacher_align,
                    "fd_own_held_out": evaluate.feature_distance(gf, held_f[s], ref),
                    "fd_other_held_out": min(
                        evaluate.feature_distance(gf, held_f[o], ref) for o in styles if o != s
                    ),
                    "fd_random_own": evaluate.feature_distance(
                        evaluate.motion_features(r.bvh), held_f[s], ref
                    ),
                    "fd_training_capture_own": copy_fd,
                    "distinct": g.distinct,
                    "used": len(g.choices),
                    "most_reused": g.most_reused,
                    "interpolated": g.interpolated_share,
                }
            )
    return {"parts": parts, "seed": seed, "rows": rows}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--parts", default="legs", choices=["legs", "arms", "all"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--clips", default="ballad_76,walk_132,bop_240", help="clips of the set")
    ap.add_argument("--set", default="/tmp/virja-jazz", help="folder of the rendered set")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    names = [c for c in args.clips.split(",") if c]
    known = {c.name for c in DEFAULT_SET}
    if not names or not set(names) <= known:
        print(f"error: --clips must name clips of {sorted(known)}", file=sys.stderr)
        return 2
    result = evaluate_all(args.parts, args.seed, names, Path(args.set))
    if args.json:
        print(json.dumps(result, indent=1))
        return 0
    print(
        "teacher clip        | BeatAlign dance / half-shift / random / teacher "
        "| FD own / other / random / train copy | distinct/used max interp"
    )
    for r in result["rows"]:  # type: ignore[attr-defined]
        print(
            f"{r['teacher']:<7} {r['clip']:<11} | {r['align']:.2f} / {r['align_half_beat_shifted']:.2f}"
            f" / {r['align_random_segments']:.2f} / {r['align_teacher_own']:.2f}"
            f" | {r['fd_own_held_out']:.2f} / {r['fd_other_held_out']:.2f}"
            f" / {r['fd_random_own']:.2f} / {r['fd_training_capture_own']:.2f}"
            f" | {r['distinct']}/{r['used']} {r['most_reused']} {100 * r['interpolated']:.0f} %"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
