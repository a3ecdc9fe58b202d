"""Fuzzing the MIDI file reader: mutated SMF bytes give InputFileError or a valid session.

Valid means: events sorted by time, finite non-negative times, a duration no
shorter than the last event.  Each read runs under a 2 s alarm (a hang fails).
The seed files are written here with mido: type 0 and type 1, tempo changes,
a time signature, programs, controllers and notes.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import mido
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz.mutate import apply_byte_edits, byte_edits, raise_unless_known_bug, time_limit
from virja.errors import InputFileError
from virja.midifile import MidiSession, read_midi


def smf(type_: int) -> bytes:
    mf = mido.MidiFile(type=type_, ticks_per_beat=96)
    meta = [
        mido.MetaMessage("set_tempo", tempo=500_000, time=0),
        mido.MetaMessage("time_signature", numerator=3, denominator=4, time=0),
        mido.MetaMessage("set_tempo", tempo=400_000, time=192),
    ]
    notes = [
        mido.Message("program_change", channel=0, program=32, time=0),
        mido.Message("control_change", channel=0, control=7, value=100, time=0),
        mido.Message("note_on", channel=0, note=40, velocity=90, time=0),
        mido.Message("note_off", channel=0, note=40, velocity=0, time=48),
        mido.Message("note_on", channel=9, note=36, velocity=100, time=48),
        mido.Message("note_on", channel=9, note=36, velocity=0, time=24),
    ]
    if type_ == 0:
        mf.tracks.append(mido.MidiTrack([*meta, *notes]))
    else:
        mf.tracks.append(mido.MidiTrack([mido.MetaMessage("track_name", name="tempo"), *meta]))
        mf.tracks.append(mido.MidiTrack([mido.MetaMessage("track_name", name="Bass"), *notes]))
    buf = io.BytesIO()
    mf.save(file=buf)
    return buf.getvalue()


SEEDS = {"type0": smf(0), "type1": smf(1)}


def assert_valid_session(s: MidiSession) -> None:
    times = [e.time_s for e in s.events]
    assert times == sorted(times)
    assert all(math.isfinite(t) and t >= 0 for t in times)
    assert math.isfinite(s.duration_s) and s.duration_s >= (times[-1] if times else 0.0)
    assert s.ticks_per_beat > 0


def test_seed_files_are_valid(tmp_path: Path) -> None:
    """The unmutated files read with their notes (else the fuzzing tests nothing)."""
    for name, data in SEEDS.items():
        p = tmp_path / f"{name}.mid"
        p.write_bytes(data)
        s = read_midi(p)
        assert len(s.notes) == 2
        assert_valid_session(s)


@settings(
    max_examples=200, deadline=2000, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(name=st.sampled_from(sorted(SEEDS)), edits=byte_edits())
def test_mutated_midi_file_gives_input_file_error_or_valid_session(
    tmp_path: Path, name: str, edits: list[tuple[int, int, int]]
) -> None:
    """A mutated SMF never raises anything but InputFileError and never hangs."""
    p = tmp_path / "fuzz.mid"
    p.write_bytes(apply_byte_edits(SEEDS[name], edits))
    try:
        with time_limit(2.0):
            session = read_midi(p)
    except InputFileError:
        return
    except Exception as exc:
        raise_unless_known_bug(exc)
        return
    assert_valid_session(session)
