"""As live, the notes the plan fixed to another hand than the one shown moving.

Plays each file as `virja motion-report FILE --as-live` does (frames at 30 fps,
`session.run_as_live`, the first `--max-seconds`), with the hands shown moving
pinned in the plan (`Performance.pin_shown`, the default) or not (`--no-pins`: the
plan of main before round 8), and prints per file: provisional strokes shown, fixed
as shown, and the notes taken from a hand already drawn moving toward them (fixed
to another limb, revised to the other hand, taken back); for each of these, how
long that hand had been moving when the plan switched (the latest frame shown less when its track first
moved for the note) and the wrist peak of the hand given the note, from that frame
to the impact (m/s, sampled at 600 Hz; none for a hi-hat note given to the left foot).

    python tools/live_switches.py /work/mma/swing1_300.mid [--no-pins] [--json OUT]

A benchmark-like figure tool, not a test (docs/motion.md, round 8).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from virja.events import NoteOn  # noqa: E402
from virja.input import load_performance_input  # noqa: E402
from virja.motion.band import BandAnimator  # noqa: E402
from virja.motion.skeleton import SKELETON  # noqa: E402
from virja.pipeline import PerformanceSettings, build_performance  # noqa: E402
from virja.session import run_as_live  # noqa: E402

FPS = 30.0  # motion-report --as-live
WRIST = {"left_hand": "LeftHand", "right_hand": "RightHand"}


def _wrist_peak(a: BandAnimator, hand: str, t0: float, t1: float) -> float:
    """The largest wrist speed (m/s) of ``hand`` over [t0, t1], sampled at 600 Hz."""
    ts = np.arange(t0, t1 + 1e-9, 1 / 600)
    if len(ts) < 2:
        return 0.0
    pos, _ = SKELETON.fk(a.local_rotations_many(ts), a._roots)
    w = pos[:, 0, SKELETON.index(WRIST[hand])]
    return float(np.linalg.norm(np.diff(w, axis=0), axis=1).max() * 600)


def measure(path: Path, max_seconds: float, pins: bool) -> dict[str, Any]:
    settings = PerformanceSettings()
    src = load_performance_input(path, settings.routing, lookahead_beats=1.0)
    end_s = src.start_s + max_seconds
    schedule = [
        r for r in src.schedule if not (isinstance(r.event, NoteOn) and r.event.time_s > end_s)
    ]
    perf = build_performance(settings, src, animate=True)
    perf.keep_planned = False
    perf.pin_shown = pins
    run_as_live(perf, schedule, FPS, src.start_s)
    a = perf.animator
    assert isinstance(a, BandAnimator)
    counts = a.provisional_counts
    # every note taken from a hand drawn moving, and every note fixed to another limb
    moving = [s for s in a.hand_switches if s.moving_since is not None or s.kind == "fixed"]
    rows = [
        {
            "kind": s.kind,
            "time": round(s.time - src.start_s, 4),
            "shown": s.shown,
            "fixed": s.fixed,
            "moving_ms": (
                None if s.moving_since is None else round((s.drawn - s.moving_since) * 1e3, 1)
            ),
            "lead_ms": round((s.impact - s.drawn) * 1e3, 1),  # left to the impact
            "new_hand_wrist_peak_m_s": (
                round(_wrist_peak(a, s.fixed, s.drawn, s.impact), 2)
                if s.fixed in WRIST and s.kind != "taken_back"
                else None
            ),
        }
        for s in moving
    ]
    return {
        "file": str(path),
        "pins": pins,
        "shown": counts["shown"],
        "fixed_same": counts["fixed_same"],
        "fixed_same_moving": counts["fixed_same_moving"],
        "fixed_other": counts["fixed_other"],
        "fixed_other_moving": counts["fixed_other_moving"],
        "revised": counts["revised"],
        "revised_moving": counts["revised_moving"],
        "taken_back": counts["taken_back"],
        "taken_back_moving": counts["taken_back_moving"],
        "dropped": int(perf.planner.report.summary().get("dropped", 0)),
        "switches": rows,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+", type=Path)
    ap.add_argument("--max-seconds", type=float, default=12.0, help="as motion_sweep.py")
    ap.add_argument("--no-pins", action="store_true", help="the plan without pins (main)")
    ap.add_argument("--json", type=Path, help="write every row here")
    args = ap.parse_args(argv)
    out = []
    for f in args.files:
        r = measure(f, args.max_seconds, not args.no_pins)
        out.append(r)
        print(
            f"{f.name}: shown {r['shown']}, fixed as shown {r['fixed_same']} "
            f"({r['fixed_same_moving']} moving); moving when fixed to another limb "
            f"{r['fixed_other_moving']} (of {r['fixed_other']}), revised "
            f"{r['revised_moving']} (of {r['revised']}), taken back "
            f"{r['taken_back_moving']} (of {r['taken_back']}); dropped {r['dropped']}"
        )
        for w in r["switches"]:
            peak = w["new_hand_wrist_peak_m_s"]
            moved = "not moving" if w["moving_ms"] is None else f"moving {w['moving_ms']:.0f} ms"
            print(
                f"  {w['kind']:<10} {w['time']:8.3f} s {w['shown']} -> {w['fixed']}: {moved}, "
                f"{w['lead_ms']:.0f} ms left"
                + ("" if peak is None else f", new hand's wrist peak {peak:.2f} m/s")
            )
    if args.json:
        args.json.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
