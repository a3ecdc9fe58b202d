"""The drummer's living body: the torso turns and breathes, the sticks stay where the clips put them."""

from __future__ import annotations

import json
from contextlib import redirect_stderr, redirect_stdout
from io import StringIO
from pathlib import Path

import numpy as np
import pytest

from tests.motion.helpers import drum
from virja.cli.main import main
from virja.events import Beat
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.drummer_body import BodySettings
from virja.motion.drummer_report import _yaw_deg
from virja.motion.skeleton import SKELETON

_CHEST = SKELETON.index("Chest")


def _groove(a: BandAnimator, right: str, left: str, n: int = 8, spb: float = 0.5) -> None:
    for k in range(n):
        t = 1.0 + k * spb
        a.add_beat(Beat(t, k // 4, k % 4 + 1, 4, 0, round(spb * 1e6)))
        a.add_planned(drum(f"{right}_right_hand", t - 0.2, t))
        a.add_planned(drum(f"{left}_left_hand", t + spb / 2 - 0.2, t + spb / 2))


def _chest_yaw(a: BandAnimator, times: np.ndarray) -> np.ndarray:
    return _yaw_deg(np.stack([p.drums.rotations[_CHEST] for p in a.poses(times)]))


def test_torso_turns_toward_the_pieces_played(library: MotionLibrary) -> None:
    ride, hihat = BandAnimator(library), BandAnimator(library)
    _groove(ride, "ride", "snare")
    _groove(hihat, "hihat", "snare")
    times = np.arange(2.0, 4.5, 0.05)
    y_ride, y_hihat = _chest_yaw(ride, times), _chest_yaw(hihat, times)
    # the ride is on the drummer's right (-x), the hi-hat on his left (+x)
    assert y_ride.mean() < -3.0
    assert y_hihat.mean() > 3.0
    assert (y_hihat.mean() - y_ride.mean()) > 6.0


def test_sticks_stay_where_the_clips_put_them(library: MotionLibrary) -> None:
    """While a hand plays, its grip and stick are the clip's exactly (the arm is re-solved)."""
    live = BandAnimator(library)
    still = BandAnimator(library, body=BodySettings.still())
    for a in (live, still):
        _groove(a, "ride", "snare", spb=0.4)
    times = np.arange(0.9, 4.6, 1 / 60)
    pl, ps = live.poses(times), still.poses(times)
    err = max(float(np.abs(x.sticks - y.sticks).max()) for x, y in zip(pl, ps, strict=True))
    assert err < 1e-6
    assert np.abs(_yaw_deg(np.stack([x.drums.rotations[_CHEST] for x in pl]))).max() > 3.0


def test_the_turn_is_smooth(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    for k in range(6):  # the right hand goes ride, crash, ride...: the target jumps
        piece = "crash" if k % 2 else "ride"
        a.add_planned(drum(f"{piece}_right_hand", 1.0 + k * 0.6 - 0.2, 1.0 + k * 0.6))
    t = np.arange(0.5, 5.0, 1 / 120)
    yaw = np.degrees(a.body.turn(t))
    assert np.ptp(yaw) > 3.0
    assert np.abs(np.diff(yaw)).max() < 0.5  # < 60 deg/s at 120 fps


def test_a_resting_hand_breathes_with_the_body(library: MotionLibrary) -> None:
    """Long after its last stroke a hand moves with the torso instead of hanging frozen."""
    a = BandAnimator(library)
    a.add_planned(drum("snare_left_hand", 0.8, 1.0))
    times = np.arange(5.0, 9.0, 0.1)
    wrist = SKELETON.index("LeftHand")
    pos = np.stack([p.drums.positions[wrist] for p in a.poses(times)])
    assert np.ptp(pos, axis=0).max() > 0.003
    still = BandAnimator(library, body=BodySettings.still())
    still.add_planned(drum("snare_left_hand", 0.8, 1.0))
    pos0 = np.stack([p.drums.positions[wrist] for p in still.poses(times)])
    assert np.ptp(pos0, axis=0).max() < 1e-9


def test_a_resting_hand_rides_the_sway_not_the_turn(library: MotionLibrary) -> None:
    """The right hand gone to rest after the hi-hat while the left plays on the snare:
    the torso stays turned toward them (about 12 deg), and a resting hand carried by
    the whole turn drifted 12 cm from its track, into the left stick over the snare
    (MMA jazzcombo 60 at 12.5 s).  It now rides only with the beat's sway."""
    live = BandAnimator(library)
    still = BandAnimator(library, body=BodySettings.still())
    for a in (live, still):
        for k in range(5):
            a.add_beat(Beat(1.0 + k, k // 4, k % 4 + 1, 4, 0, 1_000_000))  # 60 bpm
        a.add_planned(drum("hihat_right_hand", 0.8, 1.0))
        for k in range(8):
            a.add_planned(drum("snare_left_hand", 1.0 + 0.5 * k, 1.2 + 0.5 * k))
    times = np.arange(3.0, 4.6, 0.05)  # the right at rest (its last stroke 2 s before)
    wrist = SKELETON.index("RightHand")
    moved = [
        float(np.linalg.norm(x.drums.positions[wrist] - y.drums.positions[wrist]))
        for x, y in zip(live.poses(times), still.poses(times), strict=True)
    ]
    assert np.abs(np.degrees(live.body.turn(times))).min() > 8.0
    assert max(moved) < 0.045  # the sway: at most 4 deg at 60 bpm
    assert max(moved) > 0.003  # ... but not frozen


def test_beat_lean_is_smaller_when_faster(library: MotionLibrary) -> None:
    def lean_range(spb: float) -> float:
        a = BandAnimator(library)
        t0 = 1.0
        for k in range(8):
            a.add_beat(Beat(t0 + k * spb, k // 4, k % 4 + 1, 4, 0, round(spb * 1e6)))
        t = np.arange(t0, t0 + 4 * spb, 0.01)
        return float(np.ptp(a.body._lean(t, np.asarray(a._beat_times), np.asarray(a._beat_spb))))

    assert lean_range(0.5) > 1.5 * lean_range(0.2)


def test_the_sway_grows_with_the_beat_down_to_60_bpm(library: MotionLibrary) -> None:
    """One beat of sway at 60 bpm turns the chest more than 3 degrees (GMD drummer7's
    rock 60 fill: two strokes in a second, one beat in view, turned 2.97 degrees when
    every tempo under 80 bpm swayed alike)."""

    def sway_range(spb: float) -> float:
        a = BandAnimator(library)
        t0 = 1.0
        for k in range(8):
            a.add_beat(Beat(t0 + k * spb, k // 4, k % 4 + 1, 4, 0, round(spb * 1e6)))
        t = np.arange(t0, t0 + spb, spb / 100)  # one beat
        beats, bpms = np.asarray(a._beat_times), np.asarray(a._beat_spb)
        return float(np.degrees(np.ptp(a.body._sway(t, beats, bpms))))

    assert sway_range(1.0) > 3.5
    assert sway_range(1.0) > 1.2 * sway_range(0.75)  # 60 bpm sways more than 80
    assert sway_range(0.2) > 1.5  # and 300 bpm still turns


def test_single_and_batched_poses_agree(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    _groove(a, "ride", "snare", n=4)
    times = np.array([1.1, 1.7, 2.35, 3.0])
    many = a.local_rotations_many(times)
    for k, t in enumerate(times):
        one = a.local_rotations(float(t))
        assert np.allclose(np.abs(np.sum(one * many[k], axis=-1)), 1.0, atol=1e-9)


def test_settings_load_from_the_table() -> None:
    s = BodySettings.load()
    assert s.gain > 0 and s.max_turn_deg > 3 and not s.is_still
    assert BodySettings.still().is_still


def test_still_before_the_first_stroke(library: MotionLibrary) -> None:
    """Nothing played yet: the drummer sits still (a waiting window shows no motion)."""
    a = BandAnimator(library)
    a.add_planned(drum("snare_left_hand", 9.8, 10.0))
    early = a.local_rotations_many(np.arange(0.0, 8.0, 0.25))[:, 0]  # the drummer
    body = [i for i, n in enumerate(SKELETON.names) if n not in ("Neck", "Head")]  # idle nod
    assert np.abs(early[:, body] - early[0, body]).max() < 1e-12
    assert np.ptp(_chest_yaw(a, np.arange(9.5, 12.0, 0.05))) > 0.5


def test_the_feet_alone_wake_the_body(library: MotionLibrary) -> None:
    """GMD rock 118 (drummer7 session2 take 22): three hi-hat pedal chicks and nothing
    else; the body woke only for a hand's stroke, so the drummer sat still (torso 0)."""
    a = BandAnimator(library)
    for k in range(4):
        a.add_beat(Beat(1.0 + 0.5 * k, 0, k + 1, 4, 0, 500_000))
        a.add_planned(drum("hihat_left_foot", 0.85 + 0.5 * k, 1.0 + 0.5 * k))
    assert np.ptp(_chest_yaw(a, np.arange(1.0, 3.0, 0.02))) > 3.0


def test_the_right_foot_feathers_the_kick_on_beats_without_a_kick(
    library: MotionLibrary,
) -> None:
    """A ride pattern at 120 bpm, a kick on beat 3 only: the right toe presses down a
    few millimetres on the other beats, not at all near the kick (exact contact)."""
    from dataclasses import replace

    from virja.motion.metrics import contact_distance

    toe = SKELETON.index("RightToe")
    kick = drum("kick_right_foot", 1.85, 2.0, velocity=90)
    ys = []
    for feather in (BodySettings().feather_deg, 0.0):
        a = BandAnimator(library, body=replace(BodySettings(), feather_deg=feather))
        for k in range(8):
            a.add_beat(Beat(1.0 + 0.5 * k, k // 4, k % 4 + 1, 4, 0, 500_000))
            a.add_planned(drum("ride_right_hand", 0.8 + 0.5 * k, 1.0 + 0.5 * k, velocity=70))
        a.add_planned(kick)
        ts = np.array([1.8, 1.9, 2.0, 2.1, 2.5, 2.75])
        pos, _rot = SKELETON.fk(a.local_rotations_many(ts), a._roots)
        ys.append(pos[:, 0, toe, 1])
        assert contact_distance(a, kick, 2.0)[0] < 1e-4
    feathered, flat = ys
    np.testing.assert_allclose(feathered[:4], flat[:4], atol=1e-9)  # near the kick
    assert feathered[4] < flat[4] - 0.005  # pressed on a free beat
    assert abs(feathered[5] - flat[5]) < 1e-9  # and back between beats


def _rock(a: BandAnimator, beats: int, spb: float = 60 / 130) -> None:
    """Ride on every beat; the left's snare on the off-beats, a hi-hat every second
    one (GMD drummer2 rock 130)."""
    for k in range(beats):
        t = 1.0 + k * spb
        a.add_beat(Beat(t, k // 4, k % 4 + 1, 4, 0, round(spb * 1e6)))
        a.add_planned(drum("ride_right_hand", t - 0.2, t))
        left = "hihat" if k % 2 else "snare"
        a.add_planned(drum(f"{left}_left_hand", t + spb / 2 - 0.2, t + spb / 2))


def test_the_sway_goes_the_way_the_turn_goes(library: MotionLibrary) -> None:
    """On each beat the torso sways toward where the turn goes over the beat's first
    half: one way on one beat and the other way on the next, the sway went against the
    turn on every second beat of a rock groove and the two cancelled (GMD drummer2
    rock 130: 2.8 degrees of chest together)."""
    a = BandAnimator(library)
    spb = 60 / 130
    _rock(a, 12, spb)
    beats = np.asarray(a._beat_times)
    spbs = np.asarray(a._beat_spb)
    followed = 0
    for b in beats[2:-2]:
        d = float(a.body.turn(np.array([b + spb / 2]))[0] - a.body.turn(np.array([b]))[0])
        sway = float(a.body._sway(np.array([b + spb / 2]), beats, spbs)[0])
        if abs(d) > np.radians(0.05):
            assert np.sign(sway) == np.sign(d)
            followed += 1
    assert followed >= 4
    times = np.arange(2.0, 6.0, 1 / 60)
    swayed = a.body._sway(times, beats, spbs)
    assert np.degrees(np.ptp(a.body.turn(times) + swayed)) > np.degrees(np.ptp(swayed)) + 1.0


@pytest.mark.parametrize("posed", [True, False])
def test_a_beats_sway_keeps_its_side_once_drawn(library: MotionLibrary, posed: bool) -> None:
    """Live, a stroke learnt during a beat never flips its sway (a jump of twice its
    amplitude): the side is kept from the first frame drawn inside the beat, whether
    its pose was asked for (the window) or the frame only marked drawn (as live)."""
    spb = 0.5

    def groove(a: BandAnimator) -> None:
        for k in range(10):
            t = 1.0 + k * spb
            a.add_beat(Beat(t, k // 4, k % 4 + 1, 4, 0, round(spb * 1e6)))
            a.add_planned(drum("snare_left_hand", t - 0.2, t))
            if k < 6:
                a.add_planned(drum("snare_right_hand", t + 0.05, t + 0.25))

    live, whole = BandAnimator(library), BandAnimator(library)
    groove(live)
    groove(whole)
    b = 1.0 + 6 * spb  # the right goes on to the ride (-x) in this beat's first half
    late = drum("ride_right_hand", b - 0.1, b + 0.1)
    whole.add_planned(late)
    at = b + 0.05
    if posed:
        live.pose(at)  # shown, and marked drawn
    else:
        live.mark_drawn(at)
    live.add_planned(late)  # learnt after the frame at ``at`` was drawn
    beats, spbs = np.asarray(live._beat_times), np.asarray(live._beat_spb)
    mid = np.array([at, b + spb / 2])
    side_live = np.sign(live.body._sway(mid, beats, spbs))
    side_whole = np.sign(whole.body._sway(mid, beats, spbs))
    assert list(side_whole) == [-1.0, -1.0]  # known in time: the turn's way (the ride)
    assert list(side_live) == [1.0, 1.0]  # learnt late: the side drawn (the beat's parity)


def test_a_short_rock_groove_turns_the_chest_3_degrees() -> None:
    """GMD drummer2 session2 take 10 (rock, 130 bpm, 17 notes in 1.8 s): its chest
    turned 2.9 degrees on main 36cbd24, the turn toward the hi-hat against the beat's
    sway; issue 15's target is 3 or more."""
    path = Path(__file__).resolve().parent.parent / "data" / "gmd"
    out = StringIO()
    argv = ["motion-report", str(path / "drummer2_session2_10_rock_130_beat_4-4.mid"), "--json"]
    with redirect_stdout(out), redirect_stderr(StringIO()):
        assert main(argv) == 0
    assert json.loads(out.getvalue())["drums"]["torso_range_deg"] >= 3.0


def test_the_turn_never_changes_under_a_frame_drawn(library: MotionLibrary) -> None:
    """Live, each stroke is learnt when its motion is committed, at its start (0.18 s
    before its impact here), and the turn averages the hands' pieces over 0.25 s either
    side: a stroke taken in at its impact moved the turn under frames already drawn, up
    to 4 degrees a frame at 300 bpm (MMA swing1 300, as live).  A stroke's piece is now
    taken in no sooner than half the window after it is known."""
    live, whole = BandAnimator(library), BandAnimator(library)
    pieces = ["ride", "crash", "hihat", "ride", "snare", "ride"]
    notes = [
        drum(f"{pieces[k % len(pieces)]}_right_hand", 0.82 + 0.3 * k, 1.0 + 0.3 * k)
        for k in range(10)
    ]
    notes += [drum("snare_left_hand", 0.97 + 0.6 * k, 1.15 + 0.6 * k) for k in range(5)]
    notes.sort(key=lambda p: p.start)
    for p in notes:
        whole.add_planned(p)
    frames = np.arange(0.5, 5.0, 1 / 60)
    drawn = []
    k = 0
    for t in frames:
        while k < len(notes) and notes[k].start <= t:  # committed at its start
            live.add_planned(notes[k])
            k += 1
        drawn.append(float(live.body.turn(np.array([t]))[0]))
        live.mark_drawn(t)
    final = live.body.turn(frames)
    assert np.abs(np.asarray(drawn) - final).max() < 1e-12
    assert np.abs(final - whole.body.turn(frames)).max() < 1e-12
    assert np.degrees(np.ptp(final)) > 3.0
