"""The drummer's provisional hands (BandAnimator.note_provisional): a hand moves toward
a note from when it is known, before its plan is fixed; a revised plan changes no frame
drawn and re-targets the hands from where they are."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from tests.motion.helpers import assert_same_frames, drum
from virja.events import Beat, NoteOn
from virja.geometry import GEOMETRY
from virja.input import midi_input
from virja.motion.band import BandAnimator, sticks
from virja.motion.clip import MotionLibrary
from virja.motion.drummer_body import BodySettings
from virja.motion.drummer_hands import HandSettings
from virja.motion.metrics import contact_distance
from virja.motion.skeleton import SKELETON
from virja.pipeline import PerformanceSettings, perform
from virja.plan.planner import OnlinePlanner
from virja.plan.types import PlannedNote
from virja.routing import Router
from virja.session import Performance, Reveal, run_as_live

ROOT = Path(__file__).resolve().parents[2]
LEAD = 0.06  # the planned lead at 300 bpm: too short to cross the kit


def _note(motion: str, impact: float, note: int, velocity: int = 90) -> PlannedNote:
    return replace(drum(motion, impact - LEAD, impact, velocity), note=note, time=impact)


def _animator(library: MotionLibrary) -> BandAnimator:
    return BandAnimator(library, body=BodySettings.still(), hands=HandSettings())


def _wrists(a: BandAnimator, ts: np.ndarray) -> np.ndarray:
    """Both wrists (m, 2, 3) [left, right] at ``ts``."""
    pos, _ = SKELETON.fk(a.local_rotations_many(ts), a._roots)
    return pos[:, 0, [SKELETON.index("LeftHand"), SKELETON.index("RightHand")]]


def _known(a: BandAnimator, p: PlannedNote, at: float) -> None:
    a.note_known("drums", NoteOn(p.time, p.channel, p.note, p.velocity), at)


def _play(
    library: MotionLibrary, fixed: list[PlannedNote], shown: list[tuple[float, list[PlannedNote]]]
) -> tuple[BandAnimator, np.ndarray, np.ndarray]:
    """A live window at 60 fps: notes known a beat (0.5 s) ahead, the provisional sets
    ``shown`` told at their times, the fixed plans at their starts; returns the
    animator, the frame times and the frames as drawn."""
    ts = np.arange(0.2, 4.0, 1 / 60)
    a = _animator(library)
    events: list[tuple[float, int, object]] = [(p.impact - 0.5, 0, p) for p in fixed]
    events += [(at, 1, notes) for at, notes in shown]
    events += [(p.start, 2, p) for p in fixed]
    events.sort(key=lambda e: (e[0], e[1]))
    drawn, k = [], 0
    for t in ts:
        while k < len(events) and events[k][0] <= t:
            at, kind, what = events[k]
            if kind == 0:
                _known(a, what, at)  # type: ignore[arg-type]
            elif kind == 1:
                a.note_provisional(what)  # type: ignore[arg-type]
            else:
                a.add_planned(what)  # type: ignore[arg-type]
            k += 1
        drawn.append(a.local_rotations(float(t)))
        a.mark_drawn(float(t))
    return a, ts, np.array(drawn)


def test_a_provisional_hand_leaves_when_the_note_is_known(library: MotionLibrary) -> None:
    """Ride, then the floor tom 0.4 s later planned with a 60 ms lead: told the
    provisional hand when the tom is known, the right hand crosses in time (under
    5 m/s, no 15 cm jump at 30 fps); without it, it crosses in the lead."""
    ride = _note("ride_right_hand", 1.0, 51)
    tom = _note("tom_floor_right_hand", 1.4, 41)
    peaks = []
    for told in (True, False):
        shown = [(0.5, [ride]), (0.9, [ride, tom])] if told else []
        a, ts, drawn = _play(library, [ride, tom], shown)
        assert_same_frames(a, ts, drawn)
        fine = np.arange(0.3, 2.0, 1 / 120)
        w = _wrists(a, fine)[:, 1]
        speed = np.linalg.norm(np.diff(w, axis=0), axis=1) * 120
        jump = np.linalg.norm(w[4:] - w[:-4], axis=1).max()
        peaks.append((speed.max(), jump))
        for p in (ride, tom):
            assert contact_distance(a, p, p.impact)[0] < 1e-4
        assert a.provisional_counts["fixed_same"] == (2 if told else 0)
    (fast, jump_told), (slow, jump_late) = peaks
    assert fast <= 5.0 and jump_told <= 0.15
    # the case this fixes (the stick's reach takes part of the crossing in the lead
    # since round 6: 7.1 m/s, was over 8; since round 8 a squeezed move this fast
    # peaks at 1.11x its average, not 1.25x: 5.7 m/s, still a 16.3 cm jump)
    assert slow > 5.0 and jump_late > 0.15


def test_the_plan_fixing_the_shown_hand_changes_nothing(library: MotionLibrary) -> None:
    """Told the provisional hand and then the same plan fixed: the motion is the one
    shown (every frame, before and after the fix), contacts exact."""
    notes = [_note("snare_left_hand", 1.0, 38), _note("crash_right_hand", 1.5, 49)]
    a, ts, drawn = _play(library, notes, [(0.5, notes[:1]), (1.0, notes[1:])])
    assert_same_frames(a, ts, drawn)
    b = _animator(library)  # the whole input known: render's default, motion-report
    for p in notes:
        b.add_planned(p, known_at=p.impact - 0.5)
    np.testing.assert_allclose(
        np.abs(np.sum(b.local_rotations_many(ts) * drawn, axis=-1)), 1.0, atol=1e-9
    )
    assert a.provisional_counts["fixed_same"] == 2
    for p in notes:
        assert contact_distance(a, p, p.impact)[0] < 1e-4


def test_a_revised_hand_changes_no_frame_drawn_and_moves_on_from_where_it_is(
    library: MotionLibrary,
) -> None:
    """The crash is shown to the right hand when known, then the plan fixes the left:
    every frame drawn stays as drawn, the right hand turns back from where it was and
    the left goes, both without a jump, and the crash is struck exactly by the left."""
    shown = _note("crash_right_hand", 1.5, 49)
    fixed = _note("crash_left_hand", 1.5, 49)
    a, ts, drawn = _play(library, [fixed], [(1.0, [shown])])
    assert_same_frames(a, ts, drawn)
    assert a.provisional_counts["fixed_other"] == 1
    assert contact_distance(a, fixed, fixed.impact)[0] < 1e-4
    w = _wrists(a, np.arange(0.9, 2.0, 1 / 120))
    speed = np.linalg.norm(np.diff(w, axis=0), axis=-1) * 120
    assert speed[:, 1].max() < 5.0  # the right hand turns back at a walk
    right_moved = np.linalg.norm(w[:, 1] - w[0, 1], axis=-1).max()
    assert right_moved > 0.02  # it had started toward the crash
    # the left hand learns at the motion's start (its 60 ms lead): fast, but it
    # leaves from where it is, no step at the frame where its course changed
    at = int(round((fixed.start - 0.9) * 120))
    assert speed[at - 2 : at, 0].max() < 5.0  # the first step after it: a start from rest


def test_a_hand_given_the_note_at_its_motions_start_lifts_only_as_its_time_allows(
    library: MotionLibrary,
) -> None:
    """The crash shown to the right hand, fixed to the left at the motion's start: the
    left has the 60-67 ms from where it is, not the second since its last stroke (none),
    so its backswing is what that time allows (lift.per_s x the time) and its stick comes
    down on the crash no faster than a full stroke given its full time does (30 cm in
    90 ms, accelerating: 6.7 m/s).  It came down at 10.3 m/s from a 19 cm backswing
    squeezed into 30 ms.  Frames drawn stay as drawn, the contact exact."""
    shown = _note("crash_right_hand", 1.5, 49)
    fixed = _note("crash_left_hand", 1.5, 49)
    a, ts, drawn = _play(library, [fixed], [(1.0, [shown])])
    assert_same_frames(a, ts, drawn)
    assert a.provisional_counts["fixed_other"] == 1
    assert contact_distance(a, fixed, fixed.impact)[0] < 1e-4
    fine = np.arange(fixed.start - 0.04, fixed.impact + 1e-9, 1 / 600)
    pos, rot = SKELETON.fk(a.local_rotations_many(fine), a._roots)
    crash = GEOMETRY.kit.pieces["crash"]
    h = (sticks(pos[:, 0], rot[:, 0])[:, 0, 1] - crash.centre) @ crash.normal
    s = HandSettings()
    full_stroke = 2 * s.lift_loud_m / s.down_max_s
    assert -np.diff(h).min() * 600 <= full_stroke


def test_a_provisional_hand_revised_before_its_plan_and_taken_back(
    library: MotionLibrary,
) -> None:
    """Shown right, then left (a later note changed the plan), then taken back (the
    note left the set, as a dropped one): the frames drawn stay, the hands settle."""
    right = _note("tom_high_right_hand", 1.6, 48)
    left = _note("tom_high_left_hand", 1.6, 48)
    a, ts, drawn = _play(library, [], [(1.1, [right]), (1.3, [left]), (1.45, [])])
    assert_same_frames(a, ts, drawn)
    assert a.provisional_counts["revised"] == 1
    assert a.provisional_counts["taken_back"] == 1
    w = _wrists(a, np.arange(1.0, 4.0, 1 / 120))
    assert np.linalg.norm(np.diff(w, axis=0), axis=-1).max() * 120 < 8.0


def test_with_nothing_drawn_the_provisional_hands_leave_no_trace(library: MotionLibrary) -> None:
    """The whole input known (nothing drawn): told provisional hands, revised and taken
    back, the motion is exactly that of the fixed plan alone."""
    fixed = [_note("ride_right_hand", 1.0, 51), _note("crash_left_hand", 1.5, 49)]
    a = _animator(library)
    b = _animator(library)
    a.note_provisional([_note("crash_right_hand", 1.5, 49), _note("snare_left_hand", 1.2, 38)])
    a.note_provisional([fixed[1]])
    for p in fixed:
        a.add_planned(p)
        b.add_planned(p)
    ts = np.arange(0.2, 3.0, 1 / 60)
    np.testing.assert_array_equal(a.local_rotations_many(ts), b.local_rotations_many(ts))


def _live(library: MotionLibrary, pins: bool) -> tuple[BandAnimator, dict[int, PlannedNote]]:
    """At 300 bpm: a crash known 0.2 s ahead (the right hand, from rest, is shown moving
    toward it), then a high tom 80 ms after it known only 6 ms before the crash's motion
    starts; played as the live window draws it (30 fps), hands drawn moving pinned in
    the plan or not."""
    a = _animator(library)
    perf = Performance(router=Router(), planner=OnlinePlanner(), animator=a)
    perf.pin_shown = pins
    beats = [Reveal(0.0, Beat(0.2 * k, k // 4, k % 4 + 1, 4, 0, 200_000)) for k in range(12)]
    notes = [Reveal(1.3, NoteOn(1.5, 9, 49, 100)), Reveal(1.39, NoteOn(1.58, 9, 48, 90))]
    planned = run_as_live(perf, beats + notes, 30.0, 0.0)
    return a, {p.note: p for p in planned}


def test_a_hand_drawn_moving_keeps_its_note_at_the_motions_start(library: MotionLibrary) -> None:
    """The unit case of round 7 through the planner: the right hand has been drawn on
    its way from rest to the crash when a late high tom makes the left hand the cheaper
    crash hand by the table; on main 8b7d05b the plan gave the crash to the left 6 ms
    before its motion started (110 ms before it sounds), the right turned back.  Now the
    plan keeps the crash on the right (the other hand would leave only then: the speed
    tier it needs costs more than the table's difference), the right goes on to the tom
    80 ms later, and no wrist passes 8 m/s.  (Round 7's case had a late ride instead of
    the tom: there, since round 8's crossed-arms price, the left taking the crash and the
    right the ride is the better plan, arms open, and the plan gives it.)"""
    a, planned = _live(library, pins=True)
    assert planned[49].limb == "right_hand"
    assert a.provisional_counts["fixed_other"] == 0
    assert a.provisional_counts["revised_moving"] == 0
    assert a.provisional_counts["fixed_same_moving"] >= 1  # it was drawn moving
    w = _wrists(a, np.arange(1.2, 1.7, 1 / 600))
    assert np.linalg.norm(np.diff(w, axis=0), axis=-1).max() * 600 <= 8.0
    for p in planned.values():
        assert contact_distance(a, p, p.impact)[0] < 1e-4
    b, free = _live(library, pins=False)  # not pinned: the left takes the crash
    assert free[49].limb == "left_hand" and b.provisional_counts["revised_moving"] == 1


def _as_live(path: Path, until_s: float) -> tuple[Performance, BandAnimator]:
    """``path``'s first ``until_s`` played as the live window draws it (30 fps, each
    note known a beat ahead), as ``motion-report --as-live`` does."""
    settings = PerformanceSettings()
    perf, _planned = perform(
        settings,
        midi_input(path, settings.routing, 1.0),
        animate=True,
        until_s=until_s,
        as_live_fps=30.0,
    )
    a = perf.animator
    assert isinstance(a, BandAnimator)
    return perf, a


def test_as_live_no_note_is_taken_from_a_hand_drawn_moving_toward_it() -> None:
    """GMD drummer5 afro-cuban calypso 124, the first 2 s as live (motion-report
    --as-live): on main the plan gave two notes the left hand at their motion's start
    (0.36 and 1.32 s) after the right had been drawn moving toward them for 118-133 ms.
    Now no note of a hand drawn moving goes to the other hand, nor is revised away."""
    path = (
        ROOT / "tests" / "data" / "gmd" / "drummer5_session1_13_afrocuban-calypso_124_beat_4-4.mid"
    )
    perf, a = _as_live(path, 2.0)
    counts = a.provisional_counts
    assert counts["fixed_other"] == 0  # main: 2
    assert counts["shown"] > 10 and counts["fixed_same_moving"] >= 2
    assert counts["revised_moving"] == 0
    assert perf.planner.report.summary()["dropped"] == 0


def test_a_hand_frozen_just_before_the_others_impact_does_not_step_aside() -> None:
    """GMD drummer5 merengue 162 (5/8), the first 7.5 s as live: a right-hand snare
    stroke shown at 6.73 s and revised to the left at 6.80 s froze the right hand's
    track there, 23 ms before the left's snare stroke, and the hand got out of its way
    from there: 12 cm aside in 12 ms (12.5 m/s).  Getting out of the way needs
    _YIELD_MIN_S from where the track is frozen too; every wrist stays under 5 m/s."""
    path = (
        ROOT
        / "tests"
        / "data"
        / "gmd"
        / "drummer5_session1_8_latin-venezuelan-merengue_162_beat_5-8.mid"
    )
    _perf, a = _as_live(path, 7.5)
    assert a.provisional_counts["revised"] >= 1
    w = _wrists(a, np.arange(6.5, 7.3, 1 / 600))
    assert np.linalg.norm(np.diff(w, axis=0), axis=-1).max() * 600 < 5.0
