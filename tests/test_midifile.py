"""Reading MIDI files: times through tempo maps, tracks, running status, errors."""

from __future__ import annotations

from pathlib import Path

import mido
import pytest

from tests.conftest import DEMO_MID, save_midi
from virja.errors import InputFileError
from virja.events import NoteOff, NoteOn, ProgramChange
from virja.midifile import read_midi

M = mido.Message
Meta = mido.MetaMessage


def test_tempo_change_mid_file_moves_later_notes(tmp_path: Path) -> None:
    """120 bpm for 2 beats, then 60 bpm: a note on beat 3 sounds at 1.0 + 1.0 s."""
    conductor = [
        Meta("set_tempo", tempo=500_000, time=0),
        Meta("set_tempo", tempo=1_000_000, time=960),
    ]
    notes = [
        M("note_on", note=40, velocity=90, time=0),
        M("note_on", note=40, velocity=0, time=480),
        M("note_on", note=41, velocity=90, time=960),  # tick 1440 = beat 3
        M("note_off", note=41, velocity=0, time=480),
    ]
    s = read_midi(save_midi(tmp_path / "t.mid", [conductor, notes]))
    ons = [e for e in s.events if isinstance(e, NoteOn)]
    assert [round(e.time_s, 6) for e in ons] == [0.0, 2.0]
    assert s.tempo_map.seconds_per_beat_at(1.5) == pytest.approx(1.0)


def test_note_on_with_velocity_zero_is_a_note_off(tmp_path: Path) -> None:
    s = read_midi(
        save_midi(
            tmp_path / "t.mid",
            [
                [
                    M("note_on", note=60, velocity=80, time=0),
                    M("note_on", note=60, velocity=0, time=240),
                ]
            ],
        )
    )
    assert [type(e) for e in s.events] == [NoteOn, NoteOff]
    assert s.events[1].time_s == pytest.approx(0.25)


def test_running_status_is_decoded(tmp_path: Path) -> None:
    """A raw file whose second note_on omits its status byte."""
    track = bytes(
        [0x00, 0x90, 60, 100, 0x60, 62, 100, 0x60, 60, 0, 0x00, 62, 0, 0x00, 0xFF, 0x2F, 0x00]
    )
    data = (
        b"MThd"
        + (6).to_bytes(4, "big")
        + (0).to_bytes(2, "big")
        + (1).to_bytes(2, "big")
        + (96).to_bytes(2, "big")
    )
    data += b"MTrk" + len(track).to_bytes(4, "big") + track
    p = tmp_path / "rs.mid"
    p.write_bytes(data)
    s = read_midi(p)
    assert [(type(e).__name__, e.note) for e in s.events if isinstance(e, NoteOn | NoteOff)] == [
        ("NoteOn", 60),
        ("NoteOn", 62),
        ("NoteOff", 60),
        ("NoteOff", 62),
    ]


def test_several_tracks_share_the_conductor_tempo(tmp_path: Path) -> None:
    conductor = [Meta("set_tempo", tempo=250_000, time=0)]
    a = [
        Meta("track_name", name="Bass", time=0),
        M("note_on", channel=1, note=40, velocity=90, time=480),
    ]
    b = [M("note_on", channel=9, note=38, velocity=90, time=960)]
    s = read_midi(save_midi(tmp_path / "t.mid", [conductor, a, b]))
    ons = [e for e in s.events if isinstance(e, NoteOn)]
    assert [(e.track, e.time_s) for e in ons] == [(1, 0.25), (2, 0.5)]
    assert s.tracks[1].name == "Bass"
    assert s.tracks[2].channels == frozenset({9})


def test_overlapping_notes_keep_both_onsets_and_offsets(tmp_path: Path) -> None:
    t = [
        M("note_on", note=50, velocity=90, time=0),
        M("note_on", note=50, velocity=80, time=240),  # same key again before its note-off
        M("note_off", note=50, time=240),
        M("note_off", note=50, time=240),
    ]
    s = read_midi(save_midi(tmp_path / "t.mid", [t]))
    kinds = [(type(e).__name__, round(e.time_s, 3)) for e in s.events]
    assert kinds == [("NoteOn", 0.0), ("NoteOn", 0.25), ("NoteOff", 0.5), ("NoteOff", 0.75)]


def test_program_changes_become_events(tmp_path: Path) -> None:
    s = read_midi(
        save_midi(tmp_path / "t.mid", [[M("program_change", channel=2, program=33, time=0)]])
    )
    assert s.events == [ProgramChange(0.0, 2, 33, track=0)]
    assert s.tracks[0].programs == frozenset({33})


def test_beats_follow_the_time_signature(tmp_path: Path) -> None:
    conductor = [
        Meta("time_signature", numerator=3, denominator=4, time=0),
        Meta("end_of_track", time=480 * 6),
    ]
    s = read_midi(save_midi(tmp_path / "t.mid", [conductor]))
    assert [(b.bar, b.beat, b.level) for b in s.beats[:4]] == [
        (0, 1, 2),
        (0, 2, 0),
        (0, 3, 0),
        (1, 1, 2),
    ]


@pytest.mark.parametrize(
    "content, reason",
    [
        (b"", "not a readable MIDI file"),
        (b"RIFF0000WAVEfmt ", "not a readable MIDI file"),
        (
            b"MThd\x00\x00\x00\x06\x00\x01\x00\x01\x01\xe0MTrk\x00\x00\x00\x10\x00\x90",
            "not a readable MIDI file",
        ),
    ],
)
def test_malformed_file_gives_clear_error_naming_the_file(
    tmp_path: Path, content: bytes, reason: str
) -> None:
    p = tmp_path / "bad.mid"
    p.write_bytes(content)
    with pytest.raises(InputFileError, match=reason) as info:
        read_midi(p)
    assert "bad.mid" in str(info.value)


def test_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="nope.mid: no such file"):
        read_midi(tmp_path / "nope.mid")


def test_demo_session_reads() -> None:
    s = read_midi(DEMO_MID)
    assert 20 < s.duration_s < 30
    assert {t.name for t in s.tracks} >= {"Walking Bass", "Drums", "Piano"}


def test_tempo_zero_is_refused_naming_file_track_and_tick(tmp_path: Path) -> None:
    """A set_tempo of 0 µs per beat is an InputFileError naming the file, track and tick."""
    conductor = [Meta("set_tempo", tempo=500_000, time=0), Meta("set_tempo", tempo=0, time=96)]
    p = save_midi(tmp_path / "t0.mid", [conductor, [M("note_on", note=40, velocity=90)]])
    with pytest.raises(InputFileError, match=r"t0\.mid: track 0, tick 96: set_tempo of 0"):
        read_midi(p)


def test_time_signature_with_no_beats_per_bar_is_refused(tmp_path: Path) -> None:
    """A time signature 0/4 (no beats in a bar) is an InputFileError naming the file."""
    meta = [Meta("time_signature", numerator=0, denominator=4, time=0)]
    p = save_midi(tmp_path / "ts0.mid", [meta, [M("note_on", note=40, velocity=90)]])
    with pytest.raises(InputFileError, match=r"ts0\.mid: .*0/4 has no beats per bar"):
        read_midi(p)


def _long_file(tmp_path: Path, beats: int) -> Path:
    """One note, then its note-off ``beats`` beats later, at 1 tick per beat."""
    notes = [M("note_on", note=40, velocity=90, time=0), M("note_off", note=40, time=beats)]
    return save_midi(tmp_path / "long.mid", [notes], tpb=1, type_=0)


def test_beats_stop_at_the_cap_with_a_warning_and_notes_stay_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """A file longer than MAX_BEATS beats gets MAX_BEATS beats, a warning, and all its notes."""
    import virja.midifile

    monkeypatch.setattr(virja.midifile, "MAX_BEATS", 50)
    with caplog.at_level("WARNING", logger="virja.midifile"):
        s = read_midi(_long_file(tmp_path, 1000))
    assert len(s.beats) == 50
    assert [b.time_s for b in s.beats] == pytest.approx([0.5 * i for i in range(50)])
    assert "only the first 50 beats" in caplog.text and "long.mid" in caplog.text
    assert s.duration_s == pytest.approx(500.0)
    assert [type(e) for e in s.events] == [NoteOn, NoteOff]


def test_file_ending_exactly_at_the_beat_cap_is_not_warned_about(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Beats at ticks 0..49 of a 49-tick file are all of them: no warning, no beat lost."""
    import virja.midifile

    monkeypatch.setattr(virja.midifile, "MAX_BEATS", 50)
    with caplog.at_level("WARNING", logger="virja.midifile"):
        s = read_midi(_long_file(tmp_path, 49))
    assert len(s.beats) == 50
    assert "beats" not in caplog.text


def test_beat_cap_is_sane() -> None:
    """The cap allows a day of music at 120 bpm (172,800 beats) and bounds the rest."""
    from virja.midifile import MAX_BEATS

    assert 172_800 <= MAX_BEATS <= 1_000_000
