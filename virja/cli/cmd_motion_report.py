"""Measure how well the band's motion follows a MIDI file: impact, contact, continuity.

The file's notes go through the router and the planner as in a performance,
then through the animator; for every planned note this reports the timing
error (when the stick tip, toe or fingertip is really closest to its target,
minus the planned impact), the contact error at the impact (distance to the
drum head, cymbal, pedal, or string point in virja.geometry; should be under
1 cm), and the continuity of the motion: the largest frame-to-frame change of
a limb joint's angular velocity inside connection intervals versus within
single clips, and the time per pose.  For the drummer also (virja.motion.
drummer_report): wrist speed p99 and max, the largest hand jump between frames
at 30 fps, the torso's turn, collisions by pair, hi-hat state agreement with
the notes, and the notes dropped by reason.  With --json: one JSON object with
every figure.

Example:  virja motion-report song.mid
          virja motion-report song.mid --max-seconds 20 --per-note
          virja motion-report song.mid --json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING, Any

from virja.cli.common import add_routing_arguments, finite_float, performance_settings
from virja.errors import ConfigError, InputFileError

if TYPE_CHECKING:
    from virja.motion.drummer_report import DrummerFigures
    from virja.motion.metrics import MotionReport, NoteCheck
    from virja.pipeline import PerformanceSettings
    from virja.plan.types import PlannedNote
    from virja.session import Performance


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="MIDI file (type 0/1) or pcap recording of RMCP")
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
    parser.add_argument(
        "--as-live",
        action="store_true",
        help="measure the motion the live window shows (frames at 30 fps, each knowing "
        "only what was known by then: render --as-live), not the whole input known",
    )
    parser.add_argument("--per-note", action="store_true", help="also print one line per note")
    parser.add_argument("--json", action="store_true", help="one JSON object with every figure")
    add_routing_arguments(parser)


def played(
    args: argparse.Namespace,
) -> tuple[PerformanceSettings, Performance, list[PlannedNote]]:
    """The settings, the performance and its planned notes for motion-report's arguments: the input
    planned and animated as every command does (virja.pipeline), its notes, note-offs and
    beats each revealed --lookahead-beats ahead, the whole input known or as live."""
    from virja.config import load_config
    from virja.input import load_performance_input
    from virja.pipeline import perform

    settings = performance_settings(args, load_config(args.config))
    src = load_performance_input(
        Path(args.input), settings.routing, lookahead_beats=args.lookahead_beats
    )
    perf, planned = perform(
        settings,
        src,
        animate=True,
        until_s=args.max_seconds,
        as_live_fps=AS_LIVE_FPS if args.as_live else None,
    )
    return settings, perf, planned


def run(args: argparse.Namespace) -> int:
    from virja.motion.band import BandAnimator
    from virja.motion.bassist_report import measure_bassist
    from virja.motion.drummer_report import measure_drummer
    from virja.motion.metrics import CONTACT_TOLERANCE_M, measure

    path = Path(args.input)
    if not 1 <= args.fps <= 1000:
        raise ConfigError(f"--fps must be 1-1000, got {args.fps:g}")
    if args.max_seconds <= 0:
        raise ConfigError(f"--max-seconds must be > 0, got {args.max_seconds:g}")
    if not path.is_file():
        raise InputFileError(path, "no such file")
    settings, perf, planned = played(args)
    report = perf.planner.report
    animator = perf.animator
    assert isinstance(animator, BandAnimator)
    config = settings.plan
    if not planned:
        print(
            f"{path}: no bass or drum notes in the first {args.max_seconds:g} s; nothing to measure"
        )
        return 0
    progress = Stage(len(planned), args.max_seconds)
    progress("impact timing, contact and continuity")
    rep = measure(animator, planned, fps=args.fps)
    progress("the drummer's speeds, jumps, torso, collisions and hi-hat")
    kit = config.kit
    drummer = measure_drummer(
        animator, planned, {n: d.articulation for n, d in kit.notes.items()}, fps=args.fps
    )
    drops: Counter[str] = Counter(d.reason for d in report.dropped if d.performer == "drums")
    t0 = time.perf_counter()
    n = 200
    start = min(p.start for p in planned)
    for i in range(n):
        animator.pose(start + i / 60.0)
    pose_ms = (time.perf_counter() - t0) * 1e3 / n

    progress("the bassist's hands, body and fingering")
    bassist = measure_bassist(animator, planned, rep)
    progress.done()
    if args.json:
        doc = _json(path, planned, rep, drummer, drops, dict(report.unplayed), pose_ms)
        if args.as_live:  # how the hands shown before their plan was fixed fared
            doc["as_live"] = {"fps": AS_LIVE_FPS, **_provisional(animator)}
        if bassist is not None:
            doc["bass"] |= {
                "figures": dataclasses.asdict(bassist),
                "meets_targets": bassist.meets_targets,
            }
        print(json.dumps(doc))
        return 0
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
        f"  [{_continuity_verdict(rep)}]"
    )
    print(f"pose time (both players): {pose_ms:.2f} ms per frame")
    for line in _drummer_table(rep, drummer, drops):
        print(line)
    if args.as_live:
        shown = _provisional(animator)
        print(
            f"as live ({AS_LIVE_FPS:g} fps): {shown['shown']} provisional hand strokes shown, "
            f"fixed as shown {shown['fixed_same']}, fixed with the other hand "
            f"{shown['fixed_other']}, revised before fixing {shown['revised']}, "
            f"taken back {shown['taken_back']}"
        )
    if bassist is not None:
        for line in bassist.lines():
            print(line)
    return 0


AS_LIVE_FPS = 30.0  # --as-live: the frame rate of render --as-live and the window's timer


def _provisional(animator: Any) -> dict[str, int]:
    """The animator's counts of provisional hand strokes (BandAnimator.provisional_counts)."""
    counts = animator.provisional_counts
    keys = ("shown", "fixed_same", "fixed_other", "revised", "taken_back")
    return {k: int(counts.get(k, 0)) for k in keys}


CONTINUITY_RATIO = 1.5  # a connection may change velocity this much more than a clip does


def _continuity_verdict(rep: MotionReport) -> str:
    """ok when crossing from one motion to the next is about as smooth as moving within one."""
    if rep.continuity_within <= 0:
        return "ok"
    ratio = rep.continuity_connection / rep.continuity_within
    if ratio <= CONTINUITY_RATIO:
        return f"ok: connections {ratio:.2f}x the clips', target <= {CONTINUITY_RATIO:g}x"
    return f"MISS: connections {ratio:.2f}x the clips', target <= {CONTINUITY_RATIO:g}x"


class Stage:
    """One line on stderr per stage, with the time the last one took: the report takes
    tens of seconds on a long file, and a user should see it working."""

    def __init__(self, notes: int, seconds: float) -> None:
        self.started = time.perf_counter()
        print(
            f"motion-report: {notes} notes planned (first {seconds:g} s); measuring...",
            file=sys.stderr,
            flush=True,
        )

    def __call__(self, what: str) -> None:
        print(f"motion-report: measuring {what}...", file=sys.stderr, flush=True)

    def done(self) -> None:
        print(
            f"motion-report: done in {time.perf_counter() - self.started:.1f} s",
            file=sys.stderr,
            flush=True,
        )


def _split(rep: MotionReport) -> dict[str, list[NoteCheck]]:
    out: dict[str, list[NoteCheck]] = {"drums": [], "bass": []}
    for c in rep.notes:
        out["bass" if c.motion.startswith("pluck") else "drums"].append(c)
    return out


def _figure(checks: list[NoteCheck]) -> dict[str, float | int]:
    contact = [c.contact_m for c in checks] + [
        c.fret_contact_m for c in checks if c.fret_contact_m is not None
    ]
    return {
        "notes": len(checks),
        "contact_max_mm": round(max(contact, default=0.0) * 1e3, 3),
        "contact_mean_mm": round(float(sum(contact) / len(contact)) * 1e3, 3) if contact else 0.0,
        "timing_max_ms": round(max((abs(c.timing_s) for c in checks), default=0.0) * 1e3, 1),
    }


def _json(
    path: Path,
    planned: list[PlannedNote],
    rep: MotionReport,
    drummer: DrummerFigures,
    drops: Counter[str],
    unplayed: dict[str, int],
    pose_ms: float,
) -> dict[str, Any]:
    split = _split(rep)
    return {
        "file": str(path),
        "late": sum(p.late for p in planned),
        "drums": {
            **_figure(split["drums"]),
            **drummer.to_json(),
            "dropped": dict(sorted(drops.items())),
            "routed_to_nobody": unplayed,
        },
        "bass": _figure(split["bass"]),
        "continuity_connection_rad_s": round(rep.continuity_connection, 2),
        "continuity_within_rad_s": round(rep.continuity_within, 2),
        "pose_ms": round(pose_ms, 3),
    }


def _drummer_table(rep: MotionReport, drummer: DrummerFigures, drops: Counter[str]) -> list[str]:
    """The drummer's figures against the targets of issue 15."""
    from virja.plan.types import PHYSICAL_LIMITS

    d = _figure(_split(rep)["drums"])
    agree = drummer.hihat_agreement
    hits = {k: v for k, v in drummer.collisions.items() if v}
    real_drops = {k: v for k, v in drops.items() if k not in PHYSICAL_LIMITS}
    rows = [
        (
            "contact at impact (max)",
            f"{d['contact_max_mm']:.2f} mm",
            "< 10 mm",
            d["contact_max_mm"] < 10,
        ),
        ("timing error (max)", f"{d['timing_max_ms']:.1f} ms", "0 ms", d["timing_max_ms"] <= 0.5),
        (
            "wrist speed p99",
            f"{drummer.wrist_speed_p99:.2f} m/s",
            "<= 5 m/s",
            drummer.wrist_speed_p99 <= 5,
        ),
        (
            "wrist speed max",
            f"{drummer.wrist_speed_max:.2f} m/s",
            "<= 8 m/s",
            drummer.wrist_speed_max <= 8,
        ),
        (
            "largest hand jump at 30 fps",
            f"{drummer.hand_jump_30fps_m * 100:.1f} cm",
            "<= 15 cm",
            drummer.hand_jump_30fps_m <= 0.15,
        ),
        (
            "torso turn range",
            f"{drummer.torso_range_deg:.1f} deg",
            ">= 3 deg",
            drummer.torso_range_deg >= 3,
        ),
        (
            "collisions",
            ", ".join(f"{k} {v}" for k, v in sorted(hits.items())) or "0",
            "0",
            not hits,
        ),
        (
            "hi-hat agreement",
            ("-" if agree is None else f"{agree * 100:.1f} % of {drummer.hihat_notes}")
            + (
                f" ({drummer.hihat_contradictory} more with a note of the other state at once)"
                if drummer.hihat_contradictory
                else ""
            ),
            "100 %",
            agree is None or agree >= 1.0,
        ),
        (
            "dropped",
            ", ".join(f"{k} {v}" for k, v in sorted(drops.items())) or "0",
            f"0 (but {', '.join(sorted(PHYSICAL_LIMITS))})",
            not real_drops,
        ),
    ]
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    w2 = max(len(r[2]) for r in rows)
    out = ["drummer:"]
    out += [
        f"  {a:<{w0}}  {b:<{w1}}  target {c:<{w2}}  {'ok' if good else 'MISS'}"
        for a, b, c, good in rows
    ]
    return out
