"""Plot one joint angle over time with connection intervals shaded (like the paper's Fig. 6).

    .venv/bin/python tools/plot_joint.py [--joint RightArm] [--axis z] [--out fig6.png]

By default it animates the paper's second experiment at 120 bpm (four
sixteenth-note snare strokes and two eighth-note ride strokes, planned by
virja.plan) or the notes of a MIDI file given with --midi, and plots the
Euler angle (ZXY order, degrees) of one joint about one axis.  Shaded spans
are the connection intervals of the joint's limb (of any limb for a torso joint).
Needs matplotlib (pip install 'virja[plot]'); without it says so and exits 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from virja import quat
from virja.events import NoteOn
from virja.motion.band import BandAnimator
from virja.motion.metrics import in_connection
from virja.motion.skeleton import LIMB_JOINTS, SKELETON
from virja.plan import plan_notes
from virja.tempo import ConstantTempo


def _animated(midi: Path | None) -> tuple[BandAnimator, list]:
    """The band animated: the paper's experiment, or a MIDI file played as render plays
    it (virja.pipeline.perform: routing, the planner with the file's beats)."""
    if midi is None:
        notes = [("drums", NoteOn(1.0 + 0.125 * i, 9, 38, 100)) for i in range(4)]
        notes += [("drums", NoteOn(1.0 + 0.25 * i, 9, 51, 90)) for i in range(2)]
        planned = plan_notes(notes, ConstantTempo(0.5))  # type: ignore[arg-type]
        a = BandAnimator()
        for p in planned:
            a.add_planned(p)
        return a, planned
    from virja.input import midi_input
    from virja.pipeline import PerformanceSettings, perform

    settings = PerformanceSettings()
    perf, planned = perform(settings, midi_input(midi, settings.routing, 1.0), animate=True)
    assert isinstance(perf.animator, BandAnimator)
    return perf.animator, planned


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--joint", default="RightArm", help="joint name (default RightArm: right upper arm)"
    )
    ap.add_argument("--axis", default="z", choices=["x", "y", "z"], help="Euler axis (default z)")
    ap.add_argument("--figure", default="drums", choices=["drums", "bass"])
    ap.add_argument("--midi", type=Path, default=None, help="animate this MIDI file instead")
    ap.add_argument("--fps", type=float, default=120.0)
    ap.add_argument("--out", type=Path, default=Path("joint_angle.png"))
    args = ap.parse_args(argv)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_joint: matplotlib is not installed; pip install 'virja[plot]'", file=sys.stderr)
        return 2
    a, planned = _animated(args.midi)
    if not planned:
        print("plot_joint: no bass or drum notes to animate", file=sys.stderr)
        return 1
    t0 = min(p.start for p in planned) - 0.2
    t1 = max(p.impact for p in planned) + 0.6
    times = t0 + np.arange(int((t1 - t0) * args.fps) + 1) / args.fps
    fig_i = 0 if args.figure == "drums" else 1
    j = SKELETON.index(args.joint)
    q = np.stack([a.local_rotations(float(t))[fig_i, j] for t in times])
    euler = np.degrees(np.unwrap(quat.to_euler(q, "ZXY"), axis=0))
    angle = euler[:, "zxy".index(args.axis)]
    limb = next((lb for lb, js in LIMB_JOINTS.items() if args.joint in js), None)
    conn = np.array([in_connection(a, float(t), args.figure, limb) for t in times])
    fig, ax = plt.subplots(figsize=(9, 3.5))
    ax.plot(times, angle, lw=1.5)
    ax.fill_between(
        times,
        angle.min() - 5,
        angle.max() + 5,
        where=conn,
        color="0.85",
        step="mid",
        label="connection interval",
    )
    for p in planned:
        ax.axvline(p.impact, color="r", lw=0.6, alpha=0.6)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{args.joint} {args.axis} angle (deg)")
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
