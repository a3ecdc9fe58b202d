"""The provisional hands travel from the planner to every animator of the drummer:
the performance tells them when they change (not where nothing is drawn meanwhile),
the fan-out forwards them, the window's frame loop takes them from its queue."""

from __future__ import annotations

from typing import Any

from tests.live.test_frames_ahead import Window, _loop
from tests.motion.helpers import drum
from virja.events import Beat, NoteOn
from virja.live.sinks import Fanout
from virja.plan.planner import OnlinePlanner
from virja.plan.types import PlannedNote
from virja.routing import Router
from virja.session import Performance, Reveal, run_as_live, run_schedule


class Recorder:
    """A plan sink that keeps what it is told."""

    def __init__(self) -> None:
        self.provisional: list[list[PlannedNote]] = []
        self.planned: list[PlannedNote] = []

    def add_planned(self, p: PlannedNote) -> None:
        self.planned.append(p)

    def add_beat(self, beat: Beat) -> None:
        pass

    def note_provisional(self, notes: list[PlannedNote]) -> None:
        self.provisional.append(list(notes))


def _schedule() -> list[Reveal]:
    """Snare, hi-hat and crash notes, each known half a second ahead."""
    notes = [NoteOn(1.0 + 0.25 * k, 9, (38, 42, 49)[k % 3], 90) for k in range(8)]
    return [Reveal(n.time_s - 0.5, n) for n in notes]


def _performance(sink: Any) -> Performance:
    return Performance(router=Router(), planner=OnlinePlanner(), animator=sink)


def test_the_performance_tells_the_provisional_hands_as_they_change() -> None:
    rec = Recorder()
    planned = run_as_live(_performance(rec), _schedule(), 30.0, 0.0)
    assert rec.provisional, "never told"
    told = rec.provisional
    assert all(told[i] != told[i + 1] for i in range(len(told) - 1))  # changes only
    key = {(p.note, p.time): p for p in planned}
    for told in rec.provisional:
        for p in told:
            assert p.performer == "drums" and p.limb in ("left_hand", "right_hand")
            assert (p.note, p.time) in key
    # each hand note was shown before its plan was fixed, mostly with the hand fixed
    last = {(p.note, p.time): p.limb for told in rec.provisional for p in told}
    assert set(last) == set(key)
    assert sum(last[k] == key[k].limb for k in key) >= 6


def test_nothing_is_told_where_nothing_is_drawn_meanwhile() -> None:
    rec = Recorder()
    perf = _performance(rec)
    planned = run_schedule(perf, _schedule())
    assert rec.provisional == [] and len(planned) == 8
    assert perf.tell_provisional  # on again for a later live use


def test_the_fanout_forwards_to_the_sinks_that_take_them() -> None:
    rec = Recorder()

    class Plain:
        def add_planned(self, p: PlannedNote) -> None: ...

        def add_beat(self, beat: Beat) -> None: ...

    fan = Fanout([Plain(), rec])
    notes = [drum("snare_left_hand", 0.9, 1.0)]
    fan.note_provisional(notes)
    assert rec.provisional == [notes]


def test_the_window_takes_them_from_its_queue() -> None:
    note = drum("crash_right_hand", 1.3, 1.5)
    items: list[tuple[Any, ...]] = [("clock", 0.0), ("provisional", [note])]
    window = Window()
    loop = _loop(items, window, [1.0])
    assert loop.step()
    assert loop.animator.provisional_counts["shown"] == 1  # type: ignore[attr-defined]
