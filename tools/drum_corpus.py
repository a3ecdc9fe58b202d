"""Plan every MIDI file of a corpus and count the drummer's dropped and late notes.

Usage:  .venv/bin/python tools/drum_corpus.py ../shared/data/gmd [--lookahead-beats 1]
        [--jobs 2] [--show 5]

Each file goes through the same planner as `virja plan FILE` (notes read
--lookahead-beats ahead).  Prints per reason the dropped drum notes over the
whole corpus and per pitch (with the kit map's name and piece), the notes no
kit drummer plays (routed to nobody), late notes, and the files with the most
drops (--show N).  Exit status 1 when any kit note
was dropped for a reason other than a physical limit (virja.plan.types.PHYSICAL_LIMITS:
three or more hand pieces within the grouping window, which no two hands can play, or a
note no hand reaches without passing 7 m/s of stick tip).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from virja.input import midi_input
from virja.pipeline import PerformanceSettings, perform
from virja.plan.types import PHYSICAL_LIMITS

ALLOWED = PHYSICAL_LIMITS


Result = tuple[str, Counter[str], Counter[str], int, int, Counter[tuple[int, str]]]


def plan_file(path: str, lookahead: float = 1.0) -> Result:
    # planned as `virja plan` and render plan it (virja.pipeline.perform)
    settings = PerformanceSettings()
    perf, planned = perform(settings, midi_input(Path(path), settings.routing, lookahead))
    report = perf.planner.report
    drops: Counter[str] = Counter(d.reason for d in report.dropped if d.performer == "drums")
    nobody = Counter(dict(report.unplayed))
    late = sum(1 for p in planned if p.performer == "drums" and p.late)
    n = perf.counts["notes_drums"]
    by_pitch: Counter[tuple[int, str]] = Counter(
        (d.note.note, d.reason) for d in report.dropped if d.performer == "drums"
    )
    return path, drops, nobody, late, n, by_pitch


def _run(args: tuple[str, float]) -> Result:
    return plan_file(*args)


def _pitch_lines(by_pitch: Counter[tuple[int, str]]) -> list[str]:
    """One line per dropped pitch, most drops first: the kit map's name and piece."""
    from virja.plan.config import default_config

    kit = default_config().kit
    pitches: Counter[int] = Counter()
    for (pitch, _reason), n in by_pitch.items():
        pitches[pitch] += n
    lines = []
    for pitch, n in pitches.most_common():
        dn = kit.lookup(pitch)
        name = "unmapped" if dn is None else f"{dn.name}, {dn.piece}"
        reasons = ", ".join(f"{r} {k}" for (p, r), k in sorted(by_pitch.items()) if p == pitch)
        lines.append(f"  pitch {pitch:3d} ({name}): {n}; {reasons}")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("root", help="a MIDI file or a folder searched for *.mid")
    ap.add_argument("--lookahead-beats", type=float, default=1.0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--show", type=int, default=5, help="files with the most drops")
    a = ap.parse_args(argv)
    root = Path(a.root)
    files = [root] if root.is_file() else sorted(root.rglob("*.mid"))
    if not files:
        print(f"error: no .mid files under {root}", file=sys.stderr)
        return 2
    drops: Counter[str] = Counter()
    nobody: Counter[str] = Counter()
    late = total = 0
    per_file: list[tuple[int, str, Counter[str]]] = []
    work = [(str(f), a.lookahead_beats) for f in files]
    if a.jobs > 1:
        with ProcessPoolExecutor(a.jobs) as ex:
            results = list(ex.map(_run, work, chunksize=8))
    else:
        results = [_run(w) for w in work]
    by_pitch: Counter[tuple[int, str]] = Counter()
    for path, d, nb, lt, n, bp in results:
        drops += d
        by_pitch += bp
        nobody += nb
        late += lt
        total += n
        if d:
            per_file.append((sum(d.values()), path, d))
    clean = len(files) - sum(1 for _n, _p, d in per_file if any(r not in ALLOWED for r in d))
    print(f"files: {len(files)}  drum notes: {total}  late: {late}")
    print(f"files with no kit note dropped (but for {', '.join(sorted(ALLOWED))}): {clean}")
    print(
        f"dropped: {sum(drops.values())}" + "".join(f"; {r}: {n}" for r, n in sorted(drops.items()))
    )
    if by_pitch:
        print("dropped by pitch:")
        print("\n".join(_pitch_lines(by_pitch)))
    print(
        f"played by nobody (not a kit instrument): {sum(nobody.values())}"
        + "".join(f"; {k}: {n}" for k, n in sorted(nobody.items()))
    )
    for n, path, d in sorted(per_file, reverse=True)[: a.show]:
        print(f"  {n:5d}  {path}  " + ", ".join(f"{r} {k}" for r, k in sorted(d.items())))
    bad = sum(n for r, n in drops.items() if r not in ALLOWED)
    return 1 if bad or late else 0


if __name__ == "__main__":
    sys.exit(main())
