"""Generate jazz accompaniments with MMA (Musical MIDI Accompaniment) for testing.

Usage:  .venv/bin/python tools/mma_jazz.py OUT_DIR [--tempos 60,90,...,300]

Writes one MIDI file per groove and tempo (a 16-bar rhythm-changes-like
progression with an intro, fills and an ending), made by the `mma` program
(Debian package mma; not needed by the tests).  MMA's grooves randomise timing,
velocity and skipped notes; the files are made with a fixed seed (`--seed`,
default 1) so two runs, on two machines, make the same sessions.  Then, for example:
    .venv/bin/python tools/drum_corpus.py OUT_DIR
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

GROOVES = (
    "Swing", "Swing1", "SwingWalk", "JazzCombo", "Bebop", "FastSwing", "EasySwing",
    "ModernJazz", "MellowJazz", "NiteJazz", "Ballad", "BossaNova", "JazzWaltz",
)  # fmt: skip
TEMPOS = (60, 90, 120, 150, 180, 210, 240, 270, 300)
CHORDS = [
    "Bb6",
    "G7",
    "Cm7",
    "F7",
    "Dm7",
    "G7",
    "Cm7",
    "F7",
    "Bb7",
    "Bb7",
    "Eb6",
    "Ebm6",
    "Dm7",
    "G7",
    "Cm7",
    "F7",
]


def song(groove: str, tempo: int, seed: int = 1) -> str:
    bars = [f"{i + 1} {c}" for i, c in enumerate(CHORDS)]
    return "\n".join(
        [
            f"RndSeed {seed}",  # MMA's grooves randomise timing and skips: fix them
            f"Tempo {tempo}",
            f"Groove {groove}",
            *bars[:7],
            f"Groove {groove}Fill" if groove + "Fill" in _grooves() else "",
            bars[7],
            f"Groove {groove}",
            *bars[8:],
            f"Groove {groove}End" if groove + "End" in _grooves() else "",
            f"{len(CHORDS) + 1} Bb6",
            "",
        ]
    )


def _library() -> str:
    root = Path("/usr/share/mma/lib/stdlib")
    return "\n".join(p.read_text(errors="replace") for p in root.glob("*.mma"))


_LIB: str | None = None


def _grooves() -> set[str]:
    global _LIB
    if _LIB is None:
        _LIB = _library()
    return {
        line.split()[1]
        for line in _LIB.splitlines()
        if line.startswith("DefGroove") and len(line.split()) > 1
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="folder for the .mma and .mid files")
    ap.add_argument("--tempos", default=",".join(map(str, TEMPOS)))
    ap.add_argument(
        "--seed",
        type=int,
        default=1,
        help="MMA's random seed (RndSeed): the same seed makes the same files every time",
    )
    a = ap.parse_args(argv)
    mma = shutil.which("mma")
    if mma is None:
        print("error: mma not found (apt-get install mma)", file=sys.stderr)
        return 2
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    tempos = [int(t) for t in a.tempos.split(",")]
    made = 0
    for groove in GROOVES:
        for tempo in tempos:
            src = out / f"{groove.lower()}_{tempo}.mma"
            src.write_text(song(groove, tempo, a.seed))
            r = subprocess.run([mma, str(src)], capture_output=True, text=True, timeout=120)
            if r.returncode != 0 or not src.with_suffix(".mid").exists():
                print(f"error: mma failed on {src}: {r.stdout[-300:]}", file=sys.stderr)
                return 1
            made += 1
    print(f"{made} files in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
