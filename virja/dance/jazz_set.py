"""A rendered jazz set for testing beat extraction: seeded accompaniments, their quarter notes.

:func:`write_jazz_midi` writes one accompaniment (drums on channel 10,
acoustic bass, piano) in a jazz style at a tempo; :func:`build_set` renders
a list of them with fluidsynth (General MIDI soundfont) to WAV next to a
``beats.json`` of every file's own quarter-note times (the reference of
``tools/beat_eval.py``).  WAV sample 0 is MIDI time 0.

Styles (``STYLES``), each a common jazz accompaniment:

- ``walk``: swing ride (quarter + skip note), hi-hat foot on 2 and 4, a
  feathered kick, a walking bass on every quarter, piano comping on the
  Charleston rhythm and anticipations;
- ``two``: two-feel: the bass on 1 and 3 with a swung pickup now and then,
  otherwise as ``walk``;
- ``ballad``: brush kit, snare on 2 and 4, a walking bass, piano chords
  held with swung arpeggio eighths;
- ``bop``: up-tempo: ride quarters, walking bass, hi-hat on 2 and 4, kick and
  snare "bombs" on random off-beats;
- ``waltz``: jazz waltz in 3/4: bass on 1 (and 3 now and then), ride on every
  beat with skip notes, piano on 2 and 3;
- ``bossa``: straight eighths: rim click pattern, kick on 1 and the "and" of
  2, bass root-fifth in dotted quarter + eighth, piano on syncopations.

Notes are humanised (timing jitter of ``JITTER_S`` std, velocity +-10); the
reference beats are the exact grid.  A *driver* for test data (it imports
``render.video`` for fluidsynth), like :mod:`virja.dance.band_capture`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import mido
import numpy as np

from virja.errors import NotAvailableError

STYLES = ("walk", "two", "ballad", "bop", "waltz", "bossa")
JITTER_S = 0.006
TPB = 480

# 12-bar blues in F: chord root (MIDI, bass octave) and a piano voicing per bar
_BLUES_ROOTS = [41, 46, 41, 41, 46, 46, 41, 38, 43, 36, 41, 36]
_VOICINGS = {
    41: (57, 60, 63, 65),  # F7: A C Eb F
    46: (56, 58, 62, 65),  # Bb7: Ab Bb D F
    38: (54, 57, 60, 62),  # D7
    43: (58, 62, 65, 69),  # Gm7
    36: (58, 62, 64, 67),  # C7
}


@dataclass(frozen=True)
class JazzClip:
    """One accompaniment of the set: ``name``, ``style``, ``bpm``, ``bars``, ``seed``."""

    name: str
    style: str
    bpm: float
    bars: int
    seed: int = 0

    @property
    def beats_per_bar(self) -> int:
        return 3 if self.style == "waltz" else 4

    def quarter_times(self) -> list[float]:
        """Times (s) of every quarter note of the file, from 0 to its last bar."""
        n = self.bars * self.beats_per_bar
        return [60.0 * k / self.bpm for k in range(n)]


DEFAULT_SET = (
    JazzClip("ballad_60", "ballad", 60, 6, 0),
    JazzClip("ballad_76", "ballad", 76, 8, 1),
    JazzClip("two_96", "two", 96, 10, 2),
    JazzClip("bossa_120", "bossa", 120, 12, 3),
    JazzClip("walk_132", "walk", 132, 13, 4),
    JazzClip("waltz_150", "waltz", 150, 20, 5),
    JazzClip("walk_180", "walk", 180, 18, 6),
    JazzClip("two_200", "two", 200, 20, 7),
    JazzClip("bop_240", "bop", 240, 24, 8),
    JazzClip("bop_280", "bop", 280, 28, 9),
    JazzClip("bop_300", "bop", 300, 30, 10),
)
"""Eleven clips of about 24 s from 60 to 300 bpm (``tools/beat_eval.py``)."""


def _notes(clip: JazzClip) -> dict[str, list[tuple[float, int, int, float]]]:
    """Per part, (beat position, note, velocity, length in beats) of the whole clip."""
    rng = np.random.default_rng(clip.seed)
    bpb = clip.beats_per_bar
    drums: list[tuple[float, int, int, float]] = []
    bass: list[tuple[float, int, int, float]] = []
    piano: list[tuple[float, int, int, float]] = []
    sw = 2.0 / 3.0  # swung eighth
    style = clip.style
    walk = [0, 2, 3, 5, 7, 9, 10, 12]  # mixolydian-ish steps above the root
    for bar in range(clip.bars):
        b0 = float(bar * bpb)
        root = _BLUES_ROOTS[bar % 12]
        voicing = _VOICINGS[root]
        for beat in range(bpb):
            t = b0 + beat
            if style in ("walk", "two", "bop", "waltz"):
                drums.append((t, 51, 80 if beat % 2 == 0 else 70, 0.2))
                if rng.random() < 0.7:
                    drums.append((t + sw, 51, 60, 0.2))
                if style != "waltz" and beat in (1, 3):
                    drums.append((t, 44, 65, 0.2))
                if style == "waltz" and beat == 1:
                    drums.append((t, 44, 65, 0.2))
                if style in ("walk", "two"):
                    drums.append((t, 36, 45, 0.2))  # feathered bass drum
                if style == "bop" and rng.random() < 0.25:
                    drums.append((t + sw, int(rng.choice([36, 38])), 95, 0.2))
                elif style in ("walk", "two") and rng.random() < 0.2:
                    drums.append((t + sw, 38, 70, 0.2))
            elif style == "ballad":
                drums.append((t, 51, 55, 0.3))
                if beat in (1, 3):
                    drums.append((t, 38, 60, 0.3))
            elif style == "bossa":
                drums += [(t, 42, 60, 0.2), (t + 0.5, 42, 50, 0.2)]
                clave = {0: [0.0], 1: [0.5], 2: [], 3: [0.0]}
                drums += [(t + x, 37, 70, 0.2) for x in clave[beat]]
                if beat in (0, 2):
                    drums.append((t, 36, 80, 0.2))
                    drums.append((t + 1.5, 36, 65, 0.2))
            # bass
            if style in ("walk", "bop", "ballad") or (
                style == "waltz" and beat == 2 and rng.random() < 0.5
            ):
                note = root if beat == 0 else root + int(rng.choice(walk)) - 12 * (root > 43)
                bass.append((t, int(note), 100, 0.9))
            elif style == "waltz" and beat == 0:
                bass.append((t, root, 105, 1.9))
            elif style == "two" and beat in (0, 2):
                note = root if beat == 0 else root + 7 - 12 * (root > 43)
                bass.append((t, note, 100, 1.9))
                if rng.random() < 0.3:
                    bass.append((t + 1 + sw, note - 1, 85, 0.3))
            elif style == "bossa" and beat in (0, 2):
                fifth = root + 7 - 12 * (root > 43)
                bass.append((t, root if beat == 0 else fifth, 100, 1.4))
                bass.append((t + 1.5, fifth if beat == 0 else root, 90, 0.45))
        # piano comping, once per bar
        if style == "ballad":
            piano += [(b0, v, 60, float(bpb)) for v in voicing]
            piano += [(b0 + k + sw, voicing[k % 4] + 12, 50, 0.3) for k in range(bpb)]
        elif style == "waltz":
            piano += [(b0 + x, v, 65, 0.5) for x in (1.0, 2.0) for v in voicing]
        elif style == "bossa":
            for x in rng.choice([0.0, 1.5, 2.5, 3.5], size=2, replace=False):
                piano += [(b0 + float(x), v, 65, 0.8) for v in voicing]
        else:
            pattern = [(0.0, 1 + sw), (sw, 2 + sw), (1 + sw, 3 + sw)][int(rng.integers(3))]
            piano += [(b0 + x, v, 70, 0.4) for x in pattern for v in voicing]
    return {"drums": drums, "bass": bass, "piano": piano}


def write_jazz_midi(clip: JazzClip, path: str | Path) -> Path:
    """Write ``clip`` as a type 1 MIDI file (tempo, drums ch 10, bass ch 2, piano ch 3)."""
    if clip.style not in STYLES:
        raise ValueError(f"style must be one of {', '.join(STYLES)}, got {clip.style!r}")
    if clip.bars < 1 or not 20 <= clip.bpm <= 400:
        raise ValueError(f"need bars >= 1 and 20 <= bpm <= 400, got {clip.bars}, {clip.bpm}")
    rng = np.random.default_rng(clip.seed + 1000)
    ticks_per_s = TPB * clip.bpm / 60.0
    mf = mido.MidiFile(type=1, ticks_per_beat=TPB)
    conductor = mido.MidiTrack(
        [mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(clip.bpm), time=0)]
    )
    conductor.append(
        mido.MetaMessage("time_signature", numerator=clip.beats_per_bar, denominator=4, time=0)
    )
    mf.tracks.append(conductor)
    programs = {"drums": (9, 40 if clip.style == "ballad" else 0), "bass": (1, 32), "piano": (2, 0)}
    for part, notes in _notes(clip).items():
        ch, prog = programs[part]
        msgs: list[tuple[int, int, mido.Message]] = [
            (0, 0, mido.Message("program_change", channel=ch, program=prog))
        ]
        for pos, note, vel, length in notes:
            jitter = rng.normal(0.0, JITTER_S) * ticks_per_s
            on = max(0, int(round(pos * TPB + jitter)))
            off = max(on + 1, int(round((pos + length) * TPB)))
            v = int(np.clip(vel + rng.integers(-10, 11), 1, 127))
            msgs.append((on, 2, mido.Message("note_on", channel=ch, note=note, velocity=v)))
            msgs.append((off, 1, mido.Message("note_off", channel=ch, note=note)))
        track = mido.MidiTrack([mido.MetaMessage("track_name", name=part.title(), time=0)])
        now = 0
        for t, _, m in sorted(msgs, key=lambda x: (x[0], x[1])):
            track.append(m.copy(time=t - now))
            now = t
        mf.tracks.append(track)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    mf.save(str(out))
    return out


def build_set(
    folder: str | Path, clips: tuple[JazzClip, ...] = DEFAULT_SET, soundfont: str | None = None
) -> Path:
    """Render ``clips`` into ``folder`` (``NAME.mid``, ``NAME.wav``) and write ``beats.json``.

    ``beats.json``: ``{"clips": [{"name", "style", "bpm", "wav", "beats": [...]}]}``.
    Clips whose WAV already exists are not rendered again.
    """
    from virja.render.video import find_soundfont, render_audio

    sf = find_soundfont(soundfont)
    if sf is None:
        raise NotAvailableError(
            "no General MIDI soundfont found (apt-get install fluid-soundfont-gm, "
            "or set VIRJA_SOUNDFONT)"
        )
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    entries = []
    for clip in clips:
        mid = write_jazz_midi(clip, out / f"{clip.name}.mid")
        wav = out / f"{clip.name}.wav"
        if not wav.exists():
            render_audio(mid, wav, sf)
        entries.append(
            {
                "name": clip.name,
                "style": clip.style,
                "bpm": clip.bpm,
                "wav": wav.name,
                "beats": clip.quarter_times(),
            }
        )
    manifest = out / "beats.json"
    manifest.write_text(json.dumps({"clips": entries}, indent=1) + "\n", encoding="utf-8")
    return manifest
