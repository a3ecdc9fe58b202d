"""serve --audio: notes reach fluidsynth at their time, from a thread of their own."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
import soundfile

from virja.events import Beat, NoteOff, NoteOn, ProgramChange
from virja.live.audio import LiveSynth, command
from virja.render.video import find_soundfont


def test_commands_are_fluidsynths_shell() -> None:
    assert command(NoteOn(1.0, 9, 38, 100)) == "noteon 9 38 100"
    assert command(NoteOff(1.0, 1, 40, 0)) == "noteoff 1 40"
    assert command(ProgramChange(0.0, 1, 32)) == "prog 1 32"
    assert command(Beat(1.0, 0, 1, 4, 2, 500_000)) is None


def test_notes_sound_at_their_time(tmp_path: Path) -> None:
    sf = find_soundfont(None)
    if sf is None:
        pytest.skip("no GM soundfont (tools/setup.sh installs fluid-soundfont-gm)")
    wav = tmp_path / "live.wav"
    t0 = time.monotonic()
    synth = LiveSynth(
        sf, time.monotonic, driver="file", extra_args=("-o", f"audio.file.name={wav}")
    )
    try:
        synth(NoteOn(t0 + 0.3, 1, 40, 110))  # a beat ahead, as notes arrive
        synth(NoteOff(t0 + 0.9, 1, 40, 0))
        synth(NoteOn(t0 - 5.0, 1, 45, 110))  # long past: not sounded
        deadline = time.monotonic() + 10
        while synth.sent < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert time.monotonic() - t0 >= 0.3  # not before its time
    finally:
        synth.close()
    assert synth.sent == 2 and synth.skipped_late == 1 and synth.failed is None
    audio, _rate = soundfile.read(wav)
    assert np.abs(audio).max() > 0.01  # the bass note sounded
