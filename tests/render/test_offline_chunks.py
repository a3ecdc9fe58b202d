"""The offline render poses the band a stretch of frames at a time (its timer runs
ahead, what the animator is told is held back to its frame): every frame's
instances equal those of the plain loop (feed, commit, pose, scene at each frame),
and the plan is the same."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import DEMO_MID
from virja.input import load_performance_input
from virja.pipeline import PerformanceSettings, build_performance
from virja.render.offline import _Ahead
from virja.render.scene import band_scene
from virja.session import RevealFeeder, frame_times

GMD_TAKE = Path("/work/shared/data/gmd/drummer1/eval_session/1_funk-groove1_138_beat_4-4.mid")


@pytest.mark.parametrize("path", [DEMO_MID, GMD_TAKE], ids=["demo", "gmd"])
def test_chunked_frames_equal_the_plain_loop(path: Path) -> None:
    if not path.is_file():
        pytest.skip(f"{path} not here")
    settings = PerformanceSettings()
    src = load_performance_input(path, settings.routing)
    t0, _ = src.default_span()
    times = list(frame_times(t0, t0 + 8.0, 30.0))
    plain = build_performance(settings, src, animate=True)
    feeder = RevealFeeder(src.schedule)
    want = []
    for t in times:
        feeder.until(plain, t)
        plain.advance(t)
        want.append(band_scene(plain.pose(t)))
    chunked = build_performance(settings, src, animate=True)
    animator = chunked.animator
    ahead = _Ahead(chunked, RevealFeeder(src.schedule), times, 30)
    for t, w in zip(times, want, strict=True):
        got = ahead.scene(t)
        for kind in ("box", "cylinder", "sphere"):
            assert np.allclose(got.packed(kind), w.packed(kind), rtol=0, atol=1e-6), (t, kind)
    ahead.close()
    assert chunked.animator is animator
    assert [p.to_log_json(0.0) for p in chunked.planned] == [
        p.to_log_json(0.0) for p in plain.planned
    ]
    assert ahead.chunks.frames == len(times)  # each frame posed once
    # in stretches of frames, not one by one (a dense take's news: every arrival of a
    # hand note tells the provisional hands, every start the fixed plan)
    assert ahead.chunks.chunks < len(times) * 0.6
    with pytest.raises(ValueError, match="in order"):
        ahead.scene(times[0])


@pytest.mark.parametrize("path", [DEMO_MID, GMD_TAKE], ids=["demo", "gmd"])
def test_by_default_every_frame_is_drawn_knowing_the_whole_input(path: Path) -> None:
    """`virja render` (not --as-live): the whole input played through first, then
    posed 30 frames at a time; each frame is what motion-report and export measure
    (pipeline.perform's animator), the plan is the same."""
    from virja.pipeline import perform
    from virja.render.offline import _Whole

    if not path.is_file():
        pytest.skip(f"{path} not here")
    settings = PerformanceSettings()
    src = load_performance_input(path, settings.routing)
    t0, _ = src.default_span()
    times = list(frame_times(t0, t0 + 6.0, 30.0))
    known, planned = perform(settings, src, animate=True)
    want = [band_scene(known.pose(t)) for t in times]
    drawn = build_performance(settings, src, animate=True)
    whole = _Whole(drawn, RevealFeeder(src.schedule), times, 30)
    for t, w in zip(times, want, strict=True):
        got = whole.scene(t)
        for kind in ("box", "cylinder", "sphere"):
            assert np.allclose(got.packed(kind), w.packed(kind), rtol=0, atol=1e-6), (t, kind)
    assert [p.to_log_json(0.0) for p in drawn.planned] == [p.to_log_json(0.0) for p in planned]
    assert whole.chunks.chunks == -(-len(times) // 30)  # 30 frames a chunk (as asked)
