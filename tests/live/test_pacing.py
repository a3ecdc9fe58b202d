from __future__ import annotations

import pytest

from virja.live.pacing import MAX_DRAW_ESTIMATE_S, FramePacer


def test_slots_are_a_period_apart_and_drawing_starts_early_by_its_cost() -> None:
    p = FramePacer(0.1)
    s0 = p.next_slot(0.0)
    assert (s0.draw_at, s0.show_at) == (0.0, 0.0)
    p.drawn(0.0, 0.02)
    s1 = p.next_slot(0.02)
    assert s1.show_at == pytest.approx(0.1)
    assert s1.draw_at == pytest.approx(0.1 - 0.02)  # started so it is ready at its slot
    p.drawn(s1.draw_at, s1.show_at)
    s2 = p.next_slot(0.1)
    assert s2.show_at == pytest.approx(0.2)
    assert p.skipped == 0


def test_a_missed_frame_is_skipped_never_queued() -> None:
    p = FramePacer(0.1)
    p.next_slot(0.0)
    p.drawn(0.0, 0.35)  # a stall: three slots went by
    s = p.next_slot(0.35)
    # the next slot that can still be met, drawn at once: no backlog of old frames
    assert s.show_at >= 0.35 + p.draw_s - 1e-9
    assert s.show_at == pytest.approx(0.4 + 0.1 * round((s.show_at - 0.4) / 0.1))
    assert p.skipped >= 3
    p.drawn(s.draw_at, s.draw_at + 0.01)
    assert p.next_slot(s.draw_at + 0.01).show_at == pytest.approx(s.show_at + 0.1)


def test_the_cost_estimate_is_bounded_so_one_stall_does_not_lag_every_frame() -> None:
    p = FramePacer(1 / 60)
    p.next_slot(0.0)
    p.drawn(0.0, 5.0)
    assert p.draw_s == MAX_DRAW_ESTIMATE_S


def test_with_vsync_the_swap_paces_and_the_frame_shows_when_drawn() -> None:
    p = FramePacer(1 / 60, vsync=True)
    p.next_slot(1.0)
    p.drawn(1.0, 1.01)
    s = p.next_slot(1.02)
    assert s.draw_at == 1.02
    assert s.show_at == pytest.approx(1.03)


@pytest.mark.parametrize("period", [0.0, -1.0, float("inf"), float("nan")])
def test_a_bad_period_is_refused(period: float) -> None:
    with pytest.raises(ValueError, match="period"):
        FramePacer(period)
