"""Generate motion for new music from a database (method B).

Extracts the beats of MUSIC, merges beat intervals to segment lengths,
picks for each the segment whose music sounded most alike (AR(3)
parameters), joins them with time stretching and axis-angle interpolation
and writes MOTION.bvh on the database's skeleton.  With --render the dancer
is also drawn alone on the stage floor to a video (.mp4/.mkv/.mov, with
MUSIC as its audio track) or PNG frames (a folder or NAME.png).

examples:
  virja dance song.wav --db drummer_db --out dance.bvh
  virja dance song.wav --db drummer_db --out dance.bvh --render dance.mp4 --size 640x360
"""

from __future__ import annotations

import argparse
from pathlib import Path

from virja.cli.common import finite_float
from virja.dance.audio import read_audio_8k
from virja.dance.database import load_database
from virja.dance.generate import generate
from virja.errors import ConfigError
from virja.motion.bvh import write_bvh


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("music", metavar="MUSIC", help="audio file to dance to")
    parser.add_argument(
        "--db", required=True, metavar="DB", help="database folder from `virja teach`"
    )
    parser.add_argument("--out", required=True, metavar="MOTION.bvh", help="BVH file to write")
    parser.add_argument(
        "--render",
        metavar="FILE",
        help="also draw the dancer: a video (.mp4/.mkv/.mov, MUSIC as sound), a folder or NAME.png",
    )
    parser.add_argument("--size", default="640x360", metavar="WxH", help="frame size (640x360)")
    parser.add_argument(
        "--fps", type=finite_float, default=30.0, help="frames per second (default 30)"
    )
    parser.add_argument("--camera", default="front", help="camera preset (default front)")


def run(args: argparse.Namespace) -> int:
    db = load_database(args.db)
    audio = read_audio_8k(args.music)
    g = generate(db, audio)
    write_bvh(g.bvh, args.out)
    print(f"{args.out}: {g.bvh.n_frames} frames, {len(g.beats_s)} beats, {g.summary()}")
    if args.render:
        render(args, g.bvh, len(audio) / 8000.0)
    return 0


def render(args: argparse.Namespace, bvh: object, music_s: float) -> None:
    """Draw the dance alone on the stage floor, frame 0 at the music's t = 0."""
    from virja.dance.stage import DancerTrack
    from virja.motion.bvh import Bvh
    from virja.render.camera import PRESETS
    from virja.render.dancer import render_dancer_alone
    from virja.render.offline import OutputSpec, RenderSettings, parse_size

    assert isinstance(bvh, Bvh)
    if args.camera not in PRESETS:
        raise ConfigError(f"--camera must be one of {', '.join(sorted(PRESETS))}")
    if args.fps <= 0 or args.fps > 240:
        raise ConfigError(f"--fps must be in (0, 240], got {args.fps}")
    out = OutputSpec.from_path(args.render)
    track = DancerTrack(bvh, t0_s=0.0)
    settings = RenderSettings(
        out,
        size=parse_size(args.size),
        fps=args.fps,
        camera=PRESETS[args.camera],
        audio=Path(args.music) if out.kind == "video" else None,
    )
    t1 = max(music_s, (bvh.n_frames - 1) * bvh.frame_time_s)
    result = render_dancer_alone(track.pose, (0.0, t1), settings)
    print(f"wrote {result.frames} frames to {out.path} in {result.seconds:.1f} s")
