"""Example bass lines and how the planner fingers them (docs/scheduler.md).

``virja plan``'s fingering, shown on four kinds of line: a chromatic octave, a
scale over two octaves, a walking line and a bebop line.  :func:`fingering_table`
plans a line at a tempo and gives, per note, the string, fret, hand position and
whether the hand shifted; ``python -m virja.plan.bass_lines`` prints the tables
the documentation shows.
"""

from __future__ import annotations

from dataclasses import dataclass

from virja.events import NoteOn
from virja.plan.config import PlanConfig, default_config
from virja.plan.planner import OnlinePlanner
from virja.tempo import ConstantTempo
from virja.vocab import BassPluck

NAMES = ("C", "C#", "D", "Eb", "E", "F", "F#", "G", "Ab", "A", "Bb", "B")

# MIDI notes, sounding pitch, one per beat (eighths for the bebop line)
LINES: dict[str, tuple[tuple[int, ...], float]] = {
    # C2 up to C3 by semitones, quarter notes
    "chromatic C2-C3": (tuple(range(36, 49)), 1.0),
    # G major, G1 to G3 and back to G1
    "G major, two octaves": (
        (31, 33, 35, 36, 38, 40, 42, 43, 45, 47, 48, 50, 52, 54, 55)
        + (54, 52, 50, 48, 47, 45, 43, 42, 40, 38, 36, 35, 33, 31),
        1.0,
    ),
    # two choruses' worth of an F blues walk: roots, approach notes, chord tones
    "walking F blues": (
        (29, 33, 36, 38, 39, 38, 36, 33, 34, 38, 41, 44, 45, 41, 40, 38)
        + (34, 37, 38, 41, 43, 41, 38, 35, 36, 40, 43, 46, 45, 43, 41, 40),
        1.0,
    ),
    # a bebop phrase in eighths: chromatic passing tones, an arpeggio up and back
    "bebop line in F": (
        (41, 40, 39, 38, 36, 39, 43, 46, 48, 47, 46, 45, 43, 42, 41, 40)
        + (38, 41, 45, 48, 50, 49, 48, 46, 45, 44, 43, 41),
        0.5,
    ),
}


def note_name(note: int) -> str:
    return f"{NAMES[note % 12]}{note // 12 - 1}"


@dataclass(frozen=True)
class Fingered:
    note: int
    string: str
    fret: int
    position: int | None  # the hand's position (None before the first stopped note)
    shifted: bool


def fingering_table(
    notes: tuple[int, ...],
    beats_each: float = 1.0,
    *,
    bpm: float = 120.0,
    config: PlanConfig | None = None,
) -> list[Fingered]:
    """Plan ``notes`` (one every ``beats_each`` beats at ``bpm``) as a file would be."""
    cfg = config or default_config()
    spb = 60.0 / bpm
    planner = OnlinePlanner(cfg, tempo=ConstantTempo(spb))
    for i, n in enumerate(notes):
        planner.add_note("bass", NoteOn(i * beats_each * spb, 0, n, 90), now_s=-1.0)
    planned = sorted(planner.flush(), key=lambda p: p.time)
    out: list[Fingered] = []
    before: int | None = None
    for p in planned:
        pos = p.motion.position if isinstance(p.motion, BassPluck) else None
        out.append(
            Fingered(
                p.note,
                p.string or "",
                p.fret or 0,
                pos,
                before is not None and pos != before,
            )
        )
        before = pos
    return out


def markdown(title: str, rows: list[Fingered]) -> str:
    """One line per note: name, string and fret, position, shift."""
    cells = [
        f"{note_name(r.note)} {r.string}{r.fret}"
        + (f"/{r.position}" if r.position else "")
        + ("*" if r.shifted else "")
        for r in rows
    ]
    shifts = sum(r.shifted for r in rows)
    top = max((r.fret for r in rows), default=0)
    return f"**{title}** ({len(rows)} notes, {shifts} shifts, highest fret {top}):\n" + " ".join(
        cells
    )


def main() -> None:
    for title, (notes, beats) in LINES.items():
        print(markdown(title, fingering_table(notes, beats)))
        print()


if __name__ == "__main__":
    main()
