"""Teaching data from our own band: the bassist's and drummer's motion with the session's audio.

A MIDI session is planned and animated exactly as `virja render` does it
(:func:`virja.pipeline.perform`: routing, the planner with the file's beats, a
:class:`~virja.motion.band.BandAnimator`),
both players are sampled at a fixed rate into BVH
(:func:`~virja.motion.export.performance_to_bvh`: ``<stem>_drums.bvh``,
``<stem>_bass.bvh``), and the same file is rendered to a WAV by fluidsynth
(:func:`~virja.render.video.render_audio`).  Frame 0 of the captures and
sample 0 of the WAV are both MIDI time 0, so ``virja teach CAPTURE WAV``
pairs them as they were played.

:func:`write_session_midi` builds a second, different session with mido
(tempo, groove and bass line chosen by arguments and a seed) so a database
taught on one session can dance to another.

This module is a driver for test data: unlike the rest of ``virja.dance`` it
uses the planner and the audio renderer (docs/dance.md).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import mido
import numpy as np

from virja.errors import InputFileError, NotAvailableError
from virja.input import midi_input
from virja.motion.band import BandAnimator
from virja.motion.export import performance_to_bvh
from virja.pipeline import PerformanceSettings, perform
from virja.render.video import find_soundfont, render_audio

log = logging.getLogger(__name__)

CAPTURE_FPS = 30.0
"""Frame rate of the captures (the paper's 30 fps)."""

GROOVES = ("swing", "straight")


@dataclass(frozen=True)
class BandCapture:
    """The captures and audio of one session: ``drums`` and ``bass`` BVH paths,
    ``wav`` (44.1 kHz), ``duration_s`` of the captured motion (MIDI time 0 to the end)."""

    drums: Path
    bass: Path
    wav: Path
    duration_s: float


def animate_midi(midi_path: str | Path) -> tuple[BandAnimator, float]:
    """Plan and animate a MIDI file's band notes as render does; (animator, duration of
    the file in s)."""
    settings = PerformanceSettings()
    src = midi_input(Path(midi_path), settings.routing, lookahead_beats=1.0)
    if src.note_count == 0:
        raise InputFileError(midi_path, "no notes for the band (bass or drums) in this file")
    perf, _planned = perform(settings, src, animate=True)
    assert isinstance(perf.animator, BandAnimator)
    assert src.midi is not None
    return perf.animator, src.midi.duration_s


def capture_session(
    midi_path: str | Path,
    out_stem: str | Path,
    fps: float = CAPTURE_FPS,
    soundfont: str | None = None,
) -> BandCapture:
    """Write ``<stem>_drums.bvh``, ``<stem>_bass.bvh`` (``fps``, from MIDI time 0 to its end)
    and ``<stem>.wav`` (fluidsynth) for ``midi_path``."""
    sf = find_soundfont(soundfont)
    if sf is None:
        raise NotAvailableError(
            "no General MIDI soundfont found (apt-get install fluid-soundfont-gm, "
            "or set VIRJA_SOUNDFONT)"
        )
    stem = Path(out_stem)
    stem = stem.with_suffix("") if stem.suffix.lower() in (".bvh", ".wav") else stem
    stem.parent.mkdir(parents=True, exist_ok=True)
    animator, duration = animate_midi(midi_path)
    drums, bass = performance_to_bvh(animator, 0.0, duration, fps, stem)
    wav = stem.parent / f"{stem.name}.wav"
    render_audio(Path(midi_path), wav, sf)
    log.info(
        "captured %s: %.2f s at %g fps -> %s, %s, %s", midi_path, duration, fps, drums, bass, wav
    )
    return BandCapture(drums, bass, wav, duration)


def write_session_midi(
    path: str | Path,
    bpm: float = 132.0,
    bars: int = 8,
    groove: str = "straight",
    seed: int = 0,
) -> Path:
    """A two-track session (drums on channel 10, acoustic bass on channel 2) as a MIDI file.

    ``groove``: ``"straight"`` (kick on 1 and 3, snare on 2 and 4, straight
    eighths on the hi-hat) or ``"swing"`` (ride in swung eighths, hi-hat foot
    on 2 and 4, a feathered kick and a snare comp on a random off-beat).  The
    bass plays a line of quarter notes walking by random steps of a C blues
    scale (``seed``), two notes per beat in the last beat of every second bar.
    """
    if groove not in GROOVES:
        raise ValueError(f"groove must be one of {GROOVES}, got {groove!r}")
    if bars < 1 or not 20 <= bpm <= 400:
        raise ValueError(f"need bars >= 1 and 20 <= bpm <= 400, got {bars} bars at {bpm} bpm")
    rng = np.random.default_rng(seed)
    tpb = 480
    drum: list[tuple[int, int, int]] = []  # (tick, note, velocity)
    bass: list[tuple[int, int, int, int]] = []  # (tick, note, velocity, length)
    scale = [36, 39, 41, 42, 43, 46, 48, 51, 53, 55]  # C blues over two octaves (E1 = 28 lowest)
    k = 0
    for bar in range(bars):
        b0 = bar * 4 * tpb
        for beat in range(4):
            t = b0 + beat * tpb
            if groove == "straight":
                if beat in (0, 2):
                    drum.append((t, 36, 110))
                if beat in (1, 3):
                    drum.append((t, 38, 105))
                drum += [(t, 42, 80), (t + tpb // 2, 42, 60)]
            else:
                swung = t + 2 * tpb // 3
                drum += [(t, 51, 85), (swung, 51, 65)]
                drum.append((t, 36, 55))
                if beat in (1, 3):
                    drum.append((t, 44, 70))
                if rng.random() < 0.35:
                    drum.append((swung, 38, 90))
            k = int(np.clip(k + rng.choice([-2, -1, 1, 2]), 0, len(scale) - 1))
            if beat == 3 and bar % 2 == 1:
                j = int(np.clip(k + 1, 0, len(scale) - 1))
                bass += [
                    (t, scale[k], 100, tpb // 2 - 20),
                    (t + tpb // 2, scale[j], 95, tpb // 2 - 20),
                ]
            else:
                bass.append((t, scale[k], 100, tpb - 30))
    conductor = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(bpm), time=0)])
    conductor.append(mido.MetaMessage("time_signature", numerator=4, denominator=4, time=0))
    dmsgs: list[tuple[int, mido.Message]] = []
    for t, n, v in drum:
        dmsgs.append((t, mido.Message("note_on", channel=9, note=n, velocity=v)))
        dmsgs.append((t + tpb // 8, mido.Message("note_off", channel=9, note=n)))
    bmsgs: list[tuple[int, mido.Message]] = [
        (0, mido.Message("program_change", channel=1, program=32))
    ]
    for t, n, v, length in bass:
        bmsgs.append((t, mido.Message("note_on", channel=1, note=n, velocity=v)))
        bmsgs.append((t + length, mido.Message("note_off", channel=1, note=n)))
    mf = mido.MidiFile(type=1, ticks_per_beat=tpb)
    mf.tracks.append(conductor)
    for name, msgs in (("Drums", dmsgs), ("Bass", bmsgs)):
        track = mido.MidiTrack([mido.MetaMessage("track_name", name=name, time=0)])
        now = 0
        for t, m in sorted(msgs, key=lambda x: (x[0], x[1].type == "note_on")):
            track.append(m.copy(time=t - now))
            now = t
        mf.tracks.append(track)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    mf.save(str(out))
    return out
