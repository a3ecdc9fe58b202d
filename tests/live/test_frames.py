"""The viewer's frame loop without a window: a fake clock, animator and sink."""

from __future__ import annotations

from typing import Any

from virja.live.frames import FrameLoop, Inbox
from virja.live.pacing import FramePacer


class Clock:
    def __init__(self) -> None:
        self.t = 100.0
        self.draw_cost = 0.004

    def now(self) -> float:
        return self.t

    def sleep(self, s: float) -> None:
        self.t += s


class Animator:
    def __init__(self) -> None:
        self.planned: list[Any] = []
        self.beats: list[Any] = []
        self.posed: list[tuple[float, int]] = []
        self.forgot: list[float] = []

    def add_planned(self, p: Any) -> None:
        self.planned.append(p)

    def add_beat(self, beat: Any) -> None:
        self.beats.append(beat)

    def pose(self, time_s: float) -> Any:
        self.posed.append((time_s, len(self.planned)))
        return ("pose", time_s)

    def forget_before(self, time_s: float) -> None:
        self.forgot.append(time_s)


class Sink:
    def __init__(self, clock: Clock, close_after: int = 10**9) -> None:
        self.clock = clock
        self.shown: list[Any] = []
        self.close_after = close_after

    @property
    def closed(self) -> bool:
        return len(self.shown) >= self.close_after

    def show(self, pose: Any) -> None:
        self.clock.t += self.clock.draw_cost
        self.shown.append(pose)


def _loop(items: list[tuple[Any, ...]], clock: Clock, sink: Sink, **kw: Any) -> FrameLoop:
    def get() -> tuple[Any, ...] | None:
        return items.pop(0) if items else None

    return FrameLoop(
        kw.pop("animator", Animator()),
        [sink],
        Inbox(get),
        FramePacer(0.02),
        monotonic=clock.now,
        sleep=clock.sleep,
        **kw,
    )


def test_each_frame_shows_the_pose_of_its_slot_in_session_time() -> None:
    clock = Clock()
    sink = Sink(clock, close_after=5)
    from virja.events import Beat

    b1 = Beat(1100.0, 0, 1, 4, 2, 500_000)
    items: list[tuple[Any, ...]] = [("clock", 1000.0), ("planned", "n1"), ("beat", b1)]
    animator = Animator()
    loop = _loop(items, clock, sink, animator=animator)
    loop.run()
    assert len(sink.shown) == 5
    times = [t for t, _ in animator.posed]
    # session time = anchor + the monotonic moment the frame is shown: a slot apart
    assert all(abs((b - a) - 0.02) < 1e-9 for a, b in zip(times, times[1:], strict=False))
    assert 1100.0 <= times[0] < 1100.1
    assert animator.planned == ["n1"] and animator.beats == [b1]
    assert animator.posed[0][1] == 1  # what arrived was drained before the frame was posed
    assert loop.received == 1


def test_a_stop_item_or_a_dead_parent_ends_the_loop() -> None:
    clock = Clock()
    sink = Sink(clock)
    loop = _loop([("stop",)], clock, sink)
    loop.run()
    assert sink.shown == []
    alive = iter([True, True, False])
    loop = _loop([], clock, Sink(clock), alive=lambda: next(alive))
    loop.run()
    assert len(loop.sinks[0].shown) == 2  # type: ignore[attr-defined]


def test_a_slow_frame_skips_slots_and_does_not_fall_behind() -> None:
    clock = Clock()
    clock.draw_cost = 0.05  # each frame takes 2.5 slots
    sink = Sink(clock, close_after=20)
    animator = Animator()
    loop = _loop([("clock", 0.0)], clock, sink, animator=animator)
    loop.run()
    assert loop.pacer.skipped > 0
    # the pose drawn is never of a moment already past when the frame is shown
    for (t, _), shown_at in zip(animator.posed[3:], animator.posed[4:], strict=False):
        assert shown_at[0] - t <= 0.05 + 0.02 + 1e-9
    assert animator.posed[-1][0] >= clock.t - 0.05 - 1e-9


class HudSink(Sink):
    def __init__(self, clock: Clock, close_after: int = 10**9) -> None:
        super().__init__(clock, close_after)
        self.texts: list[str] = []

    def set_hud(self, text: str) -> None:
        self.texts.append(text)


def test_the_heads_up_display_reads_the_moment_each_frame_shows() -> None:
    """Beats and chords sent ahead reach the window's heads-up display at their time."""
    from virja.events import Beat, Chord

    clock = Clock()
    sink = HudSink(clock, close_after=30)
    items: list[tuple[Any, ...]] = [
        ("beat", Beat(100.1, 4, 1, 4, 2, 500_000)),
        ("chord", Chord(100.1, 10, None, "7")),
        ("beat", Beat(100.3, 4, 2, 4, 0, 500_000)),
    ]
    loop = _loop(items, clock, sink)
    loop.run()
    assert sink.texts[0] == ""  # before the first beat: nothing known yet
    assert "120 bpm   bar 5.1   Bb7" in sink.texts
    assert sink.texts[-1] == "120 bpm   bar 5.2   Bb7"
    assert len(sink.texts) == len(sink.shown)
