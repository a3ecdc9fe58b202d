"""Tests of virja.dance.beats (beat extraction) and virja.dance.audio (reading, 8 kHz)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import soundfile

from virja.dance.audio import read_audio, read_audio_8k, to_mono, to_rate
from virja.dance.beat_score import beat_score
from virja.dance.beats import (
    BeatParams,
    adaptive_threshold,
    analyse,
    band_increment,
    extract_beats,
    periodic_beats,
    suppress_neighbours,
)
from virja.dance.jazz_set import JazzClip, build_set
from virja.dance.synth_music import music, thumps
from virja.errors import InputFileError
from virja.render.video import find_soundfont

HOP_S = 0.032


def _beats(seed: int, n: int = 24) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return 0.5 + np.cumsum(rng.uniform(0.3, 1.0, n))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_thump_is_found_once_within_one_hop(seed: int) -> None:
    beats = _beats(seed)
    x = music(beats, beats[-1] + 0.6, seed=seed)
    found = extract_beats(x)
    assert len(found) == len(beats)
    assert np.max(np.abs(found - beats)) <= HOP_S


def test_noise_alone_gives_few_or_no_beats() -> None:
    rng = np.random.default_rng(5)
    x = 0.05 * rng.standard_normal(8000 * 10)
    assert len(extract_beats(x)) <= 2


def test_silence_gives_no_beats() -> None:
    assert len(extract_beats(np.zeros(8000 * 3))) == 0


def test_high_frequency_clicks_are_not_beats() -> None:
    """Only 30-120 Hz counts: 1 kHz bursts between the 60 Hz thumps are not found."""
    beats = _beats(4, 12)
    low, high = beats[::2], beats[1::2]
    x = thumps(low, beats[-1] + 0.5) + thumps(high, beats[-1] + 0.5, thump_hz=1000.0)
    found = extract_beats(x)
    assert len(found) == len(low)
    assert np.max(np.abs(found - low)) <= HOP_S


def test_D_is_the_band_sum_of_power_increments() -> None:
    p = BeatParams()
    rng = np.random.default_rng(0)
    x = rng.standard_normal(4000)
    D = band_increment(x, p)
    frames = np.stack([x[i * 256 : i * 256 + 512] for i in range(2)]) * np.hanning(512)
    power = np.abs(np.fft.rfft(frames, axis=1)) ** 2
    assert D[0] == 0.0
    assert D[1] == pytest.approx(float(np.sum(power[1, 2:8] - power[0, 2:8])))


def test_rectified_D_never_negative() -> None:
    x = thumps([0.2, 0.7], 1.2)
    assert band_increment(x, BeatParams(rectify=True)).min() >= 0.0
    assert band_increment(x, BeatParams()).min() < 0.0


def test_candidates_within_three_frames_keep_only_the_strongest() -> None:
    frames = np.array([10, 11, 12, 20, 22, 25])
    strength = np.array([1.0, 3.0, 2.0, 5.0, 4.0, 1.0])
    assert suppress_neighbours(frames, strength, 3).tolist() == [11, 20, 25]


def test_candidates_three_frames_apart_both_kept() -> None:
    assert suppress_neighbours(np.array([4, 7]), np.array([1.0, 2.0]), 3).tolist() == [4, 7]


def test_threshold_ignores_a_few_huge_values() -> None:
    """Median/MAD threshold barely moves when one onset is 1000x the rest."""
    rng = np.random.default_rng(0)
    D = rng.standard_normal(1000)
    base = adaptive_threshold(D, 4.0, 0.0)
    D[0] = 1e3
    assert adaptive_threshold(D, 4.0, 0.0) == pytest.approx(base, rel=0.02)


def test_threshold_has_relative_floor() -> None:
    D = np.zeros(100)
    D[10] = 1.0
    assert adaptive_threshold(D, 4.0, 0.05) == pytest.approx(0.05)


def test_beats_are_above_threshold_and_among_candidates() -> None:
    beats = _beats(7, 8)
    a = analyse(music(beats, beats[-1] + 0.5, seed=7))
    assert set(a.frames.tolist()) <= set(a.candidates.tolist())
    assert np.all(a.D[a.frames] > a.threshold[a.frames])


def test_to_rate_keeps_a_low_tone_and_changes_length() -> None:
    t = np.arange(44100) / 44100
    y = to_rate(np.sin(2 * np.pi * 60 * t), 44100, 8000)
    assert len(y) == 8000
    ref = np.sin(2 * np.pi * 60 * np.arange(8000) / 8000)
    assert np.max(np.abs(y[200:-200] - ref[200:-200])) < 0.01


def test_to_mono_averages_channels() -> None:
    assert to_mono(np.array([[1.0, 3.0], [0.0, 2.0]])).tolist() == [2.0, 1.0]


@pytest.mark.parametrize("fmt", ["WAV", "FLAC"])
def test_read_audio_wav_and_flac_stereo_44k(tmp_path: Path, fmt: str) -> None:
    beats = _beats(2, 6)
    x8 = music(beats, beats[-1] + 0.5, seed=2)
    x44 = to_rate(x8, 8000, 44100) * 0.5
    path = tmp_path / f"m.{fmt.lower()}"
    soundfile.write(str(path), np.stack([x44, x44], axis=1), 44100, format=fmt)
    y, rate = read_audio(path)
    assert rate == 44100 and y.ndim == 1
    found = extract_beats(read_audio_8k(path))
    assert len(found) == len(beats)
    assert np.max(np.abs(found - beats)) <= HOP_S


def test_unreadable_file_raises_input_file_error_naming_it(tmp_path: Path) -> None:
    bad = tmp_path / "bad.wav"
    bad.write_bytes(b"not audio at all")
    with pytest.raises(InputFileError, match="bad.wav"):
        read_audio(bad)


def test_missing_file_raises_input_file_error(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="no such audio file"):
        read_audio(tmp_path / "nope.wav")


def test_onset_time_stamps_have_no_frame_centre_bias() -> None:
    """Thumps start at known times: onsets within 10 ms on median, frame centres are late."""
    beats = _beats(3)
    x = music(beats, beats[-1] + 0.6, seed=3)
    onset = extract_beats(x, BeatParams(periodicity=False))
    centre = extract_beats(x, BeatParams(periodicity=False, onsets=False))
    assert abs(float(np.median(onset - beats))) < 0.010
    assert float(np.median(centre - beats)) > float(np.median(onset - beats)) + 0.010


def test_periodicity_fills_the_empty_beats_of_a_two_feel() -> None:
    grid = np.arange(24) * 0.5
    heard = np.delete(grid, [9, 11, 13, 15])  # four bars walk, then two in a two-feel
    out = periodic_beats(heard, np.ones(heard.size))
    np.testing.assert_allclose(out, grid, atol=1e-9)


def test_periodicity_drops_a_weak_pickup_between_beats() -> None:
    grid = np.arange(16) * 0.4
    t = np.sort(np.append(grid, 2.0 + 0.4 * 2 / 3))
    strength = np.where(np.isin(t, grid), 1.0, 0.3)
    np.testing.assert_allclose(periodic_beats(t, strength), grid)


def test_periodicity_leaves_music_without_a_pulse_alone() -> None:
    t = _beats(1)
    np.testing.assert_array_equal(periodic_beats(t, np.ones(t.size)), t)


needs_fluidsynth = pytest.mark.skipif(
    find_soundfont() is None or shutil.which("fluidsynth") is None,
    reason="fluidsynth and a GM soundfont are needed to render the jazz clips",
)


@needs_fluidsynth
def test_beats_of_rendered_jazz_reach_f_0_8(tmp_path: Path) -> None:
    """A small rendered set (slow ballad, medium swing, up-tempo bop): F (70 ms) >= 0.8 each."""
    clips = (
        JazzClip("ballad", "ballad", 66, 4, 1),
        JazzClip("walk", "walk", 176, 8, 4),
        JazzClip("bop", "bop", 296, 12, 9),
    )
    manifest = json.loads(build_set(tmp_path, clips).read_text(encoding="utf-8"))
    scores = []
    for clip in manifest["clips"]:
        est = extract_beats(read_audio_8k(tmp_path / clip["wav"]))
        scores.append(beat_score(est.tolist(), clip["beats"]))
    assert [s.f >= 0.8 for s in scores] == [True, True, True], [round(s.f, 2) for s in scores]
    assert all(abs(s.median_offset_s) < 0.03 for s in scores)
