"""The bench's planning figure: measured after a warm-up of other beats, the cold
start reported beside it (no time is asserted: figures are the bench's job)."""

from __future__ import annotations

import math

from virja import bench
from virja.plan import drums


def test_plan_beat_ms_warms_on_other_beats_and_reports_the_cold_start() -> None:
    drums._cache = None  # as a fresh process: no stroke signature compiled yet
    p50, p99, cold = bench.plan_beat_ms(beats=6, warm_beats=3)
    assert all(math.isfinite(x) and x > 0 for x in (p50, p99, cold))
    assert p50 <= p99
    # the warm-up compiled the signatures the measured beats meet, or most of them
    assert drums._cache is not None and len(drums._cache[2]) > 0


def test_the_warm_up_beats_are_not_the_measured_ones() -> None:
    from virja.plan.bench import beat_workload

    measured = {tuple(beat_workload(seed, 16)) for seed in range(300)}
    warm = {tuple(beat_workload(10_000 + s, 16)) for s in range(bench.PLAN_WARM_BEATS)}
    assert not measured & warm
