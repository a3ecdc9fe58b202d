"""The compiled inner loops (virja/plan/_dpcore.c) plan exactly as the Python loops."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import pytest

from virja.plan import drums, fastdp
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


def test_the_bench_reports_the_pure_path_under_virja_plan_pure() -> None:
    """``virja bench``'s planning figure says which DP path ran: "pure" when the
    environment asks for the Python loops (a fresh process: the choice is made at import)."""
    env = dict(os.environ, VIRJA_PLAN_PURE="1")
    out = subprocess.run(
        [sys.executable, "-c", "from virja.bench import plan_path; print(plan_path())"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.strip() == "pure (VIRJA_PLAN_PURE=1)"


def test_the_path_names_a_stale_build(monkeypatch: pytest.MonkeyPatch) -> None:
    """A build of another source is reported as a stale build fallen back from."""
    monkeypatch.delenv("VIRJA_PLAN_PURE", raising=False)
    monkeypatch.setattr(fastdp, "source_digest", lambda: "0" * 16)
    try:
        import virja.plan._dpcore  # noqa: F401
    except ImportError:
        pytest.skip("virja/plan/_dpcore.c is not built (tools/build_dpcore.py)")
    module, path = fastdp.load_with_path()
    assert module is None
    assert path.startswith("pure (stale build")


@needs_core
def test_the_path_says_compiled_when_the_build_is_used() -> None:
    assert fastdp.path() == "compiled"


def test_the_path_says_pure_when_the_build_is_set_aside(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fastdp, "core", None)
    assert fastdp.path().startswith("pure")


class _StepsOnly:
    """The compiled module with its whole-window call refused: the per-group compiled
    steps (``hand_step``) run instead, as for input ``hand_window`` does not take."""

    def __init__(self, core: object) -> None:
        self._core = core

    def __getattr__(self, name: str) -> object:
        return getattr(self._core, name)

    def hand_window(self, *_args: object) -> None:
        return None


@needs_core
def test_the_whole_window_in_c_plans_as_the_steps_and_the_python_loop(
    config: PlanConfig, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The hand DP's window in one C call, its per-group compiled steps, and the Python
    loop: the same planned notes, field for field, on 40 bench beats and with a beam
    that cuts (tests/plan/test_solver_equivalence.py checks each against the plain DP)."""
    workloads = [beat_workload(seed, 16) for seed in range(40)]
    whole = [plan_one_beat(w, config) for w in workloads]
    monkeypatch.setattr(fastdp, "core", _StepsOnly(fastdp.core))
    steps = [plan_one_beat(w, config) for w in workloads]
    monkeypatch.setattr(fastdp, "core", None)
    plain = [plan_one_beat(w, config) for w in workloads]
    assert [repr(p) for p in whole] == [repr(p) for p in steps] == [repr(p) for p in plain]


@needs_core
def test_the_window_in_c_with_a_cutting_beam_and_a_later_start(config: PlanConfig) -> None:
    """From a state with both hands recently struck, over many crowded groups, with a beam
    of 3: the whole-window call gives the Python loop's solution (assignments, costs,
    states, total)."""
    costs, timing = config.costs, config.timing
    groups = [
        drums.HandGroup(
            0.05 * i,
            (drums.Stroke("snare", 2, 0.0), drums.Stroke("hihat", 3, 0.004))
            if i % 3
            else (drums.Stroke("tom_high", 4, 0.0),),
        )
        for i in range(1, 30)
    ]
    m = costs.index("ride", drums.RIGHT)
    state: drums.HandState = (m, 0.02, 0.02, 0.01, "ride", "snare")
    compiled = drums.solve(costs, timing, state, groups, beam=3)
    core = fastdp.core
    try:
        fastdp.core = None
        plain = drums.solve(costs, timing, state, groups, beam=3)
    finally:
        fastdp.core = core
    assert compiled == plain


@needs_core
def test_input_the_window_does_not_take_is_left_to_python(
    config: PlanConfig, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Integer times (the C takes floats only) are refused by the whole-window call, which
    says so with None, and the solver's Python loop gives the result it gives with no
    build."""
    costs, timing = config.costs, config.timing
    groups = [drums.HandGroup(i, (drums.Stroke("snare", 2, 0.0),)) for i in range(3)]
    comps = [drums._compiled(costs, timing, g.strokes) for g in groups]
    table = drums._table_native(costs)
    args = (
        (None, None, None, None, 0, 0),
        [g.time for g in groups],
        [c.native for c in comps],
        [c.back for c in comps],
        table,
        len(costs.table[0]),
        costs.none_row,
        timing.max_gap,
        timing.rest_s,
        -1,
        drums._PIECES,
    )
    assert fastdp.core is not None
    assert fastdp.core.hand_window(*args) is None
    compiled = drums.solve(costs, timing, drums.START, groups)
    monkeypatch.setattr(fastdp, "core", None)
    assert compiled == drums.solve(costs, timing, drums.START, groups)


@needs_core
def test_crossed_arms_cost_the_same_in_c_and_in_python(config: PlanConfig) -> None:
    """Crossings at short times (timing.toml [hand_cross]): ride, hi-hat, snare and toms
    at 300 bpm with the hands crossing and uncrossing, from a state with the left hand
    just on the ride; the whole-window call, the per-group steps and the Python loop give
    the same solution, with and without a cutting beam, and it pays crossings."""
    costs, timing = config.costs, config.timing
    pieces = [
        ("ride",), ("snare", "hihat"), ("ride",), ("tom_floor", "hihat"), ("ride",),
        ("snare",), ("hihat", "ride"), ("tom_low",), ("crash2", "snare"), ("ride",),
    ]  # fmt: skip
    groups = [
        drums.HandGroup(
            0.1 + 0.066 * i,
            tuple(drums.Stroke(p, 2 + j, 0.003 * j) for j, p in enumerate(ps)),
        )
        for i, ps in enumerate(pieces * 2)
    ]
    m = costs.index("ride", drums.LEFT)
    state: drums.HandState = (m, 0.05, 0.02, 0.05, "hihat", "ride")
    for beam in (None, 3):
        whole = drums.solve(costs, timing, state, groups, beam=beam)
        core = fastdp.core
        try:
            fastdp.core = _StepsOnly(core)
            steps = drums.solve(costs, timing, state, groups, beam=beam)
            fastdp.core = None
            plain = drums.solve(costs, timing, state, groups, beam=beam)
        finally:
            fastdp.core = core
        assert whole == steps == plain
    # the crossing is in the totals: without it the same input costs less
    free = dataclasses.replace(timing, cross_penalty=0.0)
    assert drums.solve(costs, free, state, groups).total < whole.total
