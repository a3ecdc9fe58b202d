"""Standard MIDI files (type 0 and 1) to virja events.

Times are seconds from the start of the file, computed through the file's
whole tempo map (set_tempo in any track applies to every track, as in type 1
files), so tempo changes mid-file are honoured.  mido decodes running status;
a note_on with velocity 0 becomes a :class:`~virja.events.NoteOff`.

Malformed files raise :class:`~virja.errors.InputFileError` naming the file:
besides what mido refuses, a ``set_tempo`` of 0 µs per beat and a time
signature with 0 beats per bar.

Beats (:attr:`MidiSession.beats`) are generated from the time signatures up
to the end of the file, at most :data:`MAX_BEATS` of them (200,000 beats is
over 27 hours at 120 bpm).  A file whose beats would go past that (a corrupt
or hostile delta time: one delta of 2^28-1 ticks at 1 tick per beat is 268
million beats) is still read: its notes and tempo map are whole, its beats
stop at the cap, and a warning is logged.  This bounds the time and memory
reading any file takes.
"""

from __future__ import annotations

import bisect
import logging
from dataclasses import dataclass, field
from pathlib import Path

import mido
from mido.midifiles.meta import KeySignatureError

from virja import midispec
from virja.chords import parse_chord_symbol
from virja.errors import InputFileError
from virja.events import Beat, Chord, Event, NoteOff, NoteOn, ProgramChange
from virja.tempo import DEFAULT_SECONDS_PER_BEAT, TempoMap

log = logging.getLogger(__name__)

DEFAULT_TEMPO_US = 500_000
# beats generated per file at most: 27.7 hours at 120 bpm, 2.5 MB of Beat objects' worth
MAX_BEATS = 200_000
MAX_CHORDS = 100_000  # chord symbols kept per file (a chord a beat for half the beats)
CHORD_META = frozenset({"lyrics", "marker", "text", "cue_marker"})  # where files put chord symbols


@dataclass(frozen=True)
class TrackInfo:
    """What a track holds, for routing and for the CLI's report."""

    index: int
    name: str
    channels: frozenset[int]
    programs: frozenset[int]
    note_count: int


@dataclass
class MidiSession:
    """A MIDI file read into events; ``events`` sorted by time (stable)."""

    path: Path
    events: list[Event]
    tempo_map: TempoMap
    beats: list[Beat]
    tracks: list[TrackInfo]
    duration_s: float
    ticks_per_beat: int
    time_signatures: list[tuple[float, int, int]] = field(default_factory=list)
    chords: list[Chord] = field(default_factory=list)  # chord symbols in lyrics/markers/text

    @property
    def notes(self) -> list[NoteOn]:
        return [e for e in self.events if isinstance(e, NoteOn)]


class _TickClock:
    """Absolute tick -> seconds through a list of (tick, tempo_us) changes."""

    def __init__(self, changes: list[tuple[int, int]], ticks_per_beat: int) -> None:
        changes = sorted(changes, key=lambda c: c[0])
        if not changes or changes[0][0] != 0:
            changes.insert(0, (0, DEFAULT_TEMPO_US))
        # later changes at the same tick win
        merged: dict[int, int] = {}
        for tick, tempo in changes:
            merged[tick] = tempo
        self.ticks = sorted(merged)
        self.tempos = [merged[t] for t in self.ticks]
        self.tpb = ticks_per_beat
        self.seconds: list[float] = [0.0]
        for i in range(1, len(self.ticks)):
            span = self.ticks[i] - self.ticks[i - 1]
            self.seconds.append(self.seconds[-1] + span * self.tempos[i - 1] / 1e6 / self.tpb)

    def to_seconds(self, tick: int) -> float:
        i = bisect.bisect_right(self.ticks, tick) - 1
        return self.seconds[i] + (tick - self.ticks[i]) * self.tempos[i] / 1e6 / self.tpb

    def tempo_map(self) -> TempoMap:
        return TempoMap.from_changes(
            [(s, t / 1e6) for s, t in zip(self.seconds, self.tempos, strict=True)]
        )


def _open(path: Path) -> mido.MidiFile:
    if not path.exists():
        raise InputFileError(path, "no such file")
    if path.is_dir():
        raise InputFileError(path, "is a folder, not a MIDI file")
    try:
        return mido.MidiFile(str(path), clip=False)
    except (
        OSError,
        EOFError,
        ValueError,
        KeyError,
        IndexError,
        TypeError,
        KeySignatureError,  # a plain Exception: a key signature's mode byte not 0 or 1
    ) as exc:
        why = str(exc) or type(exc).__name__
        if isinstance(exc, KeySignatureError):
            why = f"bad key signature ({why or 'mode not major/minor'})"
        raise InputFileError(path, f"not a readable MIDI file: {why}") from exc


def read_midi(path: str | Path) -> MidiSession:
    """Read a type 0 or 1 MIDI file; raises InputFileError naming the file."""
    p = Path(path)
    mf = _open(p)
    if mf.type == 2:
        raise InputFileError(p, "type 2 MIDI files (independent sequences) are not supported")
    if mf.ticks_per_beat <= 0:
        raise InputFileError(p, "SMPTE time division is not supported (ticks per beat needed)")
    tempo_changes: list[tuple[int, int]] = []
    sigs: list[tuple[int, int, int]] = []
    for ti, track in enumerate(mf.tracks):
        tick = 0
        for msg in track:
            tick += msg.time
            if msg.type == "set_tempo":
                if msg.tempo <= 0:
                    raise InputFileError(
                        p, f"track {ti}, tick {tick}: set_tempo of {msg.tempo} µs per beat"
                    )
                tempo_changes.append((tick, msg.tempo))
            elif msg.type == "time_signature":
                if msg.numerator <= 0:
                    raise InputFileError(
                        p,
                        f"track {ti}, tick {tick}: time signature "
                        f"{msg.numerator}/{msg.denominator} has no beats per bar",
                    )
                sigs.append((tick, msg.numerator, msg.denominator))
    clock = _TickClock(tempo_changes, mf.ticks_per_beat)

    events: list[tuple[int, int, int, Event]] = []  # (tick, track, order, event)
    chords: list[Chord] = []
    infos: list[TrackInfo] = []
    end_tick = 0
    order = 0
    for ti, track in enumerate(mf.tracks):
        tick = 0
        name = ""
        channels: set[int] = set()
        programs: set[int] = set()
        n_notes = 0
        for msg in track:
            tick += msg.time
            if msg.is_meta:
                if msg.type == "track_name" and not name:
                    name = str(msg.name).strip()
                elif msg.type in CHORD_META:
                    chord = parse_chord_symbol(str(msg.text), clock.to_seconds(tick))
                    if chord is not None and len(chords) < MAX_CHORDS:
                        chords.append(chord)
                continue
            t = clock.to_seconds(tick)
            ev = midispec.from_mido(msg, time_s=t, track=ti)
            if isinstance(ev, NoteOn):
                n_notes += 1
            elif isinstance(ev, ProgramChange):
                programs.add(ev.program)
            if ev is not None:
                channels.add(ev.channel)
                events.append((tick, ti, order, ev))
                order += 1
        end_tick = max(end_tick, tick)
        infos.append(TrackInfo(ti, name, frozenset(channels), frozenset(programs), n_notes))

    # time order; at one tick note-offs before note-ons so a repeated note restarts cleanly
    def key(item: tuple[int, int, int, Event]) -> tuple[int, int, int]:
        tick, _track, seq, ev = item
        return (tick, 0 if isinstance(ev, NoteOff) else 1, seq)

    events.sort(key=key)
    duration = clock.to_seconds(end_tick)
    tempo_map = clock.tempo_map()
    sig_s = [(clock.to_seconds(t), n, d) for t, n, d in sorted(sigs)]
    # one beat past the cap tells a file cut short from one that ends at the cap
    beats = _beats(clock, sorted(sigs), end_tick, mf.ticks_per_beat, MAX_BEATS + 1)
    if len(beats) > MAX_BEATS:
        del beats[MAX_BEATS:]
        log.warning(
            "%s: only the first %d beats are kept (to %.0f s of %.0f s): the file is too long",
            p,
            MAX_BEATS,
            beats[-1].time_s,
            duration,
        )
    return MidiSession(
        path=p,
        events=[e for *_, e in events],
        tempo_map=tempo_map,
        beats=beats,
        chords=sorted(chords, key=lambda c: c.time_s),
        tracks=infos,
        duration_s=duration,
        ticks_per_beat=mf.ticks_per_beat,
        time_signatures=sig_s,
    )


def _beats(
    clock: _TickClock,
    sigs: list[tuple[int, int, int]],
    end_tick: int,
    tpb: int,
    max_beats: int = MAX_BEATS,
) -> list[Beat]:
    """Beats from the time signatures (4/4 when none), up to the end of the file
    or ``max_beats`` beats, whichever comes first."""
    if not sigs or sigs[0][0] != 0:
        sigs = [(0, 4, 4), *sigs]
    out: list[Beat] = []
    bar = 0
    for i, (start, num, den) in enumerate(sigs):
        stop = sigs[i + 1][0] if i + 1 < len(sigs) else end_tick + 1
        beat_ticks = max(1, tpb * 4 // max(den, 1))
        tick = start
        beat_in_bar = 1
        while tick < stop:
            if len(out) >= max_beats:
                return out
            t = clock.to_seconds(tick)
            spb = clock.to_seconds(tick + beat_ticks) - t
            level = 2 if beat_in_bar == 1 else (1 if num % 2 == 0 and beat_in_bar % 2 == 1 else 0)
            out.append(Beat(t, bar, beat_in_bar, num, level, max(1, round(spb * 1e6))))
            tick += beat_ticks
            beat_in_bar += 1
            if beat_in_bar > num:
                beat_in_bar = 1
                bar += 1
        if beat_in_bar != 1:
            bar += 1
    return out


__all__ = ["MAX_BEATS", "MidiSession", "TrackInfo", "read_midi", "DEFAULT_SECONDS_PER_BEAT"]
