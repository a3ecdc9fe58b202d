"""Captures of our own band (planned, animated, sampled) with the session's fluidsynth audio."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from virja.dance.audio import read_audio_8k
from virja.dance.band_capture import BandCapture, capture_session, write_session_midi
from virja.dance.beats import extract_beats
from virja.dance.database import teach
from virja.dance.generate import generate
from virja.dance.stage import DancerTrack
from virja.midifile import read_midi
from virja.motion.bvh import read_bvh
from virja.render.video import find_soundfont

needs_fluidsynth = pytest.mark.skipif(
    find_soundfont() is None or shutil.which("fluidsynth") is None,
    reason="fluidsynth and a GM soundfont are needed to render the session's audio",
)


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, BandCapture]:
    """Two bars at 150 bpm (3.2 s), straight groove: captured at 30 fps with its audio."""
    folder = tmp_path_factory.mktemp("band")
    mid = write_session_midi(folder / "s.mid", bpm=150, bars=2, groove="straight", seed=0)
    return mid, capture_session(mid, folder / "s")


def test_write_session_midi_gives_both_players_notes_on_the_tempo(tmp_path: Path) -> None:
    mid = write_session_midi(tmp_path / "x.mid", bpm=120, bars=3, groove="swing", seed=4)
    s = read_midi(mid)
    assert {e.channel for e in s.notes} == {1, 9}
    beats = [b.time_s for b in s.beats]
    assert np.allclose(np.diff(beats[:12]), 0.5)  # 120 bpm


def test_write_session_midi_refuses_an_unknown_groove(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="groove"):
        write_session_midi(tmp_path / "x.mid", groove="polka")


@needs_fluidsynth
def test_captures_cover_the_session_at_30_fps_from_midi_time_0(
    session: tuple[Path, BandCapture],
) -> None:
    _, cap = session
    drums, bass = read_bvh(cap.drums), read_bvh(cap.bass)
    n = int(np.floor(cap.duration_s * 30 + 1e-9)) + 1
    assert drums.n_frames == bass.n_frames == n
    assert drums.frame_time_s == pytest.approx(1 / 30, abs=1e-6)
    # the players move during the session
    for bvh in (drums, bass):
        assert np.ptp(bvh.rotations, axis=0).max() > 0.05


@needs_fluidsynth
def test_audio_beats_fall_on_the_midi_beats(session: tuple[Path, BandCapture]) -> None:
    """Sample 0 of the WAV is MIDI time 0: every beat after the first is found within 80 ms after it."""
    mid, cap = session
    found = extract_beats(read_audio_8k(cap.wav))
    for b in [x.time_s for x in read_midi(mid).beats if 0.2 < x.time_s < cap.duration_s - 0.2]:
        d = found - b
        assert np.any((d > -0.02) & (d < 0.08)), (b, found)


@needs_fluidsynth
def test_drummer_capture_teaches_a_database_that_dances_to_the_session(
    session: tuple[Path, BandCapture],
) -> None:
    _, cap = session
    audio = read_audio_8k(cap.wav)
    db = teach(read_bvh(cap.drums), audio, "arms", source="drums")
    assert len(db.segments) >= 4
    g = generate(db, audio)
    assert g.bvh.n_frames == int(round(g.beats_s[-1] * 30)) + 1  # ends on the last beat
    track = DancerTrack(g.bvh)
    assert track.pose(1.0).positions.shape == (len(db.joints), 3)
