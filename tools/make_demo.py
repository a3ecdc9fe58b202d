"""Write the bundled demo session, virja/demo/blues.mid (deterministic).

A 12-bar jazz blues in F at 132 bpm, type 1 file with four tracks:
  0  conductor (tempo, time signature)
  1  "Walking Bass"  channel 2, GM 32 Acoustic Bass: a walking line with open strings
  2  "Drums"         channel 10: swing ride, hi-hat pedal on 2 and 4, feathered kick,
                     snare comping, fills with sixteenths on the snare and toms, crash on 1
  3  "Piano"         channel 1, GM 0: chord comping (not the band's: must be ignored)

Run: python tools/make_demo.py [OUT.mid]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mido

TPB = 480
BPM = 132
BARS = 12
# F blues: F7 Bb7 F7 F7 | Bb7 Bb7 F7 D7 | Gm7 C7 F7 C7
CHORDS = ["F7", "Bb7", "F7", "F7", "Bb7", "Bb7", "F7", "D7", "Gm7", "C7", "F7", "C7"]
ROOTS = {"F7": 41, "Bb7": 34, "D7": 38, "Gm7": 43, "C7": 36}  # bass register MIDI notes
CHORD_TONES = {
    "F7": [0, 4, 7, 10],
    "Bb7": [0, 4, 7, 10],
    "D7": [0, 4, 7, 10],
    "Gm7": [0, 3, 7, 10],
    "C7": [0, 4, 7, 10],
}


def walking_line() -> list[int]:
    """Four quarter notes per bar: root, chord tone, chord tone, approach to next root."""
    notes: list[int] = []
    for i, ch in enumerate(CHORDS):
        root = ROOTS[ch]
        nxt = ROOTS[CHORDS[(i + 1) % len(CHORDS)]]
        tones = CHORD_TONES[ch]
        third = root + tones[1]
        fifth = root + tones[2]
        approach = nxt - 1 if i % 2 == 0 else nxt + 1
        while approach < 28:
            approach += 12
        while approach > 55:
            approach -= 12
        notes += [root, third, fifth, approach]
    return notes


def events_to_track(name: str, events: list[tuple[int, mido.Message]]) -> mido.MidiTrack:
    track = mido.MidiTrack()
    track.append(mido.MetaMessage("track_name", name=name, time=0))
    now = 0
    for tick, msg in sorted(events, key=lambda e: (e[0], e[1].type == "note_on")):
        track.append(msg.copy(time=tick - now))
        now = tick
    track.append(mido.MetaMessage("end_of_track", time=TPB))
    return track


def note(
    events: list[tuple[int, mido.Message]], ch: int, n: int, start: int, dur: int, vel: int
) -> None:
    events.append((start, mido.Message("note_on", channel=ch, note=n, velocity=vel)))
    events.append((start + dur, mido.Message("note_off", channel=ch, note=n, velocity=0)))


def build() -> mido.MidiFile:
    mf = mido.MidiFile(type=1, ticks_per_beat=TPB)
    conductor = mido.MidiTrack()
    conductor.append(mido.MetaMessage("track_name", name="Blues in F", time=0))
    conductor.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(BPM), time=0))
    conductor.append(mido.MetaMessage("time_signature", numerator=4, denominator=4, time=0))
    conductor.append(mido.MetaMessage("end_of_track", time=BARS * 4 * TPB))
    mf.tracks.append(conductor)

    bass: list[tuple[int, mido.Message]] = [
        (0, mido.Message("program_change", channel=1, program=32))
    ]
    for i, n in enumerate(walking_line()):
        note(bass, 1, n, i * TPB, TPB - 40, 96 if i % 4 == 0 else 84)
    mf.tracks.append(events_to_track("Walking Bass", bass))

    drums: list[tuple[int, mido.Message]] = []
    swing = TPB * 2 // 3  # the swung eighth falls two thirds into the beat
    for bar in range(BARS):
        b0 = bar * 4 * TPB
        last = bar == BARS - 1
        fill = bar in (3, 7, 11)
        for beat in range(4):
            t = b0 + beat * TPB
            note(drums, 9, 51, t, 120, 92 if beat % 2 else 80)  # ride
            if beat in (1, 3):
                note(drums, 9, 51, t + swing, 100, 64)  # swung skip note
                note(drums, 9, 44, t, 100, 70)  # hi-hat pedal on 2 and 4
            note(drums, 9, 36, t, 100, 50)  # feathered kick
        if bar == 0 or bar == 4 or bar == 8:
            note(drums, 9, 49, b0, 240, 100)  # crash on the form's landmarks
        if not fill:
            note(drums, 9, 38, b0 + 2 * TPB + swing, 100, 60)  # snare comp
        else:
            # beat 4: four sixteenths on the snare (the paper's experiment), toms on the last bar
            pieces = [38, 38, 38, 38] if not last else [50, 47, 45, 41]
            for k, p in enumerate(pieces):
                note(drums, 9, p, b0 + 3 * TPB + k * TPB // 4, 100, 90)
    note(drums, 9, 49, BARS * 4 * TPB, 480, 110)  # final crash
    note(drums, 9, 36, BARS * 4 * TPB, 200, 110)
    mf.tracks.append(events_to_track("Drums", drums))

    piano: list[tuple[int, mido.Message]] = [
        (0, mido.Message("program_change", channel=0, program=0))
    ]
    for bar, ch in enumerate(CHORDS):
        root = ROOTS[ch] + 12
        for beat in (0, 2):
            for tone in CHORD_TONES[ch][1:]:
                note(
                    piano,
                    0,
                    root + tone + 12,
                    bar * 4 * TPB + beat * TPB + swing * (beat // 2),
                    300,
                    70,
                )
    note(bass, 1, 41, BARS * 4 * TPB, TPB * 2, 100)
    mf.tracks[1] = events_to_track("Walking Bass", bass)
    mf.tracks.append(events_to_track("Piano", piano))
    return mf


def main() -> int:
    out = (
        Path(sys.argv[1])
        if len(sys.argv) > 1
        else Path(__file__).resolve().parent.parent / "virja/demo/blues.mid"
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    build().save(str(out))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
