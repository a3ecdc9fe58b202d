"""Measure how well the band's motion follows a MIDI file: impact, contact, continuity.

The file's notes go through the router and the planner as in a performance,
then through the animator; for every planned note this reports the timing
error (when the stick tip, toe or fingertip is really closest to its target,
minus the planned impact), the contact error at the impact (distance to the
drum head, cymbal, pedal, or string point in virja.geometry; should be under
1 cm), and the continuity of the motion: the largest frame-to-frame change of
a limb joint's angular velocity inside connection intervals versus within
single clips, and the time per pose.

Example:  virja motion-report song.mid
          virja motion-report song.mid --max-seconds 20 --per-note
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from virja.cli.common import finite_float
from virja.errors import ConfigError, InputFileError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="MIDI file (type 0/1)")
    parser.add_argument(
        "--lookahead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="each note is known B beats before it sounds (default 1)",
    )
    parser.add_argument(
        "--max-seconds",
        type=finite_float,
        default=60.0,
        metavar="S",
        help="measure only the first S seconds of the file (default 60)",
    )
    parser.add_argument(
        "--fps", type=finite_float, default=120.0, help="sampling rate for continuity (default 120)"
    )
    parser.add_argument("--per-note", action="store_true", help="also print one line per note")


def run(args: argparse.Namespace) -> int:
    from virja.events import NoteOn
    from virja.midifile import read_midi
    from virja.motion.band import BandAnimator
    from virja.motion.metrics import CONTACT_TOLERANCE_M, measure
    from virja.plan import plan_notes
    from virja.routing import Router, route_all

    path = Path(args.input)
    if not 1 <= args.fps <= 1000:
        raise ConfigError(f"--fps must be 1-1000, got {args.fps:g}")
    if args.max_seconds <= 0:
        raise ConfigError(f"--max-seconds must be > 0, got {args.max_seconds:g}")
    if not path.is_file():
        raise InputFileError(path, "no such file")
    session = read_midi(path)
    router = Router.for_session(session)
    notes = [
        (who, ev)
        for who, ev in route_all(session.events, router)
        if isinstance(ev, NoteOn) and ev.time_s <= args.max_seconds
    ]
    planned = plan_notes(notes, session.tempo_map, lookahead_beats=args.lookahead_beats)
    if not planned:
        print(
            f"{path}: no bass or drum notes in the first {args.max_seconds:g} s; nothing to measure"
        )
        return 0
    animator = BandAnimator()
    for beat in session.beats:
        animator.add_beat(beat)
    for p in planned:
        animator.add_planned(p)
    rep = measure(animator, planned, fps=args.fps)
    t0 = time.perf_counter()
    n = 200
    start = min(p.start for p in planned)
    for i in range(n):
        animator.pose(start + i / 60.0)
    pose_ms = (time.perf_counter() - t0) * 1e3 / n

    if args.per_note:
        print(f"{'impact s':>9} {'motion':<22} {'contact mm':>10} {'fret mm':>8} {'timing ms':>9}")
        for c in rep.notes:
            fret = "" if c.fret_contact_m is None else f"{c.fret_contact_m * 1e3:8.2f}"
            print(
                f"{c.impact:9.3f} {c.motion:<22} {c.contact_m * 1e3:10.2f} {fret:>8} {c.timing_s * 1e3:9.1f}"
            )
    print(
        f"{path}: {len(rep.notes)} notes ({sum(p.performer == 'drums' for p in planned)} drums, "
        f"{sum(p.performer == 'bass' for p in planned)} bass), {sum(p.late for p in planned)} late"
    )
    print(
        f"impact timing error: mean {rep.mean_timing_s * 1e3:.1f} ms, max {rep.max_timing_s * 1e3:.1f} ms"
    )
    print(
        f"contact error at impact: mean {rep.mean_contact_m * 1e3:.2f} mm, max {rep.max_contact_m * 1e3:.2f} mm, "
        f"{rep.contacts_over_tolerance} over {CONTACT_TOLERANCE_M * 1e3:.0f} mm"
    )
    print(
        f"continuity (largest angular-velocity jump per frame at {args.fps:g} fps): "
        f"connections {rep.continuity_connection:.1f} rad/s, within clips {rep.continuity_within:.1f} rad/s"
    )
    print(f"pose time (both players): {pose_ms:.2f} ms per frame")
    return 0
