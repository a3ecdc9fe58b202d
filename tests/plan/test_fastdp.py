"""The compiled inner loops (virja/plan/_dpcore.c) plan exactly as the Python loops."""

from __future__ import annotations

import pytest

from virja.plan import fastdp
from virja.plan.bench import beat_workload, plan_one_beat
from virja.plan.config import PlanConfig

needs_core = pytest.mark.skipif(
    fastdp.core is None, reason="virja/plan/_dpcore.c is not built (tools/build_dpcore.py)"
)


@needs_core
def test_compiled_and_python_loops_plan_the_bench_beats_alike(
    config: PlanConfig, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Both DPs through the whole planner: every planned note the same, field for field."""
    workloads = [beat_workload(seed, 16) for seed in range(40)]
    compiled = [plan_one_beat(w, config) for w in workloads]
    monkeypatch.setattr(fastdp, "core", None)
    plain = [plan_one_beat(w, config) for w in workloads]
    assert [repr(p) for p in compiled] == [repr(p) for p in plain]


def test_a_module_built_from_other_source_is_not_used(monkeypatch: pytest.MonkeyPatch) -> None:
    """A stale build (its recorded digest not the source's) leaves the Python loops."""
    monkeypatch.setattr(fastdp, "source_digest", lambda: "0" * 16)
    assert fastdp.load() is None


def test_the_environment_can_ask_for_the_python_loops(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("VIRJA_PLAN_PURE", "1")
    assert fastdp.load() is None
