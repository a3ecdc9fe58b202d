"""Online planning: notes arrive ahead of time, motions are fixed once started.

:class:`OnlinePlanner` keeps one *chain* per limb or pair of limbs whose motions
follow each other: the bass's left hand (:class:`~virja.plan.chain_bass.BassChain`),
the drummer's hands (:class:`~virja.plan.chain_hands.HandsChain`) and each foot
(:class:`~virja.plan.chain_feet.FootChain`).  Each holds its fixed state and the
notes not yet started.  Whenever asked (``add_note``, ``poll``, ``flush``) the
planner first has every chain fix each group of notes whose motion has started by
``now_s`` -- with the plan that was optimal for the notes known until then -- and
only then takes the new note in; the plan of the unstarted notes is the least-cost
one over all of them from the fixed state (bass: :func:`virja.plan.bass.solve`;
hands: :func:`virja.plan.drums.solve`).  So the result does not depend on how
often ``poll`` is called, and :func:`plan_notes` (a file) equals the live stream.
What every chain shares is in :mod:`virja.plan.chain`.  See docs/scheduler.md.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Sequence

from virja.events import Beat, NoteOn
from virja.plan.bounds import DEFAULT_BOUNDS, PlanBounds
from virja.plan.chain import GROUP_EPS_S, HISTORY, MAX_REPORTED, AnyChain, ChainContext, Ledger
from virja.plan.chain_bass import BassChain
from virja.plan.chain_feet import FootChain
from virja.plan.chain_hands import (
    BUZZ_PIECES,
    BUZZ_S,
    BUZZ_VELOCITY,
    SAME_STROKE_S,
    HandsChain,
    velocity_priority,
)
from virja.plan.chain_kit import HAND_WINDOW_S, REBOUND_VELOCITY
from virja.plan.config import PlanConfig, default_config
from virja.plan.types import HandPin, PlannedNote, PlanReport
from virja.tempo import DEFAULT_SECONDS_PER_BEAT, Tempo
from virja.vocab import Performer

__all__ = [
    "BUZZ_PIECES",
    "BUZZ_S",
    "BUZZ_VELOCITY",
    "GROUP_EPS_S",
    "HAND_WINDOW_S",
    "HISTORY",
    "MAX_BEATS_KEPT",
    "MAX_REPORTED",
    "REBOUND_VELOCITY",
    "SAME_STROKE_S",
    "OnlinePlanner",
    "plan_notes",
    "plan_notes_with_report",
    "reveal_time",
    "velocity_priority",
]

MAX_BEATS_KEPT = 1024  # tempo history: minutes of beats, far past the 10 s horizon

_default_config: PlanConfig | None = None


def _config(config: PlanConfig | None) -> PlanConfig:
    global _default_config
    if config is not None:
        return config
    if _default_config is None:
        _default_config = default_config()
    return _default_config


class _TempoTrack:
    """The session's tempo as the planner knows it: beats seen (the latest
    MAX_BEATS_KEPT), else ``tempo``, else the default.  Apart from the planner so that
    its chains can look the tempo up without holding the planner: no reference cycle,
    so a planner no longer used is freed at once rather than by the cyclic collector
    (whose pauses were the bench's slowest beats, docs/performance.md)."""

    __slots__ = ("tempo", "times", "spb")

    def __init__(self, tempo: Tempo | None) -> None:
        self.tempo = tempo
        self.times: list[float] = []  # sorted; at most MAX_BEATS_KEPT, the latest
        self.spb: list[float] = []

    def add(self, beat: Beat) -> None:
        i = bisect.bisect_right(self.times, beat.time_s)
        self.times.insert(i, beat.time_s)
        self.spb.insert(i, beat.seconds_per_beat)
        if len(self.times) > MAX_BEATS_KEPT:  # a daemon runs for hours: keep the latest
            del self.times[0], self.spb[0]

    def seconds_per_beat_at(self, time_s: float) -> float:
        i = bisect.bisect_right(self.times, time_s)
        if i > 0:
            return self.spb[i - 1]
        if self.tempo is not None:
            return self.tempo.seconds_per_beat_at(time_s)
        return self.spb[0] if self.spb else DEFAULT_SECONDS_PER_BEAT


class OnlinePlanner:
    """The scheduler, fed note by note (see the module docstring).

    ``tempo`` gives seconds per beat where no BEAT has been seen; beats given to
    :meth:`add_beat` take precedence from their time on.
    """

    def __init__(
        self,
        config: PlanConfig | None = None,
        *,
        tempo: Tempo | None = None,
        bounds: PlanBounds = DEFAULT_BOUNDS,
    ) -> None:
        self.config = _config(config)
        self.bounds = bounds
        self._track = _TempoTrack(tempo)
        self._ledger = Ledger()
        ctx = ChainContext(self.config, bounds, self._ledger, self._track.seconds_per_beat_at)
        self._bass = BassChain(ctx)
        right_foot = FootChain(ctx, "right_foot")
        left_foot = FootChain(ctx, "left_foot")
        hands = HandsChain(ctx, left_foot)
        self._hands = hands
        # a drum note's chain by its kit limb (None: a hand, chosen by cost)
        self._kit = {None: hands, "right_foot": right_foot, "left_foot": left_foot}
        # in this order each call fixes them (a hand's hi-hat may go to the left foot)
        self._chains: tuple[AnyChain, ...] = (self._bass, hands, right_foot, left_foot)
        self._seq = 0

    # -- inputs ---------------------------------------------------------------

    def add_beat(self, beat: Beat) -> None:
        """A beat of the session: its tempo applies from its time on."""
        self._track.add(beat)

    def seconds_per_beat_at(self, time_s: float) -> float:
        return self._track.seconds_per_beat_at(time_s)

    def add_note(self, performer: Performer, note: NoteOn, *, now_s: float) -> None:
        """A note for ``performer`` that sounds at ``note.time_s``, known since ``now_s``."""
        self._commit(now_s)
        self._seq += 1
        if performer == "bass":
            self._bass.take(self._bass.held(self._seq, note, now_s))
        elif performer == "drums":
            dn = self.config.kit.lookup(note.note)
            if dn is None:
                self._ledger.unmapped(performer, note)
                return
            if dn.piece == "none":  # percussion no kit drummer plays: routed to nobody
                self._ledger.unplayed[dn.name or f"note {note.note}"] += 1
                return
            chain = self._kit[dn.limb]
            chain.take(chain.held(self._seq, note, now_s, dn))
        else:
            raise ValueError(f"unknown performer {performer!r}")

    def pin_hands(self, pins: Iterable[HandPin], *, now_s: float) -> int:
        """Live: the drum notes whose provisional hand is drawn moving for them at
        ``now_s`` (the animator says which, ``BandAnimator.shown_moving``; the
        performance passes the whole current set before each commit).  The plan then
        gives such a note the other hand only at a price: what that hand's speed costs
        when it leaves only now, plus ``shown_hand_penalty``
        (:meth:`virja.plan.chain_hands.HandsChain.switch_cost`): with time to spare the
        plan may still switch, at the motion's start it keeps the hand shown unless it
        cannot play the note in time or that would drop a note.  Returns how many pending
        notes have a pin.  Whole-input planning (``run_schedule``) draws nothing and pins
        none: its plans are unchanged (docs/motion.md, round 8)."""
        return self._hands.pin(
            {(p.channel, p.note, round(p.time_s, 9)): p.hand for p in pins}, now_s
        )

    # -- outputs --------------------------------------------------------------

    def poll(self, now_s: float) -> list[PlannedNote]:
        """Planned notes whose motions have started by ``now_s``, in start order; fixed."""
        self._commit(now_s)
        outbox = self._ledger.outbox
        ready = [p for p in outbox if p.start <= now_s]
        self._ledger.outbox = [p for p in outbox if p.start > now_s]
        return sorted(ready, key=lambda p: (p.start, p.time))

    def provisional(self) -> list[PlannedNote]:
        """The drummer's hand notes not yet handed out by :meth:`poll`, each with the hand
        the plan gives it now (:meth:`virja.plan.chain_hands.HandsChain.provisional`;
        a note fixed already as fixed), in impact order.
        Call it after :meth:`add_note` or :meth:`poll`: a later note may revise it;
        the plan fixed at the motion's start is what :meth:`poll` returns.  Looking
        changes no plan (the same notes are fixed the same way whether or not it is
        called); its solve is the one the next commit would do, kept for it."""
        fixed = [  # fixed already, not handed out yet (poll): as they will be
            p for p in self._ledger.outbox if p.performer == "drums" and p.limb.endswith("_hand")
        ]
        out = fixed + self._hands.provisional()
        out.sort(key=lambda p: (p.impact, p.time, p.limb, p.note))
        return out

    def flush(self) -> list[PlannedNote]:
        """Everything still held, planned and fixed, in start order."""
        for chain in self._chains:
            chain.fix_all()
        out = sorted(self._ledger.outbox, key=lambda p: (p.start, p.time))
        self._ledger.outbox = []
        return out

    def next_deadline(self) -> float:
        """The earliest time at which :meth:`poll` can return something new: the
        start of a motion pending or planned but not started (inf when none).
        A live timer sleeps until then (or until a note arrives)."""
        t = min(c.min_start for c in self._chains)
        if self._ledger.outbox:
            t = min(t, min(p.start for p in self._ledger.outbox))
        return t

    @property
    def report(self) -> PlanReport:
        """Notes dropped or moved so far."""
        return self._ledger.report()

    @property
    def origin_s(self) -> float:
        """For messages only: times are said from the input's start (Performance sets it)."""
        return self._ledger.origin_s

    @origin_s.setter
    def origin_s(self, value: float) -> None:
        self._ledger.origin_s = value

    @property
    def pending_count(self) -> int:
        return sum(c.pending_count for c in self._chains)

    def _commit(self, now_s: float) -> None:
        for chain in self._chains:
            if chain.min_start <= now_s:  # else nothing pending has started (or none)
                chain.commit(now_s)


def reveal_time(note: NoteOn, tempo: Tempo, lookahead_beats: float) -> float:
    """When a generator sends ``note``: ``lookahead_beats`` beats before it sounds."""
    return note.time_s - lookahead_beats * tempo.seconds_per_beat_at(note.time_s)


def plan_notes_with_report(
    notes: Sequence[tuple[Performer, NoteOn]],
    tempo: Tempo,
    *,
    lookahead_beats: float = 1.0,
    config: PlanConfig | None = None,
    bounds: PlanBounds = DEFAULT_BOUNDS,
) -> tuple[list[PlannedNote], PlanReport]:
    """Plan a whole performance as the live daemon would, and the report.

    Each note is revealed at :func:`reveal_time`; in reveal order the planner is
    polled at that time and then given the note; finally flushed.
    """
    planner = OnlinePlanner(config, tempo=tempo, bounds=bounds)
    order = sorted(
        range(len(notes)), key=lambda i: reveal_time(notes[i][1], tempo, lookahead_beats)
    )
    out: list[PlannedNote] = []
    for i in order:
        performer, note = notes[i]
        now = reveal_time(note, tempo, lookahead_beats)
        out.extend(planner.poll(now))
        planner.add_note(performer, note, now_s=now)
    out.extend(planner.flush())
    return out, planner.report


def plan_notes(
    notes: Sequence[tuple[Performer, NoteOn]],
    tempo: Tempo,
    *,
    lookahead_beats: float = 1.0,
    config: PlanConfig | None = None,
) -> list[PlannedNote]:
    """The planned notes of :func:`plan_notes_with_report`, in start order."""
    return plan_notes_with_report(notes, tempo, lookahead_beats=lookahead_beats, config=config)[0]
