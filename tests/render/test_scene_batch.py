"""The moving band for a chunk of frames at once (render.scene_batch) equals
band_scene frame by frame, row for row after packing: on the demo's frames (heads
lit, cymbals swinging, the hi-hat opening, strings vibrating at stops, the bass
leaning) and on a six-string bass whose B and C strings ring."""

from __future__ import annotations

import numpy as np
import pytest

from tests.motion.helpers import bass
from virja.bench import _demo_animator
from virja.motion.band import BandAnimator
from virja.render.pedals import beater, beater_many, footboards, footboards_many
from virja.render.renderer import DrawList
from virja.render.scene import band_scene
from virja.render.scene_batch import band_scenes
from virja.vocab import ALL_BASS_STRINGS

KINDS = ("box", "cylinder", "sphere")


def _same_rows(got: DrawList, want: DrawList) -> None:
    for kind in KINDS:
        a, b = got.packed(kind), want.packed(kind)
        assert a.shape == b.shape, kind
        assert np.allclose(a, b, rtol=0, atol=1e-6), kind  # float32 rows


def test_chunks_of_demo_frames_equal_band_scene_frame_by_frame() -> None:
    animator, t0, t1 = _demo_animator()
    times = t0 + np.arange(int((t1 - t0) * 30)) / 30
    vibrating = lit = 0
    for start in range(0, len(times), 90):  # a chunk every 3 s, 24 frames each
        batch = animator.pose_batch(times[start : start + 24])
        scenes = band_scenes(batch)
        assert len(scenes) == len(batch)
        for k, dl in enumerate(scenes):
            pose = batch.pose(k)
            _same_rows(dl, band_scene(pose))
            vibrating += any(v > 1e-5 for v in pose.string_vibration.values())
            lit += any(v > 0.05 for v in pose.head_hits.values())
    assert vibrating > 20 and lit > 20  # the variable rows were exercised


def test_a_six_string_bass_ringing_on_its_b_and_c_strings() -> None:
    a = BandAnimator()
    a.use_bass_strings(ALL_BASS_STRINGS)
    a.add_planned(bass("B", 3, 1.0, 1.2))
    a.add_planned(bass("C", 7, 1.5, 1.7))
    batch = a.pose_batch(np.linspace(0.9, 2.2, 20))
    assert batch.strings == ALL_BASS_STRINGS
    for k, dl in enumerate(band_scenes(batch)):
        _same_rows(dl, band_scene(batch.pose(k)))
    assert (batch.string_vibration[:, [0, -1]] > 1e-5).any(axis=0).all()


def test_an_empty_chunk_and_a_prepacked_list_stays_as_built() -> None:
    animator, t0, _ = _demo_animator()
    assert band_scenes(animator.pose_batch(np.zeros(0))) == []
    dl = band_scenes(animator.pose_batch(np.array([t0 + 2.0])))[0]
    assert not dl.frozen and dl.count() > 100
    with pytest.raises(RuntimeError, match="prepacked"):
        dl.add("sphere", np.eye(4), (1.0, 1.0, 1.0, 1.0))


def test_pedals_over_frames_equal_one_frame_at_a_time() -> None:
    from virja.geometry import GEOMETRY

    animator, t0, _ = _demo_animator()
    batch = animator.pose_batch(t0 + np.arange(90) / 30)
    names = batch.names
    right = batch.positions[:, 0, names.index("RightToe"), 1]
    left = batch.positions[:, 0, names.index("LeftToe"), 1]
    all_boards, all_downs = footboards_many(GEOMETRY, right, left)
    axles, balls = beater_many(GEOMETRY, all_downs[:, 0])
    for k in range(len(batch)):
        boards, downs = footboards(GEOMETRY, batch.pose(k))
        axle, ball = beater(GEOMETRY, downs[0])
        assert np.allclose(boards, all_boards[k], rtol=0, atol=1e-12)
        assert downs == pytest.approx(tuple(all_downs[k]), abs=1e-12)
        assert np.allclose(axle, axles[k]) and np.allclose(ball, balls[k], rtol=0, atol=1e-12)
    assert np.ptp(all_downs[:, 0]) > 0.5  # the kick pedal went down and up
