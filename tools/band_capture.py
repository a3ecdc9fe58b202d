"""Teach method B from our own band and measure it (figures for docs/dance.md).

1. Captures: the bundled demo (virja/demo/blues.mid) and a second session
   built with mido (``--bpm``, ``--groove``, ``--seed``) are each planned,
   animated and sampled at 30 fps (``<stem>_drums.bvh``, ``<stem>_bass.bvh``)
   and rendered to WAV by fluidsynth.
2. Teaching: one database from the drummer's capture of the demo and one
   from the bassist's (``--parts``, default arms: the drummer's legs only
   work the pedals, the bassist's legs stand still).
3. Generation: each database dances to the second session's audio (and to
   the demo's own).  Reported: BeatAlign of the generated motion against the
   music's extracted beats, with a control of beats shifted by half a median
   beat interval; BeatAlign of the captures against their own music; and
   style inheritance: a nearest-centroid classifier trained on the two
   captures labels windows of each generated dance.

    .venv/bin/python tools/band_capture.py --out /tmp/band [--parts arms] [--json]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from virja.bench import demo_path
from virja.dance import evaluate
from virja.dance.audio import read_audio_8k
from virja.dance.band_capture import capture_session, write_session_midi
from virja.dance.beats import extract_beats
from virja.dance.database import save_database, teach
from virja.dance.generate import generate
from virja.motion.bvh import read_bvh, write_bvh


def run(out: Path, parts: str, bpm: float, groove: str, seed: int) -> dict[str, object]:
    second = write_session_midi(out / "second.mid", bpm=bpm, bars=12, groove=groove, seed=seed)
    caps = {
        "demo": capture_session(demo_path(), out / "demo"),
        "second": capture_session(second, out / "second"),
    }
    music = {k: read_audio_8k(c.wav) for k, c in caps.items()}
    beats = {k: extract_beats(x) for k, x in music.items()}
    teachers = {"drums": read_bvh(caps["demo"].drums), "bass": read_bvh(caps["demo"].bass)}
    result: dict[str, object] = {"parts": parts, "second": f"{groove} {bpm:g} bpm seed {seed}"}
    result["beats"] = {k: len(b) for k, b in beats.items()}
    result["teacher_vs_own_beats"] = {
        k: evaluate.beat_align_bvh(b, beats["demo"].tolist()) for k, b in teachers.items()
    }
    segments: dict[str, int] = {}
    align: dict[str, dict[str, float]] = {}
    generated: dict[str, object] = {}
    for who, bvh in teachers.items():
        db = teach(bvh, music["demo"], parts, source=f"demo_{who}")  # type: ignore[arg-type]
        save_database(db, out / f"db_{who}")
        segments[who] = len(db.segments)
        for song in ("second", "demo"):
            g = generate(db, music[song])
            write_bvh(g.bvh, out / f"dance_{who}_on_{song}.bvh")
            found = beats[song]
            half = float(np.median(np.diff(found))) / 2
            align[f"{who} on {song}"] = {
                "generated": evaluate.beat_align_bvh(g.bvh, found.tolist()),
                "shifted_control": evaluate.beat_align_bvh(g.bvh, (found + half).tolist()),
            }
            if song == "second":
                generated[who] = g.bvh
    # style: feature distance to the teachers' held-out captures (the second session)
    held = {"drums": read_bvh(caps["second"].drums), "bass": read_bvh(caps["second"].bass)}
    feats = {k: evaluate.motion_features(b) for k, b in held.items()}
    ref = np.concatenate(list(feats.values()))
    result["segments"] = segments
    result["beat_align"] = align
    result["feature_distance_to_held_out"] = {
        f"{who} dance": {
            k: evaluate.feature_distance(
                evaluate.motion_features(g),
                f,
                ref,  # type: ignore[arg-type]
            )
            for k, f in feats.items()
        }
        for who, g in generated.items()
    }
    return result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--out", type=Path, default=Path("/tmp/virja-band"), help="working folder")
    ap.add_argument("--parts", default="arms", choices=["legs", "arms", "all"])
    ap.add_argument("--bpm", type=float, default=150.0, help="second session's tempo")
    ap.add_argument("--groove", default="swing", choices=["swing", "straight"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    result = run(args.out, args.parts, args.bpm, args.groove, args.seed)
    if args.json:
        print(json.dumps(result, indent=1))
        return
    for k, v in result.items():
        print(f"{k}: {v}")


if __name__ == "__main__":
    main()
