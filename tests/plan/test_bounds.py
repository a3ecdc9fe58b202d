"""The planner's bounds: dense notes dropped by reason, waiting notes capped, a solve
windowed and its layers cut to a beam; plans of ordinary music unchanged."""

from __future__ import annotations

import random

import pytest

from virja.events import NoteOn
from virja.plan import drums
from virja.plan.bounds import DensityGate, PlanBounds, keep_best
from virja.plan.config import default_config
from virja.plan.planner import OnlinePlanner


def test_density_gate_refuses_the_note_past_the_cap_and_forgets_old_times() -> None:
    gate = DensityGate(PlanBounds(span_s=0.1, max_notes=3))
    assert [gate.admit(t) for t in (1.0, 1.01, 1.02, 1.03)] == [True, True, True, False]
    assert gate.admit(1.3)  # outside the span of the others
    gate.forget_before(1.25)
    assert len(gate) == 1


def test_keep_best_keeps_the_cheapest_in_their_order_ties_by_index() -> None:
    assert keep_best([3.0, 1.0, 2.0], 3) is None
    assert keep_best([3.0, 1.0, 2.0, 1.0], 2) == [1, 3]
    assert keep_best([1.0, 1.0, 1.0], 2) == [0, 1]


def test_bounds_reject_nonsense() -> None:
    with pytest.raises(ValueError):
        PlanBounds(span_s=0)
    with pytest.raises(ValueError):
        PlanBounds(beam=0)


def _dense_drums(n: int, gap_s: float = 0.001) -> list[NoteOn]:
    return [NoteOn(10.0 + i * gap_s, 9, (38, 42, 45)[i % 3], 100) for i in range(n)]


def test_dense_drum_flood_is_dropped_too_dense_and_planned_in_bounded_work() -> None:
    planner = OnlinePlanner()
    for note in _dense_drums(400):  # D1: 400 notes 1 ms apart, all known 5 s ahead
        planner.add_note("drums", note, now_s=5.0)
    out = planner.flush()
    counts = dict(planner.report.counts)
    assert counts["dropped_too_dense"] >= 400 - 2 * planner.bounds.max_notes * 2
    assert len(out) + counts["dropped"] == 400
    assert {p.limb for p in out} <= {"left_hand", "right_hand", "left_foot"}  # hi-hat chicks


def test_pending_notes_are_capped_planner_full() -> None:
    planner = OnlinePlanner(bounds=PlanBounds(max_pending=10))
    for i in range(30):  # bass notes 0.2 s apart: not dense, only many
        planner.add_note("bass", NoteOn(10.0 + 0.2 * i, 0, 40, 90), now_s=0.0)
    assert planner.pending_count == 10
    assert dict(planner.report.counts)["dropped_planner_full"] == 20


def test_beam_changes_nothing_on_layers_within_it_and_cuts_wider_ones() -> None:
    cfg = default_config()
    rng = random.Random(5)
    groups = []
    t = 0.0
    for _ in range(60):
        t += rng.choice((0.002, 0.01, 0.03, 0.12))
        pieces = rng.sample(["snare", "hihat", "tom_high", "ride"], rng.choice((1, 2)))
        groups.append(drums.HandGroup(t, tuple(drums.Stroke(p, 5) for p in pieces)))
    exact = drums.solve(cfg.costs, cfg.timing, drums.START, groups)
    assert drums.solve(cfg.costs, cfg.timing, drums.START, groups, beam=10_000) == exact
    cut = drums.solve(cfg.costs, cfg.timing, drums.START, groups, beam=2)
    assert len(cut.assignments) == len(groups)
    assert cut.total >= exact.total  # a valid plan, never better than the optimum


def test_each_solve_covers_at_most_the_window(monkeypatch: pytest.MonkeyPatch) -> None:
    sizes: list[int] = []
    real = drums.solve

    def spy(*args: object, **kw: object) -> drums.HandSolution:
        sizes.append(len(args[3]))  # type: ignore[arg-type]
        return real(*args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(drums, "solve", spy)
    planner = OnlinePlanner(bounds=PlanBounds(window_groups=4))
    notes = _dense_drums(40, gap_s=0.09)
    for n in notes:
        planner.add_note("drums", n, now_s=0.0)
    out = planner.flush()
    assert len(out) + dict(planner.report.counts).get("dropped", 0) == 40
    assert sizes and max(sizes) <= 4


def test_ordinary_music_is_not_touched_by_the_bounds() -> None:
    """The demo's plan with the bounds equals its plan with bounds too wide to act."""
    from pathlib import Path

    from virja.midifile import read_midi
    from virja.plan import plan_notes_with_report
    from virja.routing import Router, route_all

    demo = Path(__file__).resolve().parents[2] / "virja" / "demo" / "blues.mid"
    session = read_midi(demo)
    notes = [
        (w, e)
        for w, e in route_all(session.events, Router.for_session(session))
        if isinstance(e, NoteOn)
    ]
    bounded = plan_notes_with_report(notes, session.tempo_map)
    wide = PlanBounds(max_notes=10**6, max_pending=10**6, window_groups=10**6, beam=10**6)
    assert bounded == plan_notes_with_report(notes, session.tempo_map, bounds=wide)
