"""The hands' fastest moves in recorded plans: a whole-corpus look at the drummer's speed.

Reads folders written by `tools/plan_goldens.py record` (one JSON line per planned
note) and lists, per folder, each hand's move between two pieces faster than
``--speed`` metres a second of stick tip: the distance between the two strike points
(``virja.plan.config.hand_distances``, as timing.toml [hand_speed] prices them) over
the time between the two impacts, for a hand's consecutive notes within the hand's
speed memory (``Timing.speed_memory_s``).  Every note a hand plays counts, the notes
riding on a stroke (rebounds, buzzes) too, since the hand is drawn striking them.

A move of over 7 m/s of tip puts the wrist past 8 m/s and jumps it over 15 cm a frame at
30 fps (issue 15's limits); the motion report measures a file's first seconds, this
every note of every take, in about a minute:

    python tools/plan_goldens.py record /tmp/plans ../shared/data/gmd /work/mma --jobs 2
    python tools/plan_fast_moves.py /tmp/plans [--speed 6] [--show 20]

Prints per folder the count over the speed and the fastest moves (speed, file, hand,
from piece at time and velocity, to piece at time and velocity).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from plan_crossings import HANDS, read_plan

from virja.plan.config import default_config, hand_distances

Move = tuple[float, str, str, str, float, int, str, float, int]


def fast_moves(notes: list[dict[str, Any]], name: str, speed: float, memory_s: float) -> list[Move]:
    """The moves of one plan's hands faster than ``speed`` m/s of tip."""
    dist = hand_distances()
    out: list[Move] = []
    for hand in HANDS:
        mine = sorted((n for n in notes if n["limb"] == hand), key=lambda n: n["impact"])
        for a, b in zip(mine, mine[1:], strict=False):
            dt = b["impact"] - a["impact"]
            if a["piece"] == b["piece"] or dt > memory_s:
                continue
            v = dist.get((a["piece"], b["piece"]), 0.0) / max(dt, 1e-6)
            if v > speed:
                out.append(
                    (v, name, hand, a["piece"], a["impact"], a["velocity"], b["piece"])
                    + (b["impact"], b["velocity"])
                )
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--speed", type=float, default=7.0, help="m/s of stick tip (default 7)")
    ap.add_argument("--show", type=int, default=20, help="the fastest moves listed")
    args = ap.parse_args()
    memory_s = default_config().timing.speed_memory_s
    for folder in args.folders:
        moves: list[Move] = []
        plans = sorted(folder.glob("*.jsonl"))
        for path in plans:
            moves += fast_moves(read_plan(path), path.stem, args.speed, memory_s)
        moves.sort(reverse=True)
        print(f"{folder}: {len(plans)} plans, {len(moves)} hand moves over {args.speed:g} m/s")
        for v, name, hand, p1, t1, v1, p2, t2, v2 in moves[: args.show]:
            print(
                f"  {v:5.1f} m/s  {name}  {hand}  {p1} {t1:.3f} s (v{v1}) -> {p2} {t2:.3f} s (v{v2})"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
