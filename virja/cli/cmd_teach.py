"""Build a motion database from a capture and its music (method B).

CAPTURE.bvh is cut into motion segments where the angular acceleration of
the chosen parts (--parts legs|arms|all) has a minimum on a beat of
MUSIC (any audio libsndfile reads; beats extracted as by `virja beats`);
each segment is stored with the AR(3) sound parameters of its music
phrase.  The capture and the music must start together.  The database is a
folder (manifest.json + segments.npz, docs/dance.md).

A capture of another skeleton (CMU, Mixamo, MotionBuilder naming; any
units, any rest pose) is first retargeted to virja's figure, so that the
dancer is drawn like the band; --keep-skeleton keeps the capture's own.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from virja.cli.common import finite_float
from virja.dance.audio import read_audio_8k
from virja.dance.database import DanceError, load_database, merge, save_database, teach
from virja.dance.retarget import find_landmarks, is_figure_skeleton, retarget_to_figure
from virja.dance.segment import DEFAULT_TOLERANCE_FRAMES, PARTS
from virja.motion.bvh import read_bvh


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("capture", metavar="CAPTURE.bvh", help="motion capture (BVH)")
    parser.add_argument("music", metavar="MUSIC", help="the music the capture was danced to")
    parser.add_argument(
        "--parts", choices=PARTS, default="legs", help="parts that decide the cuts (default legs)"
    )
    parser.add_argument("--out", required=True, metavar="DB", help="database folder to write")
    parser.add_argument(
        "--tolerance",
        type=finite_float,
        default=DEFAULT_TOLERANCE_FRAMES,
        metavar="FRAMES",
        help="how far a beat may be from a minimum of acceleration (default 3 frames)",
    )
    parser.add_argument("--append", action="store_true", help="add to the segments already in DB")
    parser.add_argument("--force", action="store_true", help="replace an existing database DB")
    parser.add_argument(
        "--keep-skeleton",
        action="store_true",
        help="teach on the capture's own skeleton (default: retarget to virja's figure)",
    )


def run(args: argparse.Namespace) -> int:
    bvh = read_bvh(args.capture)
    if not args.keep_skeleton and not is_figure_skeleton(bvh):
        lm = find_landmarks(bvh.names)
        bvh = retarget_to_figure(bvh)
        print(f"{args.capture}: retargeted to the figure ({lm.style} naming)")
    out = Path(args.out)
    if out.exists() and not args.append and not args.force:
        raise DanceError(
            f"{out} exists: give --append to add to that database, --force to replace it, "
            "or another --out"
        )
    audio = read_audio_8k(args.music)
    db = teach(
        bvh, audio, args.parts, tolerance_frames=args.tolerance, source=Path(args.capture).name
    )
    if not db.segments:
        raise DanceError(
            f"{args.capture}: no motion segments found (no acceleration minimum meets a beat)"
        )
    if args.append and (Path(args.out) / "manifest.json").exists():
        db = merge([load_database(args.out), db])
    save_database(db, args.out)
    spans = db.spans
    print(
        f"{args.out}: {len(spans)} segments of {min(spans)}-{max(spans)} frames ({args.parts}, {db.fps:g} fps)"
    )
    return 0
