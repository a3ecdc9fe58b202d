"""Where the drummer misses a target of the motion report: the largest hand jumps at 30
fps, the stick-stick runs and the stick/leg collisions with pieces, each with the notes
around it (piece, limb, impact, motion start, velocity).

A diagnostic, not a test.  It plays FILE as ``virja motion-report`` does (the whole
input known, or ``--as-live``) and samples the drummer as ``virja.motion.drummer_report``
does, then says *when* each figure happens, which the report's totals do not.

    .venv/bin/python tools/drummer_where.py /work/mma/swing1_300.mid --max-seconds 30
    .venv/bin/python tools/drummer_where.py FILE --as-live --jumps 5
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from virja.cli.cmd_motion_report import played
from virja.cli.main import build_parser
from virja.motion.drummer_report import (
    _SK,
    HAND_JOINTS,
    STICK_RADIUS_M,
    _collisions,
    _sample,
    _segment_distance,
)
from virja.plan.types import PlannedNote

FINE_FPS = 240.0  # as the report's collision and speed sampling, finer than its 120 Hz
WINDOW_S = 0.25  # collisions are looked for in windows this long


def _near(drums: Sequence[PlannedNote], t: float, span: float) -> None:
    for p in drums:
        if abs(p.impact - t) < span:
            print(
                f"    {p.piece} (note {p.note}) {p.limb} impact {p.impact:.3f}"
                f" start {p.start:.3f} velocity {p.velocity}"
            )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("file", type=Path)
    ap.add_argument("--as-live", action="store_true", help="as the live window draws it")
    ap.add_argument("--max-seconds", type=float, default=12.0, help="as motion-report's")
    ap.add_argument("--jumps", type=int, default=3, help="how many of the largest jumps")
    a = ap.parse_args()
    argv = ["motion-report", str(a.file), "--max-seconds", str(a.max_seconds)]
    args = build_parser().parse_args(argv + (["--as-live"] if a.as_live else []))
    _settings, perf, planned = played(args)  # as motion-report plays it
    animator = perf.animator
    assert animator is not None
    drums = [p for p in planned if p.performer == "drums"]
    if not drums:
        print("no drum notes")
        return 0
    t0 = min(p.start for p in drums)
    t1 = max(p.impact for p in drums) + 0.5

    coarse = t0 + np.arange(int((t1 - t0) * 30.0) + 1) / 30.0
    cpos, _r, _s, _h = _sample(animator, coarse)
    hands = cpos[:, [_SK.index(j) for j in HAND_JOINTS]]
    jump = np.linalg.norm(np.diff(hands, axis=0), axis=-1)
    for k in np.argsort(jump.ravel())[::-1][: a.jumps]:
        i, h = divmod(int(k), 2)
        print(
            f"jump {100 * jump[i, h]:.1f} cm, {HAND_JOINTS[h]}, {coarse[i]:.3f}-{coarse[i + 1]:.3f} s"
        )
        _near(drums, float(coarse[i]), 0.3)

    times = t0 + np.arange(int((t1 - t0) * FINE_FPS) + 1) / FINE_FPS
    pos, _rot, stk, _hh = _sample(animator, times)
    d = _segment_distance(stk[:, 0, 0], stk[:, 0, 1], stk[:, 1, 0], stk[:, 1, 1])
    idx = np.flatnonzero(d < 2 * STICK_RADIUS_M)
    if idx.size:
        for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
            lo, hi = float(times[run[0]]), float(times[run[-1]])
            print(f"stick-stick {lo:.3f}-{hi:.3f} s, closest {1000 * d[run].min():.1f} mm")
            _near(drums, lo, 0.3)
    step = int(WINDOW_S * FINE_FPS)
    for k in range(0, len(times), step):
        found = _collisions(animator, pos[k : k + step + 1], stk[k : k + step + 1])
        found = {name: n for name, n in found.items() if n and name != "stick-stick"}
        if found:
            end = float(times[min(k + step, len(times) - 1)])
            print(f"{found} in {times[k]:.3f}-{end:.3f} s")
            _near(drums, float(times[k]) + WINDOW_S / 2, 0.3)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
