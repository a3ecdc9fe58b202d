"""The drummer's motion report over many files: one row per file, misses marked.

Runs `virja motion-report FILE --max-seconds S --json` (optionally `--as-live`)
in-process for every input, in worker processes, and prints one row per file
with the figures of issue 15 (contact, timing, wrist p99 / max, largest jump at
30 fps, torso range, collisions, hi-hat agreement, drops); a figure that misses
its target is marked with `*`.  `--out FILE.json` keeps every row (the report's
drummer figures as JSON) so two sweeps can be compared.

Inputs are files or folders (every .mid under a folder), or `--set r6`: the set
measured for issue 15's round 6 (the 19 files of docs/motion.md's "The hand with
time" table, 36 GMD takes picked for tempo and fills (the two fastest beats of each style
word, then the fastest fills, two a style), every MMA file at 240 and
300 bpm), with `--gmd` and `--mma` naming where those live.

    python tools/motion_sweep.py --set r6 --gmd ../shared/data/gmd --mma /work/mma \\
        --jobs 2 --out /tmp/sweep.json
    python tools/motion_sweep.py virja/demo/blues.mid /work/mma/swing1_300.mid

Exits 1 when any file misses a target.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from virja.plan.types import PHYSICAL_LIMITS

ROOT = Path(__file__).resolve().parent.parent

# the 19 files of docs/motion.md "The hand with time" (GMD paths under --gmd,
# MMA names under --mma, the demos in the package)
R6_GMD = (
    "drummer7/session3/91_neworleans-funk_93_beat_4-4.mid",
    "drummer5/session1/20_latin-brazilian-baiao_110_beat_4-4.mid",
    "drummer1/eval_session/8_rock-groove8_65_beat_4-4.mid",
    "drummer1/session2/110_rock-prog_190_beat_4-4.mid",
    "drummer1/eval_session/1_funk-groove1_138_beat_4-4.mid",
    "drummer1/session2/36_punk_128_beat_4-4.mid",
    "drummer1/session3/3_rock-rockabilly_200_beat_4-4.mid",
    "drummer6/session3/5_rock_180_beat_4-4.mid",
    "drummer4/session1/7_blues-shuffle_134_beat_4-4.mid",
    "drummer5/session2/9_neworleans-shuffle_104_beat_4-4.mid",
)
R6_MMA = (
    "jazzcombo_60",
    "ballad_60",
    "swing_120",
    "swing_180",
    "swing_240",
    "swing_300",
    "swing1_300",
)
R6_DEMOS = ("virja/demo/blues.mid", "virja/demo/bebop.mid")
# GMD takes picked by name: the fastest beats of each style and the fastest fills
R6_STYLES = ("rock", "funk", "latin", "jazz", "soul", "hiphop", "punk", "afro", "reggae")
_BPM = re.compile(r"_(\d+)_(beat|fill)_")


def r6_set(gmd: Path, mma: Path) -> list[Path]:
    """The round-6 sweep: 19 known files, 36 GMD takes for tempo and fills, MMA at
    240 and 300 bpm (deterministic: sorted by tempo, then path)."""
    files = [ROOT / d for d in R6_DEMOS]
    files += [gmd / p for p in R6_GMD]
    files += [mma / f"{n}.mid" for n in R6_MMA]
    known = {f.resolve() for f in files}
    takes = []
    for p in sorted(gmd.rglob("*.mid")):
        m = _BPM.search(p.name)
        if m and p.resolve() not in known:
            takes.append((int(m.group(1)), m.group(2), p))
    picked: list[Path] = []
    for style in R6_STYLES:  # the two fastest beats of each style
        beats = [t for t in takes if t[1] == "beat" and f"_{style}" in t[2].name]
        beats.sort(key=lambda t: (-t[0], str(t[2])))
        picked += [t[2] for t in beats[:2]]
    fills = sorted((t for t in takes if t[1] == "fill"), key=lambda t: (-t[0], str(t[2])))
    per_style: dict[str, int] = {}
    for t in fills:  # the fastest fills, at most two of each style
        style = t[2].name.split("_")[1]
        if len(picked) >= 36 or per_style.get(style, 0) >= 2:
            continue
        per_style[style] = per_style.get(style, 0) + 1
        picked.append(t[2])
    files += picked
    files += sorted(
        p
        for p in mma.glob("*.mid")
        if p.stem.endswith(("_240", "_300")) and p.resolve() not in known
    )
    return files


def _report(args: tuple[str, float, bool]) -> dict[str, Any]:
    from virja.cli.main import main

    path, seconds, live = args
    argv = ["motion-report", path, "--max-seconds", f"{seconds:g}", "--json"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(argv + (["--as-live"] if live else []))
        except SystemExit as exc:
            rc = exc.code if isinstance(exc.code, int) else 1
    text = out.getvalue().strip()
    if rc or not text.startswith("{"):
        return {"file": path, "error": f"rc={rc}: {err.getvalue().strip()[-300:]}"}
    doc = json.loads(text)
    return {"file": path, "late": doc["late"], **doc["drums"]}


def misses(row: dict[str, Any]) -> list[str]:
    """The targets of issue 15 that ``row`` misses."""
    if "error" in row:
        return ["error"]
    out = []
    if row["contact_max_mm"] >= 10:
        out.append("contact")
    if row["timing_max_ms"] > 0.5:
        out.append("timing")
    if row["wrist_speed_p99_m_s"] > 5:
        out.append("p99")
    if row["wrist_speed_max_m_s"] > 8:
        out.append("max")
    if row["hand_jump_30fps_m"] > 0.15:
        out.append("jump")
    if row["torso_range_deg"] < 3:
        out.append("torso")
    if any(row["collisions"].values()):
        out.append("collisions")
    if row["hihat_agreement"] is not None and row["hihat_agreement"] < 1.0:
        out.append("hihat")
    if any(k not in PHYSICAL_LIMITS for k in row["dropped"]):
        out.append("dropped")
    return out


def _name(path: str) -> str:
    p = Path(path)
    if "gmd" in p.parts:
        i = p.parts.index("gmd")
        return "/".join(p.parts[i + 1 :]).replace("_beat_4-4.mid", "").replace("_4-4.mid", "")
    return p.name


def _line(row: dict[str, Any]) -> str:
    if "error" in row:
        return f"{_name(row['file']):<58} ERROR {row['error']}"
    bad = set(misses(row))

    def m(key: str) -> str:
        return "*" if key in bad else " "

    hits = ", ".join(f"{k} {v}" for k, v in sorted(row["collisions"].items()) if v) or "0"
    agree = row["hihat_agreement"]
    hh = "-" if agree is None else f"{agree * 100:.0f}%"
    return (
        f"{_name(row['file']):<58} {row['notes']:>4} {row['contact_max_mm']:6.3f}{m('contact')}"
        f"{row['timing_max_ms']:5.1f}{m('timing')}"
        f"{row['wrist_speed_p99_m_s']:5.2f}{m('p99')}/{row['wrist_speed_max_m_s']:5.2f}{m('max')}"
        f"{row['hand_jump_30fps_m'] * 100:6.1f}{m('jump')}{row['torso_range_deg']:6.1f}{m('torso')}"
        f" {hh:>5}{m('hihat')} {hits}{m('collisions')}"
    )


HEADER = (
    f"{'file':<58} {'notes':>4} {'cont mm':>6} {'tim ms':>5} {'p99 / max m/s':>12}"
    f" {'jump cm':>6} {'torso':>6} {'hihat':>5} collisions"
)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="*", help="MIDI files or folders")
    ap.add_argument("--set", choices=["r6"], help="a named set of files (see the docstring)")
    ap.add_argument("--gmd", type=Path, default=Path("../shared/data/gmd"))
    ap.add_argument("--mma", type=Path, default=Path("/work/mma"))
    ap.add_argument("--max-seconds", type=float, default=12.0)
    ap.add_argument("--as-live", action="store_true", help="motion-report --as-live")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", type=Path, help="write the rows as JSON here")
    args = ap.parse_args(argv)
    files: list[Path] = r6_set(args.gmd, args.mma) if args.set == "r6" else []
    for name in args.inputs:
        p = Path(name)
        files += sorted(p.rglob("*.mid")) if p.is_dir() else [p]
    if not files:
        ap.error("no inputs")
    work = [(str(f), args.max_seconds, args.as_live) for f in files]
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            rows = list(pool.map(_report, work))
    else:
        rows = [_report(w) for w in work]
    print(HEADER)
    for row in rows:
        print(_line(row), flush=True)
    missed = [r for r in rows if misses(r)]
    print(f"{len(rows)} files, {len(missed)} missing a target (* marks the figure)")
    if args.out:
        args.out.write_text(json.dumps(rows, indent=1) + "\n")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
