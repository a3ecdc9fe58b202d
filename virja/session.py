"""One performance: router -> planner -> animator, driven by a timer.

``serve``, ``replay``, ``render`` and ``jam`` all build a :class:`Performance`
and drive it the same way; only the timer differs (live: the session clock;
offline: exact 1/fps steps):

    perf.feed(event, now_s=t)      # as events arrive (or are revealed)
    perf.advance(now_s=t)          # commit motions that have started
    perf.pose(t)                   # what to draw at t

The plan log (``--plan-log``) gets one JSON object per planned note, as
``virja plan --json`` prints it plus ``session_time`` (``PlannedNote.to_log_json``),
written and flushed as notes are committed.  Its times count from ``origin_s``, the
session time of the input's start (docs/architecture.md, "One time base").
"""

from __future__ import annotations

import json
import logging
import math
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import IO, TYPE_CHECKING, Protocol

from virja.events import Beat, Chord, Event, NoteOff, NoteOn
from virja.faults import close_at_last_line
from virja.hud import HudTimeline
from virja.routing import Router
from virja.tempo import Tempo
from virja.vocab import Performer

if TYPE_CHECKING:
    from virja.motion.pose import BandPose
    from virja.plan.planner import OnlinePlanner
    from virja.plan.types import PlannedNote

log = logging.getLogger(__name__)


class PlanSink(Protocol):
    """Where committed motions go: a :class:`~virja.motion.band.BandAnimator`, the
    window's process (:class:`virja.live.viewer.Viewer`) or several
    (:class:`virja.live.sinks.Fanout`).  A sink may also have ``note_off(performer,
    event)`` and ``pose(time_s)``."""

    def add_planned(self, p: PlannedNote) -> None: ...

    def add_beat(self, beat: Beat) -> None: ...


# A sink may also take ``note_provisional(notes)``: the drummer's hand notes not yet
# started with the hand the plan gives them now, the whole current set each time
# (``OnlinePlanner.provisional``); a note left out of it, or fixed, is no longer so.


class Performance:
    """Routes events, plans motions, animates the band; counts what it did."""

    def __init__(
        self,
        *,
        router: Router,
        planner: OnlinePlanner,
        animator: PlanSink | None = None,
        plan_log: IO[str] | None = None,
        origin_s: float | None = 0.0,
    ) -> None:
        self.router = router
        self.planner = planner
        # the session time users call 0: a MIDI file's start (0), a recording's first
        # packet; None until :meth:`mark_origin` (serve: the first datagram received)
        self._origin_s: float | None = None
        self.origin_s = origin_s
        self.animator = animator  # told the kit map and the tuning (the property below)
        self.plan_log = plan_log
        self.counts: Counter[str] = Counter()
        self.planned: list[PlannedNote] = []
        self.keep_planned = True
        self.hud = HudTimeline()  # tempo, bar.beat and chord for the heads-up display
        self.taps: list[Callable[[Event], None]] = []  # see every event fed (the web viewer)
        self.planned_taps: list[Callable[[PlannedNote], None]] = []  # and every note committed
        self.plan_log_failed: str | None = None
        # the hands the plan gives the drummer's notes not yet started, told to a sink
        # that takes them (note_provisional) whenever they change; off where nothing is
        # drawn before the end (run_schedule: the whole input known)
        self.tell_provisional = True
        self._provisional: list[PlannedNote] = []
        # live: the hands drawn moving for notes not yet fixed, asked of a sink that
        # draws them (shown_moving) and pinned in the plan before each commit
        # (OnlinePlanner.pin_hands); off, a live plan is the whole input's
        self.pin_shown = True

    @property
    def animator(self) -> PlanSink | None:
        return self._animator

    @animator.setter
    def animator(self, animator: PlanSink | None) -> None:
        """Set at construction or later (serve and replay build their sinks after): the
        sink learns the kit map's articulations and the tuning's strings either way."""
        self._animator = animator
        setter = getattr(animator, "set_articulations", None)
        if setter is not None:  # the hi-hat opens and closes as the (user's) kit map says
            setter({n: d.articulation for n, d in self.planner.config.kit.notes.items()})
        strings = getattr(animator, "use_bass_strings", None)
        if strings is not None:  # the bassist plays (and shows) the strings of the tuning
            strings(tuple(name for name, _ in self.planner.config.bass.strings))

    @property
    def origin_s(self) -> float | None:
        return self._origin_s

    @origin_s.setter
    def origin_s(self, session_s: float | None) -> None:
        self._origin_s = session_s
        if session_s is not None and hasattr(self.planner, "origin_s"):
            self.planner.origin_s = session_s  # its messages count from there too

    def mark_origin(self, session_s: float) -> None:
        """The input starts at ``session_s`` unless its start is known already."""
        if self.origin_s is None:
            self.origin_s = session_s

    def feed(self, event: Event, *, now_s: float) -> Performer | None:
        """An event has become known at ``now_s``; returns the performer it went to."""
        for tap in self.taps:
            tap(event)
        if isinstance(event, Beat):
            self._beat(event)
            return None
        if isinstance(event, Chord):
            self.hud.add(event)
            add_chord = getattr(self.animator, "add_chord", None)
            if add_chord is not None:  # the live window's heads-up display
                add_chord(event)
            return None
        performer = self.router.route(event)
        if performer is not None:
            self.feed_routed(performer, event, now_s=now_s)
        elif isinstance(event, NoteOn):
            self.counts["notes_not_the_bands"] += 1
        return performer

    def feed_routed(self, performer: Performer, event: Event, *, now_s: float) -> None:
        """An event already routed (jam's keyboard split does its own routing)."""
        if isinstance(event, NoteOn):
            self._pin_shown(now_s)  # the planner commits what started before taking it in
            known = getattr(self.animator, "note_known", None)
            if known is not None and performer == "drums":  # a free hand may start toward it
                known(performer, event, now_s)
            self.planner.add_note(performer, event, now_s=now_s)
            self.counts[f"notes_{performer}"] += 1
            if performer == "drums":
                self._tell_provisional()
        elif isinstance(event, NoteOff):
            if self.animator is not None:
                note_off = getattr(self.animator, "note_off", None)
                if note_off is not None:
                    note_off(performer, event)
        elif isinstance(event, Beat):
            self._beat(event)

    def _beat(self, beat: Beat) -> None:
        self.hud.add(beat)
        self.planner.add_beat(beat)
        if self.animator is not None:
            self.animator.add_beat(beat)
        self.counts["beats"] += 1

    def advance(self, now_s: float) -> list[PlannedNote]:
        """Commit the motions that have started by ``now_s``; log and animate them."""
        self._pin_shown(now_s)
        notes = self._commit(self.planner.poll(now_s))
        if any(p.performer == "drums" for p in notes):
            self._tell_provisional()
        return notes

    def _pin_shown(self, now_s: float) -> None:
        """Live: the notes whose provisional hand a sink has drawn moving
        (``shown_moving``), pinned to that hand in the plan (``pin_hands``) before the
        planner fixes anything: the commit keeps a hand shown moving on its note unless
        it cannot play it.  Not where nothing is drawn meanwhile (``run_schedule``)."""
        if not self.tell_provisional:
            return
        look = getattr(self.animator, "shown_moving", None)
        pin = getattr(self.planner, "pin_hands", None)
        if look is None or pin is None:
            return
        pins = look()  # asked even when not pinned: the animator counts how they fare
        if self.pin_shown:
            pin(pins, now_s=now_s)

    def _tell_provisional(self) -> None:
        """The plan's current hands for the drum notes not yet started, to a sink that
        takes them (``note_provisional``), when they changed since last told."""
        if not self.tell_provisional:
            return
        tell = getattr(self.animator, "note_provisional", None)
        look = getattr(self.planner, "provisional", None)
        if tell is None or look is None:
            return
        notes: list[PlannedNote] = look()
        if notes != self._provisional:
            self._provisional = notes
            tell(notes)

    def finish(self) -> list[PlannedNote]:
        """Commit everything still pending (end of a file or a replay)."""
        return self._commit(self.planner.flush())

    def _commit(self, notes: list[PlannedNote]) -> list[PlannedNote]:
        if notes and self.origin_s is None:  # no datagram marked it: the first note's motion
            self.mark_origin(min(p.start for p in notes))
        for p in notes:
            for tap in self.planned_taps:
                tap(p)
            if self.animator is not None:
                self.animator.add_planned(p)
            if self.plan_log is not None:
                self._log(json.dumps(p.to_log_json(self.origin_s or 0.0)) + "\n")
            if self.keep_planned:
                self.planned.append(p)
            self.counts["planned"] += 1
            if p.late:
                self.counts["planned_late"] += 1
        if notes and self.plan_log is not None:
            self._log(None)
        return notes

    def _log(self, line: str | None) -> None:
        """Write ``line`` to the plan log (None: flush).  A write that fails (a full
        disk) stops the log, reported once in ``plan_log_failed``; the band goes on."""
        assert self.plan_log is not None
        try:
            if line is None:
                self.plan_log.flush()
            else:
                self.plan_log.write(line)
        except (OSError, ValueError) as exc:
            self.plan_log_failed = getattr(exc, "strerror", None) or str(exc)
            log.warning("plan log stopped: %s (planning goes on)", self.plan_log_failed)
            close_at_last_line(self.plan_log)
            self.plan_log = None

    def pose(self, time_s: float) -> BandPose:
        pose = getattr(self.animator, "pose", None)
        if pose is None:
            raise RuntimeError("this performance has no animator to pose")
        result: BandPose = pose(time_s)
        return result


@dataclass(frozen=True)
class Reveal:
    """An event and the session time at which it becomes known."""

    at_s: float
    event: Event


def reveal_schedule(events: Iterable[Event], tempo: Tempo, lookahead_beats: float) -> list[Reveal]:
    """File events revealed as a performance generator would send them.

    Notes (on and off) and beats become known ``lookahead_beats`` beats before
    their time, at the tempo in force then; controllers and program changes
    likewise, so routing sees a program before the notes it governs.
    """
    out = [
        Reveal(ev.time_s - lookahead_beats * tempo.seconds_per_beat_at(ev.time_s), ev)
        for ev in events
    ]
    out.sort(key=lambda r: r.at_s)  # stable: simultaneous reveals keep file order
    return out


def frame_times(t0_s: float, t1_s: float, fps: float) -> Iterator[float]:
    """The replay timer: frame i is at exactly t0 + i / fps, up to and including t1."""
    if fps <= 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    n = int((t1_s - t0_s) * fps + 1e-9) + 1
    for i in range(max(n, 0)):
        yield t0_s + i / fps


class RevealFeeder:
    """Feeds a reveal schedule into a performance as the timer passes each reveal."""

    def __init__(self, schedule: list[Reveal]) -> None:
        self.schedule = schedule
        self.next = 0

    def until(self, perf: Performance, now_s: float) -> int:
        n = 0
        while self.next < len(self.schedule) and self.schedule[self.next].at_s <= now_s:
            r = self.schedule[self.next]
            perf.feed(r.event, now_s=r.at_s)
            self.next += 1
            n += 1
        return n

    @property
    def done(self) -> bool:
        return self.next >= len(self.schedule)

    def finish(self, perf: Performance) -> list[PlannedNote]:
        """Everything not fed yet, played through on the virtual clock
        (:func:`run_schedule`); the performance finished."""
        rest = self.schedule[self.next :]
        self.next = len(self.schedule)
        return run_schedule(perf, rest)


def run_schedule(perf: Performance, schedule: list[Reveal]) -> list[PlannedNote]:
    """Play a whole reveal schedule on a virtual clock as fast as possible.

    The clock jumps from reveal to reveal; at each, what started is committed
    and the event is fed, exactly as the live daemon does when a datagram
    arrives.  Returns every planned note, in commit order.
    """
    out: list[PlannedNote] = []
    told, perf.tell_provisional = perf.tell_provisional, False  # nothing drawn meanwhile
    try:
        for r in schedule:
            out.extend(perf.advance(r.at_s))
            perf.feed(r.event, now_s=r.at_s)
        out.extend(perf.finish())
    finally:
        perf.tell_provisional = told
    return out


def run_as_live(
    perf: Performance, schedule: list[Reveal], fps: float, t0_s: float
) -> list[PlannedNote]:
    """Play a reveal schedule as the live window draws it: frames of exactly ``1/fps``
    from ``t0_s`` (:func:`frame_times`), at each what became known is fed, what
    started committed, and the frame marked drawn (``mark_drawn``): a later plan
    changes nothing up to there, so the animator ends with the motion the window
    showed.  Runs until every event is fed and every note has sounded; returns
    every planned note, in commit order.  The plan equals :func:`run_schedule`'s but for
    the notes whose provisional hand was drawn moving when the plan would have given
    them the other (``Performance.pin_shown``: kept unless that drops a note)."""
    feeder = RevealFeeder(schedule)
    end_s = max((r.event.time_s for r in schedule), default=t0_s)
    start_s = min([t0_s, *(r.at_s for r in schedule[:1])])
    start_s = t0_s - math.ceil((t0_s - start_s) * fps - 1e-9) / fps  # on the frame grid
    out: list[PlannedNote] = []
    for t in frame_times(start_s, end_s, fps):
        feeder.until(perf, t)
        out.extend(perf.advance(t))
        mark = getattr(perf.animator, "mark_drawn", None)
        if mark is not None:
            mark(t)
    out.extend(feeder.finish(perf))
    return out
