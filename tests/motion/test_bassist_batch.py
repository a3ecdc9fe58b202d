"""The bassist's body batched over frames (``Bassist.body_many``) equals the plain
per-frame version (kept here as it was written before the speed work: forward
kinematics, the torso moved, the reach search and the arms solved, one frame at a
time) on the demo and on a five-string take, with beats, stops, vibrato and
note-offs; and the note table follows notes added, ended and forgotten."""

from __future__ import annotations

import bisect
import math

import numpy as np
import pytest

from tests.conftest import DEMO_MID
from tests.motion.helpers import bass
from tests.motion.test_band_batch import _animate
from virja import quat
from virja.events import NoteOff
from virja.geometry import GEOMETRY
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.motion.bassist import (
    _ARM_LEN,
    _ARMS,
    _FORES,
    _HANDS,
    _LTIP,
    _SHOULDERS,
    CHEST,
    POLE_PUSH_MAX_M,
    POLE_PUSH_PER_M,
    WRIST_BESIDE_M,
    Bassist,
    _two_bone,
)
from virja.motion.clip import MotionLibrary
from virja.motion.skeleton import SKELETON as _SK


def _plain_vibrato(b: Bassist, t: float) -> np.ndarray:
    import bisect

    s = b.settings
    i = bisect.bisect_right(b._times, t)
    if i == 0:
        return np.zeros(3)
    n = b._notes[i - 1]
    nxt = b._notes[i].start if i < len(b._notes) else math.inf
    end = min(n.off, nxt)
    held = t - n.impact
    if n.fret <= 0 or held < s.vibrato_after_s or end - n.impact < s.long_note_s or t >= end:
        return np.zeros(3)
    ramp = min(1.0, (held - s.vibrato_after_s) / 0.2, max(0.0, (end - t) / 0.1))
    amp = s.vibrato_m * ramp * math.sin(2 * math.pi * s.vibrato_hz * (held - s.vibrato_after_s))
    return amp * b.geometry.bass.string_dir(n.string)


def _plain_torso(loc: np.ndarray, sway: float, dip: float, turn: float) -> np.ndarray:
    out = loc.copy()
    hips, spine, chest = _SK.index("Hips"), _SK.index("Spine"), _SK.index("Chest")
    q_sway = quat.from_axis_angle([0.0, 0.0, 1.0], sway)
    out[hips] = quat.multiply(out[hips], q_sway)
    legs = [_SK.index("LeftUpLeg"), _SK.index("RightUpLeg")]
    out[legs] = quat.multiply(quat.conjugate(q_sway), out[legs])
    out[spine] = quat.multiply(out[spine], quat.from_axis_angle([1.0, 0.0, 0.0], dip))
    out[chest] = quat.multiply(out[chest], quat.from_axis_angle([0.0, 1.0, 0.0], turn))
    return out


def _plain_wrist_beside_board(
    b: Bassist, wrist: np.ndarray, tip: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    s = b.settings
    n = b.neck
    rel = wrist - tip
    length = float(np.linalg.norm(rel))
    c_tip = n.coords(tip)
    need = float(n.low_edge(float(c_tip[0]))) + WRIST_BESIDE_M
    if float(n.coords(wrist)[1]) >= need or length < 1e-9:
        return wrist, quat.identity(), 0.0
    d_need = need - float(c_tip[1])
    d_lat = min(d_need, s.reach_share * length)
    ramp = min(max((d_need - d_lat) / s.arch_ramp_m, 0.0), 1.0)
    r = math.sqrt(max(length**2 - d_lat**2, 0.0))
    along, face = float(rel @ n.along), float(rel @ n.face)
    norm = math.hypot(along, face)
    f0, a0 = (face / norm, along / norm) if norm > 1e-9 else (1.0, 0.0)
    f = max(r * f0, -r + (min(s.arch_m, r) + r) * ramp)
    a = math.copysign(math.sqrt(max(r**2 - f**2, 0.0)), 1.0 if a0 >= 0.0 else -1.0)
    new = d_lat * n.lateral + a * n.along + f * n.face
    elbow_ramp = min(max((d_need - d_lat) / (3.0 * s.arch_ramp_m), 0.0), 1.0)
    return tip + new, quat.from_two_vectors(rel, new), elbow_ramp


def _plain_reach_with_shoulder(
    b: Bassist, out: np.ndarray, pos: np.ndarray, rot: np.ndarray, wrist: np.ndarray
) -> bool:
    s = b.settings
    clav, shoulder = pos[_SHOULDERS[0]], pos[_ARMS[0]]
    excess = float(np.linalg.norm(wrist - shoulder)) - s.shoulder_slack_m
    if excess <= 0.0:
        return False
    bone = shoulder - clav
    axis = np.cross(bone, wrist - clav)
    n = float(np.linalg.norm(axis))
    if n < 1e-12:
        return False
    angle = min(excess / float(np.linalg.norm(bone)), s.shoulder_max_rad)
    world = quat.multiply(quat.from_axis_angle(axis / n, angle), rot[_SHOULDERS[0]])
    parent = int(_SK.parents[_SHOULDERS[0]])
    out[_SHOULDERS[0]] = quat.multiply(quat.conjugate(rot[parent]), world)
    return True


def plain_body(
    b: Bassist, loc: np.ndarray, root: np.ndarray, t: float, beat_phase: float, beat_index: int
) -> np.ndarray:
    s = b.settings
    wpos, wrot = _SK.fk(loc, root)
    held = b.fretted(t)
    if not b._notes:
        return loc
    # before the first note: its envelope is 0 (the body still), the arm goes round the board
    last = b.current(t) or b._notes[0]
    i = max(bisect.bisect_right(b._times, t) - 1, 0)
    ramp = s.body_ramp_s
    after = min(max(3.0 - (t - last.impact), 0.0), 1.0)
    nxt = b._notes[i + 1].impact if i + 1 < len(b._notes) else math.inf
    before = min(max(1.0 + (t - nxt) / ramp, 0.0), 1.0)
    first = min(max((t - b._notes[0].impact) / ramp, 0.0), 1.0)
    loud = (0.6 + 0.4 * last.velocity / 127) * max(after, before) * first
    two = (beat_index % 2 + beat_phase) / 2.0
    sway = s.sway_rad * loud * math.cos(2 * math.pi * two)
    dip = s.dip_rad * loud * (0.5 + 0.5 * math.cos(2 * math.pi * (beat_phase - s.dip_after_beat)))
    # the chest turns with where the fingertip is along the neck while a stopped note is held
    down = 0.0
    if held is not None:
        down = min(max(float(b.neck.coords(wpos[_LTIP])[0]), 0.0), b.neck.length)
    turn = s.turn_rad_per_m * down
    targets = wpos[_HANDS].copy()
    hand_rot = wrot[_HANDS].copy()
    targets[0], turn_hand, arched = _plain_wrist_beside_board(b, wpos[_HANDS[0]], wpos[_LTIP])
    hand_rot[0] = quat.multiply(turn_hand, hand_rot[0])
    targets[0] += _plain_vibrato(b, t)
    endpin = b.geometry.bass.endpin

    def posed(k: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        out = _plain_torso(loc, k * sway, k * dip, k * turn)
        pos, rot = _SK.fk(out, root)
        q = b.lean(pos[CHEST], wpos[CHEST])
        return out, pos, rot, q, bass_lean.apply(bass_lean.matrix(q, endpin), targets)

    out, moved_pos, moved_rot, q, leaned = posed(1.0)
    reach = _ARM_LEN[0] + _ARM_LEN[1] - 1e-3
    k = 1.0
    for i in range(2):
        s0, s1 = wpos[_ARMS[i]], moved_pos[_ARMS[i]]
        t0, t1 = targets[i], leaned[i]
        if np.linalg.norm(t1 - s1) > reach:
            lo, hi = 0.0, 1.0
            for _ in range(12):
                mid = 0.5 * (lo + hi)
                if np.linalg.norm(t0 + mid * (t1 - t0) - (s0 + mid * (s1 - s0))) > reach:
                    hi = mid
                else:
                    lo = mid
            k = min(k, lo)
    if k < 1.0:
        out, moved_pos, moved_rot, q, leaned = posed(k)
    if _plain_reach_with_shoulder(b, out, moved_pos, moved_rot, leaned[0]):
        moved_pos, moved_rot = _SK.fk(out, root)
    poles = wpos[_FORES] + (moved_pos[_ARMS] - wpos[_ARMS])
    across = -float(b.neck.coords(wpos[_LTIP])[1])
    push = min(max(across, 0.0) * POLE_PUSH_PER_M, POLE_PUSH_MAX_M)
    poles[0] += push * quat.rotate(q, b.neck.lateral)
    poles[0] += arched * s.arch_elbow_m * quat.rotate(q, b.neck.face)
    poles[0] += max(arched * POLE_PUSH_MAX_M - push, 0.0) * quat.rotate(q, b.neck.lateral)
    upper, lower = _two_bone(moved_pos[_ARMS], leaned, poles)
    out[_ARMS] = quat.multiply(quat.conjugate(moved_rot[_SHOULDERS]), upper)
    out[_FORES] = quat.multiply(quat.conjugate(upper), lower)
    out[_HANDS] = quat.multiply(quat.conjugate(lower), quat.multiply(q, hand_rot))
    return out


def _same_up_to_sign(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference between rotations, q and -q being the same rotation."""
    d = np.minimum(np.abs(a - b).max(axis=-1), np.abs(a + b).max(axis=-1))
    return float(d.max())


def _compare(animator: BandAnimator, times: np.ndarray) -> None:
    loc = animator.local_rotations_many(times)  # the bassist's body, batched
    moved = 0
    for k, t in enumerate(times.tolist()):
        # the clips' pose before the body: rebuild it as local_rotations does
        index, phase = animator._pulse_at(t)
        pre = _clips_only(animator, t)
        want = plain_body(animator.bassist, pre, animator._roots[1], t, phase, index)
        assert _same_up_to_sign(loc[k, 1], want) < 1e-12, f"t={t}"
        moved += int(_same_up_to_sign(want, pre) > 1e-6)
    assert moved > len(times) // 2  # the body really moved in most frames


def _clips_only(animator: BandAnimator, t: float) -> np.ndarray:
    """The bassist's local rotations at ``t`` from the clips alone (no living body)."""
    nod = animator._nod(t)
    loc = animator.idle["bass"].rotations[0].copy()
    loc[_SK.index("Neck")] = quat.multiply(loc[_SK.index("Neck")], nod[0])
    loc[_SK.index("Head")] = quat.multiply(loc[_SK.index("Head")], nod[1])
    for limb in ("left_hand", "right_hand"):
        tl = animator.timelines[("bass", limb)]
        if len(tl):
            loc[tl.joint_index] = tl.blend(t, loc[tl.joint_index])
    return loc


def test_batched_body_equals_the_plain_one_on_the_demo() -> None:
    animator, (t0, t1) = _animate(DEMO_MID)
    _compare(animator, t0 + np.arange(int((t1 - t0) * 30)) / 30)


def test_batched_body_with_note_offs_vibrato_and_forgetting(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    for i, (string, fret) in enumerate([("E", 3), ("A", 0), ("D", 7), ("G", 12), ("A", 5)]):
        a.add_planned(bass(string, fret, 0.8 * i + 0.3, 0.8 * i + 0.5))
    a.note_off("bass", NoteOff(1.0, 0, 40))  # ends the first note early
    assert a.bassist._notes[0].off == 1.0
    times = np.arange(0.0, 8.0, 1 / 30)
    _compare(a, times)
    a.forget_before(12.0)  # drops the old notes: the table follows
    a.add_planned(bass("D", 2, 12.3, 12.5))
    _compare(a, np.arange(12.0, 14.0, 1 / 30))
    assert a.bassist._note_table().impact.tolist() == [n.impact for n in a.bassist._notes]


def test_batched_body_on_a_six_string_high_up(library: MotionLibrary) -> None:
    """The high C and G up the neck of a six-string: the hand arched over the wide board
    (its wrist in front of the strings, the elbow's pole raised) in both versions."""
    a = BandAnimator(library)
    a.use_bass_strings(("B", "E", "A", "D", "G", "C"))
    frets = [("C", 12), ("C", 17), ("G", 15), ("C", 20), ("B", 3), ("C", 9)]
    for i, (string, fret) in enumerate(frets):
        a.add_planned(bass(string, fret, 0.6 * i + 0.3, 0.6 * i + 0.5))
    _compare(a, np.arange(0.0, 5.0, 1 / 30))


@pytest.mark.parametrize("fret", [0, 5])
def test_table_matches_fretted_lookup(library: MotionLibrary, fret: int) -> None:
    b = Bassist(GEOMETRY)
    for i in range(40):  # more than 32 notes since the last stopped one: as fretted() says
        b.add(0.25 * i, 40, "E", fret if i == 0 else 0, "pluck_E", 90)
    tab = b._note_table()
    for t in np.arange(0.0, 11.0, 0.1):
        i = np.searchsorted(tab.impact, [t], side="right")
        held = b.fretted(float(t))
        assert tab.has_fretted(i)[0] == (held is not None)
