"""Write one of the example bass lines of virja.plan.bass_lines as a MIDI file.

For looking at and measuring the bassist on known lines (docs/motion.md):

    .venv/bin/python tools/bass_line_midi.py --line walking --bpm 300 --out out/walk300.mid
    .venv/bin/virja motion-report out/walk300.mid

The track is named "Bass" (GM program 33, acoustic bass), one note per step of
the line (quarters, eighths for the bebop line), each held 90 % of its length.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mido

from virja.plan.bass_lines import LINES

KEYS = {title.split()[0].lower(): title for title in LINES}  # chromatic, g, walking, bebop


def write(path: Path, notes: tuple[int, ...], beats_each: float, bpm: float, repeat: int) -> None:
    tpb = 480
    step = int(round(beats_each * tpb))
    hold = int(step * 0.9)
    track = mido.MidiTrack()
    track.append(mido.MetaMessage("track_name", name="Bass"))
    track.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(bpm)))
    track.append(mido.Message("program_change", channel=1, program=32))
    for n in notes * repeat:
        track.append(mido.Message("note_on", channel=1, note=n, velocity=96, time=0))
        track.append(mido.Message("note_off", channel=1, note=n, velocity=0, time=hold))
        track.append(mido.Message("note_off", channel=1, note=n, velocity=0, time=step - hold))
    mid = mido.MidiFile(type=1, ticks_per_beat=tpb)
    mid.tracks.append(track)
    path.parent.mkdir(parents=True, exist_ok=True)
    mid.save(str(path))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--line", choices=sorted(KEYS), default="walking")
    ap.add_argument("--bpm", type=float, default=120.0)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    if not 20 <= args.bpm <= 400 or args.repeat < 1:
        ap.error("--bpm must be 20-400 and --repeat at least 1")
    notes, beats = LINES[KEYS[args.line]]
    write(args.out, notes, beats, args.bpm, args.repeat)
    print(
        f"wrote {args.out}: {KEYS[args.line]}, {len(notes) * args.repeat} notes at {args.bpm:g} bpm"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
