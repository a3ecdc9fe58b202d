"""What every chain of the online planner shares (virja.plan.chain): grouping, the
caps, out-of-order placement, fixing what has started, the windowed plan."""

from __future__ import annotations

import pytest

from tests.plan.chains import bass, context
from virja.plan.bounds import PlanBounds
from virja.plan.chain import (
    GROUP_EPS_S,
    HISTORY,
    Chain,
    ChainContext,
    Held,
    Ledger,
    WindowedPlan,
    as_limb,
    group_notes,
)


class Recording(Chain[Held]):
    """A chain that plays every note with the right hand and records what it was asked."""

    def __init__(self, ctx: ChainContext) -> None:
        super().__init__(ctx)
        self.fixed_groups: list[list[float]] = []
        self.out_of_order: list[float] = []
        self.forgotten = 0

    def forget_plan(self) -> None:
        self.forgotten += 1

    def fix_groups(self, groups: list[list[Held]], n_groups: int) -> None:
        for g in groups[:n_groups]:
            self.fixed_groups.append([r.note.time_s for r in g])
            for r in g:
                self.emit(
                    r, limb="right_hand", piece=None, string="E", fret=0, motion="m", cost=0.0
                )

    def place_out_of_order(self, rec: Held) -> None:
        self.out_of_order.append(rec.note.time_s)


def held(seq: int, t: float, known_s: float = 0.0) -> Held:
    return Held(seq, "bass", bass(t, 40), known_s, "pluck", 40)


def test_group_notes_cuts_at_the_window_from_each_group_first_note() -> None:
    recs = [held(1, 1.020), held(2, 1.0), held(3, 1.0005), held(4, 1.011), held(5, 1.0)]
    groups = group_notes(recs, window=0.010)
    assert [[r.seq for r in g] for g in groups] == [[2, 5, 3], [4, 1]]
    assert [[r.seq for r in g] for g in group_notes(recs)] == [[2, 5, 3], [4], [1]]


def test_take_aligns_the_note_and_keeps_the_earliest_start() -> None:
    chain = Recording(context())
    chain.take(held(1, 2.0, known_s=0.0))
    chain.take(held(2, 1.0, known_s=0.0))
    assert [r.seq for r in chain.pending] == [1, 2]
    assert chain.pending[1].impact == 1.0 and not chain.pending[1].late
    assert chain.min_start == chain.pending[1].start < 1.0
    assert chain.forgotten == 2  # each note invalidates the plan kept


def test_take_drops_past_the_pending_cap_and_the_density_cap() -> None:
    chain = Recording(context(bounds=PlanBounds(max_pending=2, max_notes=3, span_s=0.1)))
    for i in range(4):
        chain.take(held(i, 1.0 + 0.5 * i))
    assert chain.pending_count == 2
    assert dict(chain.ctx.ledger.counts)["dropped_planner_full"] == 2
    dense = Recording(context(bounds=PlanBounds(max_notes=3, span_s=0.1)))
    for i in range(5):
        dense.take(held(i, 1.0 + 0.01 * i))
    assert dense.pending_count == 3
    assert [d.reason for d in dense.ctx.ledger.dropped] == ["too_dense", "too_dense"]


def test_commit_fixes_only_started_groups_and_everything_before_them() -> None:
    chain = Recording(context())
    for i, t in enumerate((1.0, 1.5, 2.0)):
        chain.take(held(i, t))
    chain.commit(0.0)  # nothing has started
    assert chain.fixed_groups == [] and chain.pending_count == 3
    chain.commit(chain.pending[1].start)  # the second has started: the first two fixed
    assert chain.fixed_groups == [[1.0], [1.5]]
    assert chain.last_fixed_t == 1.5
    assert chain.min_start == chain.pending[0].start and chain.pending_count == 1
    assert [p.time for p in chain.ctx.ledger.outbox] == [1.0, 1.5]
    chain.fix_all()
    assert chain.fixed_groups[-1] == [2.0] and chain.min_start == float("inf")


def test_a_note_not_after_the_last_fixed_group_is_placed_out_of_order() -> None:
    chain = Recording(context())
    chain.take(held(1, 1.0))
    chain.fix_all()
    chain.take(held(2, 1.0 + GROUP_EPS_S / 2))  # with the fixed group
    chain.take(held(3, 0.5))  # before it
    chain.take(held(4, 1.2))  # after it: waits
    assert chain.out_of_order == [1.0 + GROUP_EPS_S / 2, 0.5]
    assert [r.seq for r in chain.pending] == [4]


def test_fixed_history_is_bounded() -> None:
    chain = Recording(context())
    for i in range(HISTORY + 10):
        chain.take(held(i, 1.0 + 0.2 * i))
    chain.fix_all()
    assert len(chain.fixed) == HISTORY
    assert chain.fixed[-1][0] == pytest.approx(1.0 + 0.2 * (HISTORY + 9))


def test_share_takes_the_twin_motion_and_times_at_no_cost() -> None:
    chain = Recording(context())
    chain.take(held(1, 1.0))
    chain.fix_all()
    twin = chain.fixed[-1][1]
    late = held(2, 1.0, known_s=1.2)
    chain.share(late, twin)
    p = chain.ctx.ledger.outbox[-1]
    assert (p.start, p.impact, p.late, p.motion, p.cost) == (twin.start, twin.impact, False, "m", 0)
    assert chain.fixed_at(1.0) == [twin, p]


def test_windowed_plan_solves_a_window_at_a_time_and_keeps_it_until_forgotten() -> None:
    plan: WindowedPlan[int] = WindowedPlan(window_groups=3)
    groups = [[held(i, float(i))] for i in range(7)]
    solved: list[list[int]] = []

    def solve(win: list[list[Held]], gi: int) -> list[int]:
        assert win[0] is groups[gi]
        solved.append([g[0].seq for g in win])
        return [g[0].seq * 10 for g in win]

    assert [plan.step(groups, gi, solve) for gi in range(4)] == [0, 10, 20, 30]
    assert solved == [[0, 1, 2], [3, 4, 5]]
    plan.forget()
    assert plan.step(groups, 4, solve) == 40
    assert solved[-1] == [4, 5, 6]


def test_ledger_report_counts_every_case() -> None:
    ledger = Ledger()
    ledger.drop(held(1, 1.0), "too_fast")
    ledger.unmapped("drums", bass(1.0, 20))
    ledger.move("bass", bass(2.0, 90), 66)
    ledger.unplayed["Conga"] += 2
    summary = ledger.report().summary()
    assert summary == {
        "dropped": 2,
        "moved": 1,
        "dropped_too_fast": 1,
        "dropped_unmapped": 1,
    }
    assert ledger.report().unplayed == (("Conga", 2),)


def test_as_limb_refuses_a_name_that_is_no_limb() -> None:
    assert as_limb("left_foot") == "left_foot"
    with pytest.raises(ValueError, match="not a limb"):
        as_limb("bass")
