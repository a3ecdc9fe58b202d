"""The drummer's technique (issue 15): what a kit drummer plays, and how.

Every test plans notes through :func:`plan_notes_with_report`, read a beat ahead
as `virja plan` reads a file, and checks that each note is played at its own
time (impact == time, never late) or reported under the reason it names.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

from virja.events import NoteOn
from virja.midifile import read_midi
from virja.plan import PlannedNote, PlanReport, plan_notes_with_report
from virja.routing import Router, route_all
from virja.tempo import ConstantTempo
from virja.vocab import Performer

T120 = ConstantTempo(0.5)
GMD = Path(__file__).parent.parent / "data" / "gmd"


def _plan(
    notes: list[tuple[float, int, int]], tempo: ConstantTempo = T120
) -> tuple[list[PlannedNote], PlanReport]:
    seq: list[tuple[Performer, NoteOn]] = [("drums", NoteOn(t, 9, n, v)) for t, n, v in notes]
    return plan_notes_with_report(seq, tempo)


def _all_played_on_time(planned: list[PlannedNote], report: PlanReport, n: int) -> None:
    assert report.dropped == ()
    assert len(planned) == n
    for p in planned:
        assert not p.late and p.impact == p.time


def test_percussion_no_kit_drummer_plays_goes_to_nobody_as_routing() -> None:
    notes = [(0.0, 38, 90), (0.0, 63, 90), (0.25, 63, 90), (0.5, 70, 80), (0.5, 42, 80)]
    planned, report = _plan(notes)
    assert sorted(p.note for p in planned) == [38, 42]
    assert report.dropped == ()
    assert dict(report.unplayed) == {"Open Hi Conga": 2, "Maracas": 1}


def test_a_flam_is_two_hands_each_at_its_own_time() -> None:
    planned, report = _plan([(1.0, 38, 30), (1.02, 38, 110)])
    _all_played_on_time(planned, report, 2)
    assert {p.limb for p in planned} == {"left_hand", "right_hand"}


def test_a_double_on_a_cymbal_is_one_hands_and_a_flam_on_a_drum_two() -> None:
    """Round 9: two ride notes 29 ms apart (GMD rock 102 records every stroke twice) were
    a flam of both hands, the left crossing to the ride under the right stick (they
    touched); on a cymbal it is one hand's double, on the snare still a flam."""
    ride, report = _plan([(0.5, 51, 80), (1.0, 51, 77), (1.029, 51, 70), (1.25, 38, 90)])
    _all_played_on_time(ride, report, 4)
    assert [p.limb for p in sorted(ride, key=lambda p: p.time)] == [
        "right_hand",
        "right_hand",
        "right_hand",
        "left_hand",
    ]
    snare, report = _plan([(1.0, 38, 40), (1.025, 38, 100)])
    _all_played_on_time(snare, report, 2)
    assert {p.limb for p in snare} == {"left_hand", "right_hand"}


def test_humanised_hits_meant_together_are_grouped_and_keep_their_times() -> None:
    """Snare and ride 2-30 ms apart used to be two groups, the hands planned apart."""
    notes = []
    for beat in range(8):
        t = beat * 0.5
        notes += [(t, 51, 90), (t + 0.012 * (beat % 3), 38 if beat % 2 else 42, 90)]
    planned, report = _plan(notes)
    _all_played_on_time(planned, report, len(notes))
    ride = {p.limb for p in planned if p.piece == "ride"}
    assert ride == {"right_hand"}  # the time-keeping hand stays on the ride


def test_a_buzz_roll_under_the_ride_is_played_by_one_hand() -> None:
    """Soft snare notes 20 ms apart (a press roll) while the right hand rides."""
    notes = [(i * 0.02, 38, 25) for i in range(1, 40)]
    notes += [(q * 0.25, 51, 90) for q in range(4)]
    planned, report = _plan(notes)
    _all_played_on_time(planned, report, len(notes))
    assert {p.limb for p in planned if p.piece == "snare"} == {"left_hand"}


def test_ride_skip_notes_and_hihat_chicks_at_300_bpm() -> None:
    """Swung ride (spang-a-lang) with the hi-hat pedal on 2 and 4 and its swung upbeat."""
    spb = 0.2
    notes = []
    for bar in range(4):
        t0 = bar * 4 * spb
        for beat in range(4):
            t = t0 + beat * spb
            notes.append((t, 51, 80))
            if beat % 2 == 1:
                notes += [(t + spb * 2 / 3, 51, 60), (t, 44, 70)]
                notes.append((t - spb / 3, 44, 50))  # the swung upbeat before it
    planned, report = _plan(notes, ConstantTempo(spb))
    _all_played_on_time(planned, report, len(notes))


def test_kick_doubles_and_a_beater_rebound_are_played() -> None:
    notes = [(0.0, 36, 100), (0.06, 36, 90), (0.5, 36, 100), (0.53, 36, 10)]
    planned, report = _plan(notes)
    _all_played_on_time(planned, report, 4)
    assert {p.limb for p in planned} == {"right_foot"}


def test_three_hand_pieces_within_30_ms_is_its_own_reason() -> None:
    planned, report = _plan([(0.0, 38, 90), (0.01, 49, 90), (0.02, 45, 90)])
    assert [d.reason for d in report.dropped] == ["three_pieces_at_once"]
    assert len(planned) == 2


def test_a_crowded_hihat_goes_to_the_left_foot() -> None:
    """MMA's swing: open hi-hat, ride and side stick at once; the foot takes the hi-hat."""
    notes = [(b * 0.5, 46, 60) for b in range(4)] + [(b * 0.5, 51, 60) for b in range(4)]
    notes += [(b * 0.5 + 0.003, 37, 80) for b in (1, 3)]
    planned, report = _plan(notes)
    _all_played_on_time(planned, report, len(notes))
    feet = [p for p in planned if p.limb == "left_foot"]
    assert {p.time for p in feet} == {0.5, 1.5} and {p.piece for p in feet} == {"hihat"}


def test_velocity_weighs_in_the_priority() -> None:
    """Three pieces at once: the ghost note gives way, not the ride."""
    planned, report = _plan([(0.0, 51, 90), (0.0, 38, 90), (0.0, 45, 20)])
    assert [d.note.note for d in report.dropped] == [45]


GMD_FILES = sorted(GMD.glob("*.mid"))
# the Roland TD-11's own pitches in the Groove MIDI Dataset (edges, rims, bell)
TD11_PITCHES = frozenset({22, 26, 40, 47, 50, 52, 53, 55, 58, 59})


@pytest.mark.parametrize("path", GMD_FILES, ids=[p.stem for p in GMD_FILES])
def test_groove_midi_dataset_takes_drop_no_kit_note(path: Path) -> None:
    """A sample of the Groove MIDI Dataset (tests/data/gmd/README.md): human drumming
    with flams, ghost notes, buzzes and the TD-11's own pitches; read a beat ahead,
    nothing is dropped and nothing is late."""
    session = read_midi(path)
    router = Router.for_session(session)
    notes = [(w, e) for w, e in route_all(session.events, router) if isinstance(e, NoteOn)]
    planned, report = plan_notes_with_report(notes, session.tempo_map)
    assert Counter(d.reason for d in report.dropped) == Counter()
    assert not any(p.late for p in planned)
    assert len(planned) == sum(1 for w, _ in notes if w == "drums")
    used = {e.note for w, e in notes if w == "drums"} & TD11_PITCHES
    assert {p.note for p in planned} & TD11_PITCHES == used  # each one the take has


def test_the_gmd_sample_has_the_td11_s_own_pitches() -> None:
    """The sample above plays the TD-11's own pitches (edges, rims, bell); a take of
    General MIDI pitches alone (funk purdie shuffle 130 fill) is in it for its motion."""
    pitches: set[int] = set()
    with_td = 0
    for path in GMD_FILES:
        got = {e.note for e in read_midi(path).events if isinstance(e, NoteOn)}
        pitches |= got
        with_td += bool(got & TD11_PITCHES)
    assert pitches >= TD11_PITCHES
    assert with_td >= len(GMD_FILES) - 1


def test_crash_2_notes_are_played_on_crash_2_by_the_right_hand() -> None:
    """GMD drummer7 session2 take 54: 52 (the TD-11's crash 2 edge) at 52.269 s, a
    snare accent 15 ms later, a soft ride note 47 ms later.  On one crash, front left,
    the ride note was dropped; with crash 2 beside the ride the right hand plays the
    crash and goes on to the ride while the left takes the snare."""
    path = GMD / "drummer7_session2_54_soul-motown_148_beat_4-4.mid"
    session = read_midi(path)
    router = Router.for_session(session)
    notes = [(w, e) for w, e in route_all(session.events, router) if isinstance(e, NoteOn)]
    planned, report = plan_notes_with_report(notes, session.tempo_map)
    assert report.dropped == ()
    crash2 = [p for p in planned if p.note in (52, 57)]
    assert crash2 and all(p.piece == "crash2" for p in crash2)
    moment = sorted((p for p in planned if 52.26 < p.time < 52.32), key=lambda p: p.time)
    assert [(p.note, p.limb) for p in moment if p.limb.endswith("hand")] == [
        (52, "right_hand"),
        (38, "left_hand"),
        (51, "right_hand"),
    ]


def test_the_sample_is_there() -> None:
    assert len(GMD_FILES) >= 3
