"""Routing notes to performers: drums on channel 10, GM basses, bass-named tracks, overrides."""

from __future__ import annotations

from pathlib import Path

import mido
import pytest

from tests.conftest import DEMO_MID
from virja.errors import ConfigError
from virja.events import NoteOn, ProgramChange
from virja.midifile import read_midi
from virja.routing import Router, RoutingConfig, looks_like_bass, route_all


def test_channel_10_goes_to_the_drummer() -> None:
    assert Router().route(NoteOn(0, 9, 38, 100)) == "drums"


def test_gm_bass_program_goes_to_the_bassist() -> None:
    r = Router()
    r.route(ProgramChange(0, 2, 33))
    assert r.route(NoteOn(0.1, 2, 40, 90)) == "bass"


def test_a_bass_named_track_is_the_bassists_whatever_its_program_and_the_report_says_so() -> None:
    r = Router(track_names={1: "Bass", 2: "Piano"})
    r.route(ProgramChange(0, 0, 25, track=1))  # GM 26, a steel guitar
    assert r.route(NoteOn(0.1, 0, 40, 90, track=1)) == "bass"
    r.route(ProgramChange(0, 1, 0, track=2))
    assert r.route(NoteOn(0.1, 1, 60, 90, track=2)) is None  # a piano part stays the piano's
    (line,) = [x for x in r.report() if "'Bass'" in x]
    assert "bassist" in line and "GM program 26 is not a bass" in line


def test_a_bass_named_track_on_another_instrument_is_left_when_the_file_has_its_bass(
    tmp_path: Path,
) -> None:
    """An MMA session: 'Bass-Hits' horn stabs (GM 66, tenor sax) beside 'Bass' (GM 33):
    the bassist plays 'Bass' only, and the report says why the other was left and
    how to add it; alone, the same track would still be the bass part."""
    mf = mido.MidiFile(type=1)
    for name, channel, program, note in (("Bass-Hits2", 11, 65, 50), ("Bass", 15, 32, 40)):
        tr = mido.MidiTrack()
        mf.tracks.append(tr)
        tr.append(mido.MetaMessage("track_name", name=name))
        tr.append(mido.Message("program_change", program=program, channel=channel))
        for _ in range(4):
            tr.append(mido.Message("note_on", note=note, velocity=90, channel=channel))
            tr.append(mido.Message("note_off", note=note, velocity=0, channel=channel, time=240))
    both = tmp_path / "mma.mid"
    mf.save(both)
    session = read_midi(both)
    r = Router.for_session(session)
    routed = route_all(session.events, r)
    assert {ev.note for who, ev in routed if who == "bass"} == {40}
    (line,) = [x for x in r.report() if "'Bass-Hits2'" in x]
    assert "not the band's" in line and "GM program 66 is not a bass" in line
    assert "track 1 'Bass' plays one" in line and "--bass-track 'Bass-Hits2'" in line
    del mf.tracks[1]
    alone = tmp_path / "alone.mid"
    mf.save(alone)
    session = read_midi(alone)
    assert {who for who, _ in route_all(session.events, Router.for_session(session))} == {"bass"}


def test_configuration_lets_the_program_win_over_the_name() -> None:
    cfg = RoutingConfig.from_dict({"names_over_programs": False})
    r = Router(cfg, track_names={1: "Bass"})
    r.route(ProgramChange(0, 0, 0, track=1))  # the program says piano
    assert r.route(NoteOn(0.1, 0, 40, 90, track=1)) is None
    with pytest.raises(ConfigError, match="true or false"):
        RoutingConfig.from_dict({"names_over_programs": "yes"})


def test_bass_named_track_without_program_goes_to_the_bassist() -> None:
    r = Router(track_names={1: "Walking bass"})
    assert r.route(NoteOn(0.0, 3, 40, 90, track=1)) == "bass"


def test_unprogrammed_unnamed_part_is_not_the_bands() -> None:
    assert Router().route(NoteOn(0.0, 0, 60, 90)) is None


@pytest.mark.parametrize(
    "name, expected",
    [
        ("Bass", True),
        ("Acoustic Bass 1", True),
        ("Kontrabass", True),
        ("Bass Drum", False),
        ("Bassoon", False),
        ("Piano", False),
    ],
)
def test_bass_track_names(name: str, expected: bool) -> None:
    assert looks_like_bass(name) is expected


def test_config_overrides_channels_and_tracks() -> None:
    cfg = RoutingConfig.from_dict({"channels": {"1": "bass"}, "tracks": {"Kit": "drums"}})
    r = Router(cfg, track_names={4: "Kit"})
    assert r.route(NoteOn(0, 0, 40, 90)) == "bass"
    assert r.route(NoteOn(0, 5, 38, 90, track=4)) == "drums"


def test_cli_flags_win_over_the_file() -> None:
    cfg = RoutingConfig.from_dict({"channels": {"2": "drums"}}).with_overrides(bass_channels=[2])
    assert Router(cfg).route(NoteOn(0, 1, 40, 90)) == "bass"


@pytest.mark.parametrize(
    "table, text",
    [
        ({"channels": {"17": "bass"}}, "1-16"),
        ({"channels": {"2": "piano"}}, "must be one of"),
        ({"colour": 1}, "unknown key"),
    ],
)
def test_bad_routing_config_is_a_clear_error(table: dict[str, object], text: str) -> None:
    with pytest.raises(ConfigError, match=text):
        RoutingConfig.from_dict(table)


def test_demo_routes_bass_and_drums_and_ignores_the_piano() -> None:
    s = read_midi(DEMO_MID)
    r = Router.for_session(s)
    routed = route_all(s.events, r)
    performers = {p for p, _ in routed}
    assert performers == {"bass", "drums"}
    assert not any(ev.channel == 0 for _, ev in routed)
    report = "\n".join(r.report())
    assert "'Piano'" in report and "not the band's" in report


def test_the_report_counts_one_note_as_one_note() -> None:
    r = Router()
    r.route(NoteOn(0.0, 9, 38, 100))
    for n in range(2):
        r.route(NoteOn(0.1 * n, 0, 60, 90))
    assert r.report() == [
        "channel 1: 2 notes -> not the band's (ignored)",
        "channel 10: 1 note -> drummer",
    ]
