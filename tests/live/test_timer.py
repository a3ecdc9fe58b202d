from __future__ import annotations

import asyncio
import math
import time

from virja.events import NoteOn
from virja.live.sinks import Fanout
from virja.live.timer import MAX_SLEEP_S, DeadlineTimer, wake_in
from virja.plan.planner import OnlinePlanner


def test_wake_in_is_the_earliest_deadline_never_negative_and_bounded() -> None:
    assert wake_in([5.0, 2.0, math.inf], 1.0) == 1.0
    assert wake_in([0.5], 1.0) == 0.0
    assert wake_in([math.inf], 1.0) == MAX_SLEEP_S
    assert wake_in([], 1.0) == MAX_SLEEP_S


def test_a_poke_wakes_the_timer_even_one_that_came_before_the_sleep() -> None:
    async def main() -> tuple[float, float]:
        timer = DeadlineTimer()
        timer.arm()
        asyncio.get_running_loop().call_later(0.05, timer.poke)
        t0 = time.monotonic()
        await timer.sleep(10.0)
        woke = time.monotonic() - t0
        timer.arm()
        timer.poke()  # between the work and the sleep: not lost
        t0 = time.monotonic()
        await timer.sleep(10.0)
        return woke, time.monotonic() - t0

    woke, early = asyncio.run(main())
    assert woke < 5.0 and early < 5.0


def test_the_planners_next_deadline_is_the_next_motion_start() -> None:
    planner = OnlinePlanner()
    assert planner.next_deadline() == math.inf
    planner.add_note("drums", NoteOn(time_s=2.0, channel=9, note=38, velocity=90), now_s=0.0)
    planner.add_note("bass", NoteOn(time_s=3.0, channel=1, note=40, velocity=90), now_s=0.0)
    first = planner.next_deadline()
    assert 1.0 < first < 2.0  # the snare stroke starts ahead of its impact
    assert planner.poll(first - 1e-6) == []
    started = planner.poll(first)
    assert [p.time for p in started] == [2.0]
    assert 2.0 < planner.next_deadline() < 3.0
    planner.poll(10.0)
    assert planner.next_deadline() == math.inf


class Sink:
    def __init__(self) -> None:
        self.got: list[object] = []

    def add_planned(self, p: object) -> None:
        self.got.append(p)

    def add_beat(self, beat: object) -> None:
        self.got.append(beat)


def test_fanout_gives_every_sink_everything_in_order() -> None:
    a, b = Sink(), Sink()
    fan = Fanout([a])
    fan.add(b)
    fan.add_planned("p")  # type: ignore[arg-type]
    fan.add_beat("b")  # type: ignore[arg-type]
    fan.note_off("bass", "off")  # type: ignore[arg-type]  # sinks without note_off are skipped
    assert a.got == b.got == ["p", "b"]
