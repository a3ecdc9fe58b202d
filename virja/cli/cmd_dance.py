"""Generate motion for new music from a database (method B).

Extracts the beats of MUSIC, merges beat intervals to segment lengths,
picks for each the segment whose music sounded most alike (AR(3)
parameters), joins them with time stretching and axis-angle interpolation
and writes MOTION.bvh on the database's skeleton.  Rendering the result to
video (--render) is not available yet: it waits for the renderer.
"""

from __future__ import annotations

import argparse

from virja.dance.audio import read_audio_8k
from virja.dance.database import load_database
from virja.dance.generate import generate
from virja.motion.bvh import write_bvh


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("music", metavar="MUSIC", help="audio file to dance to")
    parser.add_argument(
        "--db", required=True, metavar="DB", help="database folder from `virja teach`"
    )
    parser.add_argument("--out", required=True, metavar="MOTION.bvh", help="BVH file to write")


def run(args: argparse.Namespace) -> int:
    db = load_database(args.db)
    audio = read_audio_8k(args.music)
    g = generate(db, audio)
    write_bvh(g.bvh, args.out)
    exact = sum(1 for iv in g.intervals if iv.tolerance == 0)
    print(
        f"{args.out}: {g.bvh.n_frames} frames, {len(g.beats_s)} beats, "
        f"{len(g.intervals)} segments ({exact} exact lengths)"
    )
    return 0
