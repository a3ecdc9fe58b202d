"""The bassist's body batched over frames (``Bassist.body_many``) equals the plain
per-frame version (kept here as it was written before the speed work: forward
kinematics, the torso moved, the reach search and the arms solved, one frame at a
time) on the demo and on a five-string take, with beats, stops, vibrato and
note-offs; and the note table follows notes added, ended and forgotten."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import DEMO_MID
from tests.motion.helpers import bass
from tests.motion.test_band_batch import _animate
from virja.events import NoteOff
from virja.geometry import GEOMETRY
from virja.motion import quat
from virja.motion.band import BandAnimator
from virja.motion.bassist import (
    _ARM_LEN,
    _ARMS,
    _FORES,
    _HANDS,
    _SHOULDERS,
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


def plain_body(
    b: Bassist, loc: np.ndarray, root: np.ndarray, t: float, beat_phase: float, beat_index: int
) -> np.ndarray:
    s = b.settings
    wpos, wrot = _SK.fk(loc, root)
    held = b.fretted(t)
    last = b.current(t)
    if last is None:
        return loc
    settle = min(max(3.0 - (t - last.impact), 0.0), 1.0)
    loud = (0.6 + 0.4 * last.velocity / 127) * settle
    two = (beat_index % 2 + beat_phase) / 2.0
    sway = s.sway_rad * loud * math.sin(2 * math.pi * two)
    dip = s.dip_rad * loud * math.sin(math.pi * beat_phase) ** 2
    turn = s.turn_rad_per_m * (b.geometry.bass.fret_distance(held.fret) if held else 0.0)
    targets = wpos[_HANDS].copy()
    targets[0] += _plain_vibrato(b, t)
    out = _plain_torso(loc, sway, dip, turn)
    moved_pos, moved_rot = _SK.fk(out, root)
    reach = _ARM_LEN[0] + _ARM_LEN[1] - 1e-3
    k = 1.0
    for i in range(2):
        s0, s1 = wpos[_ARMS[i]], moved_pos[_ARMS[i]]
        if np.linalg.norm(targets[i] - s1) > reach:
            lo, hi = 0.0, 1.0
            for _ in range(12):
                mid = 0.5 * (lo + hi)
                if np.linalg.norm(targets[i] - (s0 + mid * (s1 - s0))) > reach:
                    hi = mid
                else:
                    lo = mid
            k = min(k, lo)
    if k < 1.0:
        out = _plain_torso(loc, k * sway, k * dip, k * turn)
        moved_pos, moved_rot = _SK.fk(out, root)
    poles = wpos[_FORES] + (moved_pos[_ARMS] - wpos[_ARMS])
    upper, lower = _two_bone(moved_pos[_ARMS], targets, poles)
    out[_ARMS] = quat.multiply(quat.conjugate(moved_rot[_SHOULDERS]), upper)
    out[_FORES] = quat.multiply(quat.conjugate(upper), lower)
    out[_HANDS] = quat.multiply(quat.conjugate(lower), wrot[_HANDS])
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
        index, phase = animator._beat_phase(t)
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


@pytest.mark.parametrize("fret", [0, 5])
def test_table_matches_fretted_lookup(library: MotionLibrary, fret: int) -> None:
    b = Bassist(GEOMETRY)
    for i in range(40):  # more than 32 notes since the last stopped one: as fretted() says
        b.add(0.25 * i, 40, "E", fret if i == 0 else 0, "pluck_E", 90)
    tab = b._note_table()
    for t in np.arange(0.0, 11.0, 0.1):
        i = np.searchsorted(tab.impact, [t], side="right")
        held = b.fretted(float(t))
        want = GEOMETRY.bass.fret_distance(held.fret) if held else 0.0
        assert tab.fretted_down(i)[0] == want
