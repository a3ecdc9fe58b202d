"""Crossed arms at short times in recorded plans, and what changed between two records.

Reads folders written by `tools/plan_goldens.py record` (one JSON line per planned
note) and counts, per folder, the hand strokes that leave the arms crossed while the
other hand struck a moment before: timing.toml ``[hand_cross]`` (``Timing.crossed``:
the left hand's piece right of the right hand's, the home posture excepted; the other
hand's latest stroke at most ``window_s`` before, simultaneous ones included).  With
two folders it also compares them note by note (by time, note and performer) and
sorts the changed notes into classes: a hand note to the other hand, a hi-hat note
between a hand and the left foot, anything else.

    python tools/plan_goldens.py record /tmp/after ../shared/data/gmd /work/mma --jobs 1
    python tools/plan_crossings.py /work/goldens/plans_r8 /tmp/after

Prints the counts (all inputs, GMD takes, MMA files) and, for two folders, the files
that changed, the classes with counts and a few examples of each.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path
from typing import Any

from virja.plan.config import Timing, default_config

HANDS = ("left_hand", "right_hand")
Note = dict[str, Any]


def read_plan(path: Path) -> list[Note]:
    """The planned notes of one golden file (its first line is the exit status)."""
    notes = []
    for line in path.read_text().splitlines():
        if line.startswith("{"):
            notes.append(json.loads(line))
    return notes


def crossings(notes: list[Note], timing: Timing) -> int:
    """How many hand strokes leave the arms crossed within the window of the other
    hand's latest stroke (the notes of one plan, any order)."""
    strokes = sorted(
        (n["impact"], n["limb"], n["piece"])
        for n in notes
        if n["performer"] == "drums" and n["limb"] in HANDS
    )
    last: dict[str, tuple[float, str]] = {}
    count = 0
    for impact, limb, piece in strokes:
        other = "right_hand" if limb == "left_hand" else "left_hand"
        if other in last:
            t_other, p_other = last[other]
            left, right = (piece, p_other) if limb == "left_hand" else (p_other, piece)
            if impact - t_other <= timing.cross_window_s and timing.crossed(left, right):
                count += 1
        last[limb] = (impact, piece)
    return count


def change_class(before: Note, after: Note) -> str:
    """What kind of change turned ``before`` into ``after`` (one planned note)."""
    pair = (before["limb"], after["limb"])
    if before["limb"] in HANDS and after["limb"] in HANDS:
        return "hand swap " + " -> ".join(limb.split("_")[0] for limb in pair)
    if "left_foot" in pair:
        return "hi-hat " + " -> ".join(limb.replace("_", " ") for limb in pair)
    return "other " + " -> ".join(str(limb) for limb in pair)


def _group(name: str) -> str:
    """GMD takes start with their number, MMA files are named style_tempo_hash; the
    rest are the demos and the pcap recording."""
    if name[0].isdigit():
        return "gmd"
    return "mma" if name.split("_")[1].isdigit() else "other"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folders", nargs="+", type=Path, help="one or two plan_goldens records")
    ap.add_argument("--examples", type=int, default=3, help="examples per class")
    args = ap.parse_args(argv)
    timing = default_config().timing
    plans = [
        {p.name: read_plan(p) for p in sorted(folder.glob("*.jsonl"))} for folder in args.folders
    ]
    for folder, plan in zip(args.folders, plans, strict=True):
        by_group: Counter[str] = Counter()
        for name, notes in plan.items():
            by_group[_group(name)] += crossings(notes, timing)
        print(
            f"{folder}: {len(plan)} plans, crossed at short times: "
            f"{sum(by_group.values())} (GMD {by_group['gmd']}, MMA {by_group['mma']}, "
            f"demos and pcap {by_group['other']})"
        )
    if len(plans) != 2:
        return 0
    before, after = plans
    classes: Counter[str] = Counter()
    examples: dict[str, list[str]] = {}
    files = []
    for name in sorted(before.keys() & after.keys()):
        if before[name] == after[name]:
            continue
        files.append(name)
        key = lambda n: (n["performer"], n["time"], n["note"])  # noqa: E731
        old = {key(n): n for n in before[name]}
        for n in after[name]:
            o = old.get(key(n))
            if o is None or (o["limb"], o["piece"]) == (n["limb"], n["piece"]):
                continue
            c = change_class(o, n)
            classes[c] += 1
            if len(examples.setdefault(c, [])) < args.examples:
                examples[c].append(f"{name} {n['time']:.3f} s note {n['note']} {n['piece']}")
    print(f"plans that differ: {len(files)} of {len(before)}")
    for name in files:
        print(f"  {name}")
    for c, k in classes.most_common():
        print(f"{c}: {k} notes; e.g. " + "; ".join(examples[c]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
