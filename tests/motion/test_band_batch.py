"""Batched sampling (BandAnimator.local_rotations_many / poses) equals pose(t) frame by frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import DEMO_MID
from virja.input import load_performance_input
from virja.motion.band import BandAnimator
from virja.plan.planner import OnlinePlanner
from virja.routing import Router, RoutingConfig
from virja.session import Performance, run_schedule

GMD_TAKE = Path("/work/shared/data/gmd/drummer1/eval_session/1_funk-groove1_138_beat_4-4.mid")


def _animate(path: Path) -> tuple[BandAnimator, tuple[float, float]]:
    src = load_performance_input(path, RoutingConfig())
    animator = BandAnimator()
    perf = Performance(
        router=Router.for_session(src.midi, RoutingConfig()),
        planner=OnlinePlanner(tempo=src.tempo),
        animator=animator,
    )
    run_schedule(perf, src.schedule)
    return animator, src.default_span()


@pytest.mark.parametrize("path", [DEMO_MID, GMD_TAKE], ids=["demo", "gmd"])
def test_batched_local_rotations_equal_single_time_ones(path: Path) -> None:
    if not path.is_file():
        pytest.skip(f"{path} not here")
    animator, (t0, t1) = _animate(path)
    times = t0 + np.arange(int((min(t1, t0 + 12) - t0) * 30)) / 30
    single = np.stack([animator.local_rotations(t) for t in times])
    batch = animator.local_rotations_many(times)
    assert batch.shape == single.shape
    assert np.max(np.abs(batch - single)) < 1e-12


def test_batched_poses_equal_pose() -> None:
    animator, (t0, _) = _animate(DEMO_MID)
    times = t0 + np.arange(0, 300, 7) / 30
    for got, t in zip(animator.poses(times), times, strict=True):
        want = animator.pose(float(t))
        assert got.time_s == want.time_s
        for a, b in ((got.drums, want.drums), (got.bass, want.bass)):
            assert np.allclose(a.positions, b.positions, rtol=0, atol=1e-12)
            assert np.allclose(a.rotations, b.rotations, rtol=0, atol=1e-12)
        assert np.allclose(got.sticks, want.sticks, rtol=0, atol=1e-12)
        assert got.hihat_open == pytest.approx(want.hihat_open, abs=1e-12)
        # the kit and string state of all the frames at once (HitTable's windows): the
        # same terms summed in the same order, equal to rounding
        for a_map, b_map in (
            (got.cymbal_swing, want.cymbal_swing),
            (got.string_vibration, want.string_vibration),
            (got.head_hits, want.head_hits),
        ):
            assert list(a_map) == list(b_map)
            assert list(a_map.values()) == pytest.approx(list(b_map.values()), abs=1e-12)
        assert got.string_stops == want.string_stops
        assert np.allclose(got.bass_fingers, want.bass_fingers, rtol=0, atol=1e-12)
        assert np.allclose(got.bass_transform, want.bass_transform, rtol=0, atol=1e-12)


def test_batched_sampling_wants_sorted_times() -> None:
    with pytest.raises(ValueError, match="sorted"):
        BandAnimator().local_rotations_many(np.array([1.0, 0.5]))


def _align_signs_loop(frames: np.ndarray) -> np.ndarray:
    out = frames.copy()
    for k in range(1, out.shape[0]):
        flip = np.sum(out[k] * out[k - 1], axis=-1) < 0
        out[k, flip] *= -1.0
    return out


def test_vectorised_align_signs_equals_the_frame_loop() -> None:
    from virja.motion.clip import align_signs

    rng = np.random.default_rng(7)
    q = rng.normal(size=(60, 9, 4))
    assert np.array_equal(align_signs(q), _align_signs_loop(q))
    q[10, 3] = 0.0  # a zero dot product: the sign restarts, as in the loop
    assert np.array_equal(align_signs(q), _align_signs_loop(q))


def test_sticks_of_many_frames_equal_one_at_a_time() -> None:
    from virja.motion.band import sticks

    animator, (t0, _) = _animate(DEMO_MID)
    times = t0 + np.arange(0, 200, 13) / 30
    loc = animator.local_rotations_many(times)
    from virja.motion.skeleton import SKELETON

    wpos, wrot = SKELETON.fk(loc[:, 0], animator.idle["drums"].root_positions[0])
    many = sticks(wpos, wrot)
    for k in range(len(times)):
        assert np.array_equal(many[k], sticks(wpos[k], wrot[k]))


def test_one_frame_at_a_time_equals_the_batched_pose_through_live_news() -> None:
    """As the live window and the jam pose: news arrives between frames (notes known,
    provisional hands shown, revised and fixed), each frame is posed alone with
    ``pose(t)`` (which marks it drawn); the batched pose of the same time, taken just
    before (many frames at once: the arrays, not the few-row paths), equals it."""
    src = load_performance_input(DEMO_MID, RoutingConfig())
    animator = BandAnimator()
    perf = Performance(
        router=Router.for_session(src.midi, RoutingConfig()),
        planner=OnlinePlanner(tempo=src.tempo),
        animator=animator,
    )
    schedule = sorted(src.schedule, key=lambda r: r.at_s)
    t0 = schedule[0].at_s
    k, fed, drawn = 0, 0, 0
    for t in t0 + np.arange(0.0, 6.0, 1 / 30):  # a frame every 33 ms, 6 s of the demo
        while k < len(schedule) and schedule[k].at_s <= t:
            perf.advance(schedule[k].at_s)
            perf.feed(schedule[k].event, now_s=schedule[k].at_s)
            k, fed = k + 1, fed + 1
        perf.advance(float(t))
        ahead = float(t) + np.arange(40) / 60  # this frame and the next ones, batched
        batch = animator.pose_batch(ahead).pose(0)
        one = perf.pose(float(t))
        drawn += 1
        assert animator.drawn_until == float(t)
        for a, b in ((one.drums, batch.drums), (one.bass, batch.bass)):
            np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-9)
            np.testing.assert_allclose(a.rotations, b.rotations, rtol=0, atol=1e-9)
        np.testing.assert_allclose(one.sticks, batch.sticks, rtol=0, atol=1e-9)
        np.testing.assert_allclose(one.bass_fingers, batch.bass_fingers, rtol=0, atol=1e-9)
        np.testing.assert_allclose(one.bass_transform, batch.bass_transform, rtol=0, atol=1e-9)
        assert one.hihat_open == pytest.approx(batch.hihat_open, abs=1e-9)
        assert one.string_stops == batch.string_stops
    assert fed > 20 and drawn == 180
    assert animator.provisional_counts["shown"] > 0  # hands shown before their plan
