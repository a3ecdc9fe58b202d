"""The viewer's frame loop: take what the planner committed, draw the pose of the
moment each frame will be shown, paced to the display, missed frames skipped.

Runs in the window's process (:mod:`virja.live.viewer`) and owns its animator:
the planning side only sends committed items, so nothing is shared and no lock
is held while drawing.  Frame consumers (:class:`FrameSink`: the window, or any
later one) get every drawn pose.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from virja.hud import HudTimeline
from virja.live.pacing import FramePacer
from virja.motion.pose import BandPose

KEEP_MOTION_S = 20.0  # motions older than this are forgotten (memory stays flat)
FORGET_EVERY = 60  # frames between forgets
AHEAD_FRAMES = 6  # the band is posed for this many slots at once (thrown away on news)


def _changes_pose(animator: Any, item: tuple[Any, ...]) -> bool:
    """Whether an inbox item may change the animator's poses (chords, the clock, a
    note's arrival before its plan and a drum's note-off do not:
    ``BandAnimator.NOTE_OFF_PERFORMERS``)."""
    if item[0] in ("chord", "clock", "stop", "known"):
        return False
    if item[0] == "off":
        return item[1] in getattr(animator, "NOTE_OFF_PERFORMERS", (item[1],))
    return True


class FrameSink(Protocol):
    """A consumer of drawn poses: ``show`` one frame; ``closed`` when it wants to stop."""

    @property
    def closed(self) -> bool: ...

    def show(self, pose: BandPose) -> None: ...


class Animator(Protocol):
    def add_planned(self, p: Any) -> None: ...

    def add_beat(self, beat: Any) -> None: ...

    def pose(self, time_s: float) -> BandPose: ...

    def forget_before(self, time_s: float) -> None: ...

    def use_bass_strings(self, strings: tuple[str, ...]) -> None: ...

    def set_articulations(self, articulations: dict[int, str | None]) -> None: ...


@dataclass
class Inbox:
    """Items from the planning side: ``get()`` returns the next or None when none."""

    get: Callable[[], tuple[Any, ...] | None]


class FrameLoop:
    """Draws paced frames to ``sinks`` until a sink closes or a ``("stop",)`` arrives.

    Time: ``monotonic()`` paces the frames; session time is ``anchor + monotonic()``
    where ``anchor`` comes from the planning side (``("clock", anchor)``), so both
    processes agree on the session clock (CLOCK_MONOTONIC is system-wide).
    """

    def __init__(
        self,
        animator: Animator,
        sinks: Sequence[FrameSink],
        inbox: Inbox,
        pacer: FramePacer,
        *,
        anchor_s: float = 0.0,
        monotonic: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
        alive: Callable[[], bool] = lambda: True,
    ) -> None:
        self.animator = animator
        self.sinks = list(sinks)
        self.inbox = inbox
        self.pacer = pacer
        self.anchor_s = anchor_s
        self.monotonic = monotonic
        self.sleep = sleep
        self.alive = alive
        self.stopped = False
        self.received = 0
        self.hud = HudTimeline()  # beats and chords: the heads-up display's line
        # a BandAnimator's poses and scenes, a few slots at a time (render.chunks)
        self.chunks: Any = None
        if hasattr(animator, "pose_batch"):
            from virja.render.chunks import FrameChunks

            self.chunks = FrameChunks(animator)  # type: ignore[arg-type]
        self._news = False  # the animator was told something since the last frame

    def drain(self) -> None:
        """Everything the planning side sent so far, into the animator (the frames
        posed ahead are thrown away when it is told anything)."""
        while (item := self.inbox.get()) is not None:
            kind = item[0]
            if self.chunks is not None and _changes_pose(self.animator, item):
                self.chunks.invalidate()
                self._news = True
            if kind == "planned":
                self.animator.add_planned(item[1])
                self.received += 1
            elif kind == "known":  # a note's arrival: a free hand may move toward it
                known = getattr(self.animator, "note_known", None)
                if known is not None:
                    known(item[1], item[2], item[3])
            elif kind == "provisional":  # the plan's current hands for notes not started
                provisional = getattr(self.animator, "note_provisional", None)
                if provisional is not None:
                    provisional(item[1])
            elif kind == "beat":
                self.animator.add_beat(item[1])
                self.hud.add(item[1])
            elif kind == "chord":
                self.hud.add(item[1])
            elif kind == "off":
                off = getattr(self.animator, "note_off", None)
                if off is not None:
                    off(item[1], item[2])
            elif kind == "strings":  # the tuning's strings: played and drawn (5/6-string)
                self.animator.use_bass_strings(tuple(item[1]))
            elif kind == "articulations":  # the kit map's hi-hat articulations
                self.animator.set_articulations(dict(item[1]))
            elif kind == "clock":
                self.anchor_s = float(item[1])
            elif kind == "stop":
                self.stopped = True

    @property
    def done(self) -> bool:
        return self.stopped or any(s.closed for s in self.sinks) or not self.alive()

    def step(self) -> bool:
        """Wait for the next slot, draw it; False when the loop should end."""
        slot = self.pacer.next_slot(self.monotonic())
        wait = slot.draw_at - self.monotonic()
        if wait > 0:
            self.sleep(wait)
        self.drain()
        if self.done:
            return False
        started = self.monotonic()
        pose, scene = self._pose(slot.show_at)
        hud_text = self.hud.at(self.anchor_s + slot.show_at).text()
        for s in self.sinks:
            set_hud = getattr(s, "set_hud", None)
            if set_hud is not None:
                set_hud(hud_text)
            show_frame = getattr(s, "show_frame", None)
            if scene is not None and show_frame is not None:
                show_frame(pose, scene)  # the window: the instances built with the chunk
            else:
                s.show(pose)
        mark = getattr(self.animator, "mark_drawn", None)
        if mark is not None:  # shown: a note learnt later changes nothing up to here
            mark(pose.time_s)
        self.pacer.drawn(started, self.monotonic())
        if self.pacer.shown % FORGET_EVERY == 0:
            self.animator.forget_before(self.anchor_s + started - KEEP_MOTION_S)
            if self.chunks is not None:
                self.chunks.invalidate()
        return True

    def _pose(self, show_at: float) -> tuple[BandPose, Any]:
        """The pose (and, for a BandAnimator, its instances) of the slot shown at
        ``show_at``: from the frames posed ahead when it is one of them, else posed
        with the next slots as the pacer will ask for them (without vsync the slots
        are a period apart; with it, the swap decides: one frame at a time).  A frame
        right after news is posed alone: it shows the news (a key just played) no
        later than one posed frame by frame would; the chunk starts with the next."""
        t = self.anchor_s + show_at
        news, self._news = self._news, False
        if self.chunks is None:
            return self.animator.pose(t), None
        if not self.chunks.has(t):
            times = [t]
            shows = show_at
            for _ in range(0 if self.pacer.vsync or news else AHEAD_FRAMES - 1):
                shows += self.pacer.period_s  # as FramePacer adds it, slot after slot
                times.append(self.anchor_s + shows)
            self.chunks.prepare(times)
        frame: tuple[BandPose, Any] = self.chunks.frame(t)
        return frame

    def run(self) -> None:
        while self.step():
            pass
