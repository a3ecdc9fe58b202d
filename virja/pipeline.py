"""The one place a performance is put together: router + planner + animator + plan log.

Every command that plays notes (``serve``, ``render``, ``replay``, ``jam``,
``plan`` on a recording, ``export``, ``batch``) and the capture tools build
their :class:`~virja.session.Performance` here, from a
:class:`PerformanceSettings` parsed once from the command line (or handed to a
batch worker) and, for a file or a recording, its
:class:`~virja.input.PerformanceInput`:

    settings = PerformanceSettings(plan=load_plan_config(path), routing=routing)
    perf = build_performance(settings, src, animate=True, plan_log=fh)

What differs between commands is only data: the tables (a jam without delay and
RTP-MIDI notes, played at once, get the shortest strokes: ``immediate``), the
routing (a MIDI file's router knows its track names) and the tempo (a file's
tempo map; a recording or a live session learns it from BEAT messages).
Outputs that want planned motions (the window's process, an animator for the
browsers) join as the performance's ``animator`` (a ``live.sinks.Fanout``);
drawing to files is :mod:`virja.render.offline` with its ``RenderSettings``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING

from virja.plan.config import PlanConfig, load_plan_config
from virja.routing import Router, RoutingConfig
from virja.session import Performance, PlanSink

if TYPE_CHECKING:
    from virja.input import PerformanceInput
    from virja.plan.types import PlannedNote


def _default_plan() -> PlanConfig:
    return load_plan_config(None)


@dataclass(frozen=True)
class PerformanceSettings:
    """What a performance is built from, parsed once (plain data: it pickles, so a
    batch worker gets it whole).

    ``plan``: the scheduler's tables (``[plan]`` and motions/*.toml); ``routing``:
    who plays what, flags already applied over ``[routing]``; ``immediate``: notes are
    played as they arrive (a jam without delay, RTP-MIDI), so strokes are cut to the
    shortest (:mod:`virja.plan.immediate`).
    """

    plan: PlanConfig = field(default_factory=_default_plan)
    routing: RoutingConfig = field(default_factory=RoutingConfig)
    immediate: bool = False

    def tables(self) -> PlanConfig:
        """The tables the planner gets: ``plan``, or its immediate strokes."""
        if not self.immediate:
            return self.plan
        from virja.plan.immediate import immediate_strokes

        return immediate_strokes(self.plan)


def build_performance(
    settings: PerformanceSettings,
    src: PerformanceInput | None = None,
    *,
    animate: bool = False,
    animator: PlanSink | None = None,
    plan_log: IO[str] | None = None,
) -> Performance:
    """Router + planner (+ animator, + plan log) for one performance.

    With ``src`` (a MIDI file or a recording) the router knows the file's track
    names, the planner its tempo map, and a recording's RTP-MIDI notes (played at
    once, as live) get the shortest strokes.  ``animate`` gives it a
    :class:`~virja.motion.band.BandAnimator` (poses in this process); ``animator``
    any other :class:`~virja.session.PlanSink` (the live outputs' fan-out).  Times
    in the plan log and messages count from the input's start; without ``src`` from
    the first datagram (or note) unless the caller sets ``origin_s``.
    """
    from virja.plan.planner import OnlinePlanner

    if animate and animator is not None:
        raise ValueError("give animate or an animator, not both")
    if src is not None and src.immediate and not settings.immediate:
        settings = PerformanceSettings(settings.plan, settings.routing, immediate=True)
    midi = src.midi if src is not None else None
    router = (
        Router.for_session(midi, settings.routing) if midi is not None else Router(settings.routing)
    )
    if animate:
        from virja.motion.band import BandAnimator

        animator = BandAnimator()
    tempo = src.tempo if src is not None else None
    return Performance(
        router=router,
        planner=OnlinePlanner(settings.tables(), tempo=tempo),
        animator=animator,
        plan_log=plan_log,
        # the session time users call 0: the input's start (a recording's first packet);
        # live, the first datagram's arrival (serve's Daemon.arrived) or the jam's start
        origin_s=src.start_s if src is not None else None,
    )


def perform(
    settings: PerformanceSettings,
    src: PerformanceInput,
    *,
    animate: bool = False,
    until_s: float | None = None,
    as_live_fps: float | None = None,
) -> tuple[Performance, list[PlannedNote]]:
    """A whole input through :func:`build_performance` on a virtual clock, as fast as
    possible (:func:`virja.session.run_schedule`): each event fed when it becomes known,
    what has started committed, exactly as live.  ``until_s`` (seconds from the input's
    start) leaves out the notes that sound after it (their note-offs and the beats stay).
    Returns the performance (its planner's report, its animator) and every planned note
    in commit order; ``plan``, ``motion-report`` and the capture tools plan here, so their
    plans are the ones render draws.  ``as_live_fps``: instead, frames of ``1/fps`` drawn
    as the live window draws them (:func:`virja.session.run_as_live`; the same plan but
    for notes whose hand was drawn moving, kept for them),
    so the animator ends with the motion the window showed."""
    from virja.events import NoteOn
    from virja.session import run_as_live, run_schedule

    schedule = src.schedule
    if until_s is not None:
        end_s = src.start_s + until_s
        schedule = [
            r for r in schedule if not (isinstance(r.event, NoteOn) and r.event.time_s > end_s)
        ]
    perf = build_performance(settings, src, animate=animate)
    perf.keep_planned = False
    if as_live_fps is not None:
        return perf, run_as_live(perf, schedule, as_live_fps, src.start_s)
    return perf, run_schedule(perf, schedule)
