"""Routing that helps: unrouted bass-like parts and missing drums get a hint; `plan`
prints where each track went; nothing for the band is an error with a hint."""

from __future__ import annotations

from pathlib import Path

import mido
import pytest

from virja.cli.main import main
from virja.events import NoteOn
from virja.routing_hints import routing_hints


def daw_file(path: Path, *, bass: bool = True, drums_channel: int | None = 9) -> Path:
    """A DAW-style export: tracks "Track 1..." with no program changes."""
    mid = mido.MidiFile(type=1)
    mid.tracks.append(mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=500_000)]))

    def track(name: str, channel: int, chords: list[list[int]]) -> None:
        t = mido.MidiTrack([mido.MetaMessage("track_name", name=name)])
        for notes in chords:
            for n in notes:
                t.append(mido.Message("note_on", channel=channel, note=n, velocity=80, time=0))
            for i, n in enumerate(notes):
                t.append(
                    mido.Message("note_off", channel=channel, note=n, time=480 if i == 0 else 0)
                )
        mid.tracks.append(t)

    track("Track 1", 0, [[60, 64, 67]] * 16)
    if bass:
        track("Track 2", 1, [[[36, 40, 43, 45][i % 4]] for i in range(16)])
    if drums_channel is not None:
        track("Track 3", drums_channel, [[[36, 38][i % 2]] for i in range(16)])
    mid.save(path)
    return path


def test_a_bass_line_nobody_plays_gets_the_flag_that_routes_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", str(daw_file(tmp_path / "daw.mid"))]) == 0
    out = capsys.readouterr().out
    assert "track 2 'Track 2', channel 2: 16 notes -> not the band's (ignored)" in out
    assert "hint: track 2 'Track 2', channel 2" in out and "--bass-track 'Track 2'" in out
    assert "hint: track 1" not in out  # the piano chords are no bass line


def test_the_hinted_flag_works(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", str(daw_file(tmp_path / "daw.mid")), "--bass-track", "Track 2"]) == 0
    out = capsys.readouterr().out
    assert "bass: 16 notes planned" in out and "hint:" not in out


def test_drums_on_another_channel_get_a_hint(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = daw_file(tmp_path / "d.mid", bass=False, drums_channel=3)
    assert main(["plan", str(path)]) == 1
    err = capsys.readouterr().err
    assert "no notes for the band" in err and "--drums-channel 4" in err


def test_a_piano_only_file_is_an_error_that_says_how_to_route(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = daw_file(tmp_path / "p.mid", bass=False, drums_channel=None)
    for cmd in (
        ["plan", str(path)],
        ["render", str(path), "--out", str(tmp_path / "x.png"), "--at", "0"],
    ):
        assert main(cmd) == 1
        err = capsys.readouterr().err
        assert "no notes for the band" in err and "--bass-channel N" in err
        assert "Traceback" not in err


def test_plan_json_keeps_stdout_for_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    assert main(["plan", "--json", str(daw_file(tmp_path / "daw.mid"))]) == 0
    out, err = capsys.readouterr()
    assert all(json.loads(line) for line in out.splitlines())
    assert "-> drummer" in err and "hint:" in err


def test_no_hint_when_the_band_has_its_parts() -> None:
    notes = [(NoteOn(i * 0.5, 1, 40, 80, track=2), "bass") for i in range(16)]
    notes += [(NoteOn(i * 0.5, 0, 60 + i % 3, 80, track=1), None) for i in range(16)]
    assert routing_hints(notes, {1: "Left hand", 2: "Bass"}) == []  # type: ignore[arg-type]
