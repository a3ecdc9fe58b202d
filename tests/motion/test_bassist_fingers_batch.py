"""The bassist's fingers posed for many frames at once (``Bassist.fingers_many``, used by
``BandAnimator.pose_batch``) equal the per-frame ``Bassist.fingers`` on the demo, on a line
with open strings, note-offs and thumb position, on a six-string, and with notes added
out of order."""

from __future__ import annotations

import numpy as np

from tests.conftest import DEMO_MID
from tests.motion.helpers import bass
from tests.motion.test_band_batch import _animate
from virja.events import NoteOff
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.skeleton import SKELETON


def _compare(a: BandAnimator, times: np.ndarray) -> int:
    """Every frame: batched fingers == per-frame ones; and poses() == pose(); returns how
    many frames had their fingers move from the frame before (they are not frozen)."""
    loc = a.local_rotations_many(times)
    wpos, _ = SKELETON.fk(loc, a._roots)
    leans = a.bass_transform(wpos[:, 1])
    own = np.stack(
        [bass_lean.apply(bass_lean.inverse(m), p) for m, p in zip(leans, wpos[:, 1], strict=True)]
    )
    many = a.bassist.fingers_many(times, own)
    for k, t in enumerate(times.tolist()):
        one = a.bassist.fingers(t, own[k])
        assert many[k].shape == one.shape
        assert np.abs(many[k] - one).max() < 1e-12, f"t={t}"
    poses = a.poses(times)
    for k in range(0, len(times), 7):
        want = a.pose(float(times[k])).bass_fingers
        assert np.abs(poses[k].bass_fingers - want).max() < 1e-9, times[k]
    return int((np.abs(np.diff(many, axis=0)).max(axis=(1, 2, 3)) > 1e-6).sum())


def test_batched_fingers_on_the_demo() -> None:
    a, (t0, t1) = _animate(DEMO_MID)
    times = t0 + np.arange(int((min(t1, t0 + 12.0) - t0) * 30)) / 30
    assert _compare(a, times) > len(times) // 2


def test_batched_fingers_with_open_strings_note_offs_and_thumb_position(
    library: MotionLibrary,
) -> None:
    a = BandAnimator(library)
    line = [("E", 3), ("A", 0), ("D", 7), ("G", 14), ("G", 16), ("A", 5), ("E", 0), ("D", 2)]
    for i, (string, fret) in enumerate(line):
        a.add_planned(bass(string, fret, 0.5 * i + 0.3, 0.5 * i + 0.5))
    a.note_off("bass", NoteOff(0.7, 0, 40))  # the first note ends early: the fingers lift
    times = np.arange(0.0, 6.0, 1 / 30)
    assert _compare(a, times) > 40


def test_batched_fingers_on_a_six_string_and_before_any_note(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    a.use_bass_strings(("B", "E", "A", "D", "G", "C"))
    assert a.bassist.fingers_many(np.array([0.0]), np.zeros((1, SKELETON.n_joints, 3))).shape == (
        1,
        17,
        2,
        3,
    )
    for i, (string, fret) in enumerate([("B", 2), ("C", 12), ("C", 19), ("G", 0)]):
        a.add_planned(bass(string, fret, 0.6 * i + 0.3, 0.6 * i + 0.5))
    _compare(a, np.arange(0.0, 3.5, 1 / 30))


def test_notes_added_out_of_order_fall_back_to_the_per_frame_fingers(
    library: MotionLibrary,
) -> None:
    a = BandAnimator(library)
    a.add_planned(bass("A", 5, 0.95, 1.0))
    a.add_planned(bass("D", 7, 0.97, 0.99))  # an earlier impact, started after the first
    assert np.any(np.diff(a.bassist._note_table().start) < 0)
    _compare(a, np.arange(0.0, 2.0, 1 / 30))
