"""Online planning: notes arrive ahead of time, motions are fixed once started.

:class:`OnlinePlanner` keeps, per *chain* (the bass's left hand, the drummer's
hands, each foot), a fixed state and the notes not yet started.  Whenever
asked (``add_note``, ``poll``, ``flush``) it first fixes every group of notes
whose motion has started by ``now_s`` -- with the plan that was optimal for the
notes known until then -- and only then takes the new note in; the plan of the
unstarted notes is the least-cost one over all of them from the fixed state
(bass: :func:`virja.plan.bass.solve`; hands: :func:`virja.plan.drums.solve`).
So the result does not depend on how often ``poll`` is called, and
:func:`plan_notes` (a file) equals the live stream.  See docs/scheduler.md.
"""

from __future__ import annotations

import bisect
import logging
import math
from collections import Counter, deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from virja.events import Beat, NoteOn, Performer
from virja.plan import bass as bass_mod
from virja.plan import drums as drums_mod
from virja.plan.bounds import DEFAULT_BOUNDS, DensityGate, PlanBounds
from virja.plan.config import DrumNote, PlanConfig, default_config
from virja.plan.timing import align
from virja.plan.types import DroppedNote, DropReason, Limb, MovedNote, PlannedNote, PlanReport
from virja.tempo import DEFAULT_SECONDS_PER_BEAT, Tempo

log = logging.getLogger(__name__)

GROUP_EPS_S = 0.001  # notes this close sound together (one stroke per piece and limb)
# The drummer's hands take notes within this window of a group's first note as meant
# together (humanised "simultaneous" hits lie 2-30 ms apart; a flam's grace note leads
# its main note by 15-30 ms): one decision for the group, each note at its own time.
HAND_WINDOW_S = 0.030
# Notes of one piece this close are one stroke heard twice (head and rim, a pad's
# double trigger): the later ones ride on the first stroke, each at its own time.
SAME_STROKE_S = 0.010
# A note this soft on the piece a limb has just struck, sooner than the limb could
# strike again, is that stroke's rebound (a beater or stick bouncing off the head
# once more), heard at its own time and played by the same stroke.
REBOUND_VELOCITY = 16
# A soft hand note (a ghost note) this soon after another note on the same piece is
# part of a buzz or press roll: the same hand presses, the stick bounces.
BUZZ_VELOCITY = 48  # ghost notes and soft drag notes (below mezzo-piano)
BUZZ_S = 0.050
BUZZ_PIECES = frozenset({"snare", "tom_high", "tom_low", "tom_floor", "hihat", "ride"})
HISTORY = 64  # fixed hand strokes kept for notes that arrive out of order
MAX_BEATS_KEPT = 1024  # tempo history: minutes of beats, far past the 10 s horizon
MAX_REPORTED = 10_000  # dropped and moved notes kept for the report (totals are counted)

_default_config: PlanConfig | None = None


def _config(config: PlanConfig | None) -> PlanConfig:
    global _default_config
    if config is not None:
        return config
    if _default_config is None:
        _default_config = default_config()
    return _default_config


@dataclass(slots=True)
class _Rec:
    """A note the planner holds."""

    seq: int
    performer: Performer
    note: NoteOn
    known_s: float
    chain: str  # "bass" | "hands" | "right_foot" | "left_foot"
    kind: str  # timing kind: piece, "kick", "hihat_pedal", "pluck"
    played: int  # bass: the pitch played (after octave folding); drums: the note
    drum: DrumNote | None = None
    start: float = 0.0
    impact: float = 0.0
    late: bool = False
    rebound: bool | None = None  # hands: decided once, the first time it is planned
    to_foot: bool | None = None  # hands: a hi-hat note given to the left foot (decided once)


@dataclass(slots=True)
class _Chain:
    name: str
    pending: list[_Rec] = field(default_factory=list)
    # min(r.start for r in pending), inf when none: kept up to date on every change of
    # pending so that each call need not scan it (it is checked on every note)
    min_start: float = math.inf
    state: Any = None  # bass: finger; hands: HandState; feet: last stroke time
    last_fixed_t: float | None = None
    fixed: list[tuple[float, PlannedNote]] = field(default_factory=list)  # recent, for sharing
    # the optimal plan of the pending groups, one decision per group, kept until a
    # note arrives: fixing in several steps then equals fixing in one (ties included)
    plan: list[Any] | None = None


def _groups(recs: list[_Rec], window: float = GROUP_EPS_S) -> list[list[_Rec]]:
    """``recs`` in time order, cut into groups of notes within ``window`` of the
    group's first note."""
    out: list[list[_Rec]] = []
    for r in sorted(recs, key=lambda r: (r.note.time_s, r.seq)):
        if out and r.note.time_s - out[-1][0].note.time_s <= window + drums_mod.TIME_EPS_S:
            out[-1].append(r)
        else:
            out.append([r])
    return out


def _window(chain: str) -> float:
    return GROUP_EPS_S if chain == "bass" else HAND_WINDOW_S


def velocity_priority(priority: int, velocity: int) -> int:
    """A note's priority weighed by its velocity (lower = more important): a ghost
    note (velocity < 40) gives way first, a soft one (< 64) next, an accent (>= 100)
    is kept before a plain stroke of its piece."""
    if velocity < 40:
        return priority + 3
    if velocity < 64:
        return priority + 1
    if velocity >= 100:
        return max(0, priority - 1)
    return priority


@dataclass(frozen=True, slots=True)
class _HandGroupPlan:
    """A hand group prepared for the solver: its (at most two) strokes, the notes of
    each, bounces (index of the stroke they ride on, notes) and notes beyond two hands."""

    group: drums_mod.HandGroup
    kept: list[list[_Rec]]
    bounces: list[tuple[int, list[_Rec]]]
    extra: list[_Rec]


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
        self._tempo = tempo
        self._beat_times: list[float] = []  # sorted; at most MAX_BEATS_KEPT, the latest
        self._beat_spb: list[float] = []
        self._chains = {n: _Chain(n) for n in ("bass", "hands", "right_foot", "left_foot")}
        self._chains["hands"].state = drums_mod.START
        self._gates = {n: DensityGate(bounds) for n in self._chains}
        self._outbox: list[PlannedNote] = []
        self._dropped: deque[DroppedNote] = deque(maxlen=MAX_REPORTED)
        self._moved: deque[MovedNote] = deque(maxlen=MAX_REPORTED)
        self._counts: Counter[str] = Counter()
        self._unplayed: Counter[str] = Counter()  # per instrument: not a kit drummer's
        self._seq = 0
        # for messages only: times are said from the input's start (Performance sets it)
        self.origin_s = 0.0

    # -- inputs ---------------------------------------------------------------

    def add_beat(self, beat: Beat) -> None:
        """A beat of the session: its tempo applies from its time on."""
        i = bisect.bisect_right(self._beat_times, beat.time_s)
        self._beat_times.insert(i, beat.time_s)
        self._beat_spb.insert(i, beat.seconds_per_beat)
        if len(self._beat_times) > MAX_BEATS_KEPT:  # a daemon runs for hours: keep the latest
            del self._beat_times[0], self._beat_spb[0]

    def seconds_per_beat_at(self, time_s: float) -> float:
        i = bisect.bisect_right(self._beat_times, time_s)
        if i > 0:
            return self._beat_spb[i - 1]
        if self._tempo is not None:
            return self._tempo.seconds_per_beat_at(time_s)
        return self._beat_spb[0] if self._beat_spb else DEFAULT_SECONDS_PER_BEAT

    def add_note(self, performer: Performer, note: NoteOn, *, now_s: float) -> None:
        """A note for ``performer`` that sounds at ``note.time_s``, known since ``now_s``."""
        self._commit(now_s)
        rec = self._make_rec(performer, note, now_s)
        if rec is None:
            return
        chain = self._chains[rec.chain]
        if len(chain.pending) >= self.bounds.max_pending:
            self._drop(rec, "planner_full")
            return
        if not self._gates[rec.chain].admit(note.time_s):
            self._drop(rec, "too_dense")
            return
        if chain.last_fixed_t is not None and note.time_s <= chain.last_fixed_t + GROUP_EPS_S:
            self._place_out_of_order(chain, rec)
        else:
            chain.pending.append(rec)
            chain.min_start = min(chain.min_start, rec.start)
            chain.plan = None

    # -- outputs --------------------------------------------------------------

    def poll(self, now_s: float) -> list[PlannedNote]:
        """Planned notes whose motions have started by ``now_s``, in start order; fixed."""
        self._commit(now_s)
        ready = [p for p in self._outbox if p.start <= now_s]
        self._outbox = [p for p in self._outbox if p.start > now_s]
        return sorted(ready, key=lambda p: (p.start, p.time))

    def flush(self) -> list[PlannedNote]:
        """Everything still held, planned and fixed, in start order."""
        for chain in self._chains.values():
            groups = _groups(chain.pending, _window(chain.name))
            self._fix(chain, groups, len(groups))
        out = sorted(self._outbox, key=lambda p: (p.start, p.time))
        self._outbox = []
        return out

    def next_deadline(self) -> float:
        """The earliest time at which :meth:`poll` can return something new: the
        start of a motion pending or planned but not started (inf when none).
        A live timer sleeps until then (or until a note arrives)."""
        t = min(c.min_start for c in self._chains.values())
        if self._outbox:
            t = min(t, min(p.start for p in self._outbox))
        return t

    @property
    def report(self) -> PlanReport:
        """Notes dropped or moved so far."""
        return PlanReport(
            tuple(self._dropped),
            tuple(self._moved),
            tuple(sorted(self._counts.items())),
            tuple(sorted(self._unplayed.items())),
        )

    @property
    def pending_count(self) -> int:
        return sum(len(c.pending) for c in self._chains.values())

    # -- internals ------------------------------------------------------------

    def _drop(self, rec: _Rec, reason: DropReason) -> None:
        log.info(
            "dropped %s note %d at %.3f s: %s",
            rec.performer,
            rec.note.note,
            rec.note.time_s - self.origin_s,
            reason,
        )
        self._dropped.append(DroppedNote(rec.performer, rec.note, reason))
        self._counts["dropped"] += 1
        self._counts[f"dropped_{reason}"] += 1

    def _make_rec(self, performer: Performer, note: NoteOn, now_s: float) -> _Rec | None:
        self._seq += 1
        if performer == "bass":
            setup = self.config.bass
            played = bass_mod.fold_into_range(setup, note.note)
            if played != note.note:
                log.info("bass note %d out of range: played as %d", note.note, played)
                self._moved.append(MovedNote(performer, note, played))
                self._counts["moved"] += 1
            rec = _Rec(self._seq, performer, note, now_s, "bass", "pluck", played)
        elif performer == "drums":
            dn = self.config.kit.lookup(note.note)
            if dn is None:
                self._dropped.append(DroppedNote(performer, note, "unmapped"))
                self._counts["dropped"] += 1
                self._counts["dropped_unmapped"] += 1
                log.info("drum note %d not in the kit map: dropped", note.note)
                return None
            if dn.piece == "none":  # percussion no kit drummer plays: routed to nobody
                self._unplayed[dn.name or f"note {note.note}"] += 1
                return None
            chain = dn.limb or "hands"
            kind = (
                dn.piece if dn.limb is None else ("kick" if dn.piece == "kick" else "hihat_pedal")
            )
            rec = _Rec(self._seq, performer, note, now_s, chain, kind, note.note, dn)
        else:
            raise ValueError(f"unknown performer {performer!r}")
        a = align(
            self.config.timing, rec.kind, note.time_s, now_s, self.seconds_per_beat_at(note.time_s)
        )
        rec.start, rec.impact, rec.late = a.start, a.impact, a.late
        return rec

    def _commit(self, now_s: float) -> None:
        for chain in self._chains.values():
            if chain.min_start > now_s:  # nothing pending has started (or none pending)
                continue
            groups = _groups(chain.pending, _window(chain.name))
            started = [i for i, g in enumerate(groups) if min(r.start for r in g) <= now_s]
            if started:
                self._fix(chain, groups, started[-1] + 1)

    def _fix(self, chain: _Chain, groups: list[list[_Rec]], n_groups: int) -> None:
        """Plan the chain's pending notes and fix the first ``n_groups`` of their
        ``groups`` (:func:`_groups` of the pending notes)."""
        if n_groups == 0 or not chain.pending:
            return
        if chain.name == "bass":
            self._fix_bass(chain, groups, n_groups)
        elif chain.name == "hands":
            self._fix_hands(chain, groups, n_groups)
        else:
            self._fix_foot(chain, groups, n_groups)
        fixed = {r.seq for g in groups[:n_groups] for r in g}
        chain.pending = [r for r in chain.pending if r.seq not in fixed]
        chain.min_start = min((r.start for r in chain.pending), default=math.inf)
        chain.last_fixed_t = groups[n_groups - 1][0].note.time_s
        self._gates[chain.name].forget_before(chain.last_fixed_t)
        chain.fixed = chain.fixed[-HISTORY:]

    def _emit(self, chain: _Chain, rec: _Rec, **kw: Any) -> PlannedNote:
        n = rec.note
        p = PlannedNote(
            time=n.time_s,
            performer=rec.performer,
            channel=n.channel,
            note=rec.played,
            velocity=n.velocity,
            start=rec.start,
            impact=rec.impact,
            late=rec.late,
            **kw,
        )
        self._outbox.append(p)
        chain.fixed.append((n.time_s, p))
        return p

    # bass ---------------------------------------------------------------------

    def _bass_group(self, group: list[_Rec]) -> tuple[list[int], tuple[bass_mod.BassOption, ...]]:
        pitches = sorted({r.played for r in group}, reverse=True)
        kept, options = bass_mod.chord_options(self.config.bass, tuple(pitches))
        return pitches[:kept], options

    def _fix_bass(self, chain: _Chain, groups: list[list[_Rec]], n_groups: int) -> None:
        window = self.bounds.window_groups  # plan.bounds: one solve, at most this many groups
        for gi in range(n_groups):
            kept, opts = self._bass_group(groups[gi])
            if not chain.plan:  # none yet, or the window's plan is used up: solve the next
                win = groups[gi : gi + window]
                times = [g[0].note.time_s for g in win]
                last = groups[gi - 1][0].note.time_s if gi > 0 else chain.last_fixed_t
                gaps = [times[0] - last if last is not None else math.inf]
                gaps += [b - a for a, b in zip(times, times[1:], strict=False)]
                sol = bass_mod.solve(
                    chain.state,
                    [self._bass_group(g)[1] for g in win],
                    self.config.bass.fingering,
                    gaps,
                )
                chain.plan = list(zip(sol.choice, sol.costs, sol.states, strict=True))
            choice, cost, state = chain.plan.pop(0)
            self._emit_bass_group(chain, groups[gi], kept, opts[choice], cost, state)
            chain.state = state

    def _emit_bass_group(
        self,
        chain: _Chain,
        group: list[_Rec],
        kept: list[int],
        option: bass_mod.BassOption,
        cost: float,
        hand: bass_mod.BassState,
    ) -> None:
        where = dict(zip(kept, option, strict=True))
        paid = False
        for rec in group:
            if rec.played not in where:
                self._drop(rec, "no_double_stop")
                continue
            s, f = where[rec.played]
            name = self.config.bass.strings[s][0]
            self._emit(
                chain,
                rec,
                limb="right_hand",
                piece=None,
                string=name,
                fret=f,
                motion=bass_mod.motion_name(name, f, hand),
                cost=0.0 if paid else cost,
            )
            paid = True

    # drums: hands -------------------------------------------------------------

    def _rebounds(self, chain: _Chain) -> set[int]:
        """The pending hand notes that are rebounds (REBOUND_VELOCITY) of an earlier
        note on the same piece, fixed or pending, within its ``min_interval_s`` (a
        buzz: soft rebounds of one pressed stroke)."""
        strokes: dict[str, list[float]] = {}
        for ft, p in chain.fixed:
            if p.piece is not None:
                strokes.setdefault(p.piece, []).append(ft)
        for r in chain.pending:
            if r.drum is not None:
                strokes.setdefault(r.drum.piece, []).append(r.note.time_s)
        for r in chain.pending:
            if r.rebound is not None:
                continue
            r.rebound = False
            if r.drum is None or r.note.velocity >= BUZZ_VELOCITY:
                continue
            if r.drum.piece not in BUZZ_PIECES:  # a crash swings away: no rebound
                continue
            t = r.note.time_s
            reach = self.config.timing.get(r.drum.piece).min_interval_s
            if r.note.velocity >= REBOUND_VELOCITY:
                reach = max(reach, BUZZ_S)
            r.rebound = any(0 < t - s <= reach + GROUP_EPS_S for s in strokes.get(r.drum.piece, ()))
        return {r.seq for r in chain.pending if r.rebound}

    def _hand_group(self, group: list[_Rec], t0: float) -> _HandGroupPlan:
        """The strokes of a group: notes of one piece within GROUP_EPS_S are one stroke.

        The two most important strokes (velocity-weighed priority, then the earlier)
        are planned; a further stroke on a piece already planned is a bounce of the
        nearest planned stroke there (a buzz or a drag's second note, same hand); a
        third distinct piece within the window is more than two hands can strike.
        """
        if not group:
            return _HandGroupPlan(drums_mod.HandGroup(t0, ()), [], [], [])
        clusters: list[list[_Rec]] = []
        for r in sorted(group, key=lambda r: (r.note.time_s, r.seq)):
            assert r.drum is not None
            same = next(
                (
                    c
                    for c in clusters
                    if c[0].drum is not None
                    and c[0].drum.piece == r.drum.piece
                    and r.note.time_s - c[0].note.time_s <= SAME_STROKE_S
                ),
                None,
            )
            if same is None:
                clusters.append([r])
            else:
                same.append(r)

        def rank(c: list[_Rec]) -> tuple[int, float, int]:
            prio = min(velocity_priority(r.drum.priority, r.note.velocity) for r in c if r.drum)
            return (prio, c[0].note.time_s, c[0].seq)

        ranked = sorted(clusters, key=rank)
        kept = ranked[:2]
        bounces: list[tuple[int, list[_Rec]]] = []
        extra: list[_Rec] = []
        for c in ranked[2:]:
            piece = c[0].drum.piece if c[0].drum else ""
            near = [
                (abs(k[0].note.time_s - c[0].note.time_s), i)
                for i, k in enumerate(kept)
                if k[0].drum is not None and k[0].drum.piece == piece
            ]
            if near:
                bounces.append((min(near)[1], c))
            else:
                extra.extend(c)
        strokes = tuple(
            drums_mod.Stroke(
                c[0].drum.piece if c[0].drum else "", rank(c)[0], c[0].note.time_s - t0
            )
            for c in kept
        )
        return _HandGroupPlan(drums_mod.HandGroup(t0, strokes), kept, bounces, extra)

    def _fix_hands(self, chain: _Chain, groups: list[list[_Rec]], n_groups: int) -> None:
        rebounds = self._rebounds(chain)
        for g in groups:
            self._decide_foot(g, rebounds)
        aside = rebounds | {r.seq for r in chain.pending if r.to_foot}

        def prepare(g: list[_Rec]) -> _HandGroupPlan:
            return self._hand_group([r for r in g if r.seq not in aside], g[0].note.time_s)

        window = self.bounds.window_groups  # plan.bounds: one solve, at most this many groups
        for gi in range(n_groups):
            hp = prepare(groups[gi])
            if not chain.plan:  # none yet, or the window's plan is used up: solve the next
                sol = drums_mod.solve(
                    self.config.costs,
                    self.config.timing,
                    chain.state,
                    [prepare(g).group for g in groups[gi : gi + window]],
                    beam=self.bounds.beam,
                )
                chain.plan = list(zip(sol.assignments, sol.stroke_costs, sol.states, strict=True))
            assignment, stroke_costs, state = chain.plan.pop(0)
            for r in hp.extra:
                if not self._foot_chick(r):
                    self._drop(r, "too_many_hands")
            # three or more pieces at once: whatever else gives way, gives way to that
            slow: DropReason = "too_many_hands" if hp.extra else "too_fast"
            late_rebounds = [r for r in groups[gi] if r.seq in rebounds]
            for r in groups[gi]:
                if r.to_foot and not self._foot_chick(r):
                    self._drop(r, "too_many_hands")
            for si, stroke in enumerate(hp.group.strokes):
                recs = hp.kept[si]
                hand = assignment[si]
                bounces = [r for k, c in hp.bounces if k == si for r in c]
                other = 1 - si
                if (
                    hand is None
                    and len(hp.group.strokes) == 2
                    and hp.group.strokes[other].piece == stroke.piece
                    and assignment[other] is not None
                ):
                    # no second hand for it, but the first is on the same piece: a
                    # rebound of that stroke (a drag, a buzz, a pad's double trigger)
                    hand = assignment[other]
                    assert hand is not None
                    for r in recs + bounces:
                        self._emit_bounce(chain, r, stroke.piece, hand)
                    continue
                if hand is None:
                    for r in recs + bounces:
                        if not self._foot_chick(r):
                            self._drop(r, slow)
                    continue
                now = [r for r in recs if r.note.time_s - recs[0].note.time_s <= GROUP_EPS_S]
                self._emit_stroke(chain, now, stroke.piece, hand, stroke_costs[si])
                for r in recs[len(now) :] + bounces:
                    self._emit_bounce(chain, r, stroke.piece, hand)
            for r in late_rebounds:
                self._emit_rebound(chain, r)
            chain.state = state

    def _decide_foot(self, group: list[_Rec], rebounds: set[int]) -> None:
        """Three or more hand pieces at once, one the hi-hat: the left foot takes the
        hi-hat (a chick) if it is free, and the hands keep the rest."""
        undecided = [r for r in group if r.to_foot is None]
        if not undecided:
            return
        pieces = {r.drum.piece for r in group if r.drum is not None and r.seq not in rebounds}
        crowded = len(pieces) >= 3 and "hihat" in pieces
        for r in undecided:
            r.to_foot = (
                crowded
                and r.seq not in rebounds
                and r.drum is not None
                and r.drum.piece == "hihat"
                and self._foot_free(r.note.time_s)
            )

    def _foot_near(self) -> list[float]:
        foot = self._chains["left_foot"]
        near = [ft for ft, _p in foot.fixed] + [r.note.time_s for r in foot.pending]
        if foot.state is not None:
            near.append(foot.state)
        return near

    def _foot_free(self, t: float) -> bool:
        """The left foot plays the hi-hat at ``t`` already, or can."""
        near = self._foot_near()
        min_int = self.config.timing.get("hihat_pedal").min_interval_s
        return any(abs(ft - t) <= HAND_WINDOW_S for ft in near) or not any(
            abs(ft - t) < min_int - drums_mod.TIME_EPS_S for ft in near
        )

    def _foot_chick(self, rec: _Rec) -> bool:
        """A hi-hat note both hands are too busy for, played by the left foot (a chick
        on the pedal) if the foot is free then or already plays the hi-hat then."""
        if rec.drum is None or rec.drum.piece != "hihat":
            return False
        foot = self._chains["left_foot"]
        t = rec.note.time_s
        min_int = self.config.timing.get("hihat_pedal").min_interval_s
        near = self._foot_near()
        if any(abs(ft - t) <= HAND_WINDOW_S for ft in near):
            shared = True  # the foot plays the hi-hat then: the note rides on that chick
        elif any(abs(ft - t) < min_int - drums_mod.TIME_EPS_S for ft in near):
            return False
        else:
            shared = False
        a = align(self.config.timing, "hihat_pedal", t, rec.known_s, self.seconds_per_beat_at(t))
        rec.start, rec.impact, rec.late = a.start, a.impact, a.late
        self._emit(
            foot,
            rec,
            limb="left_foot",
            piece="hihat",
            string=None,
            fret=None,
            motion="hihat_left_foot",
            cost=0.0,
        )
        if not shared and (foot.state is None or t > foot.state):
            foot.state = t
        self._counts["foot_chick"] += 1
        return True

    def _emit_rebound(self, chain: _Chain, rec: _Rec) -> None:
        """``rec`` rides on the latest stroke before it on its piece (see
        :meth:`_rebounds`); dropped if that stroke was not played."""
        assert rec.drum is not None
        t = rec.note.time_s
        by = next(
            (p for ft, p in reversed(chain.fixed) if p.piece == rec.drum.piece and ft < t),
            None,
        )
        if by is None or by.limb is None:
            self._drop(rec, "too_fast")
        else:
            self._emit_bounce(chain, rec, rec.drum.piece, by.limb)

    def _emit_bounce(self, chain: _Chain, rec: _Rec, piece: str, limb: str) -> None:
        """A note played by the rebound of a stroke of ``limb`` on ``piece`` within the
        grouping window: its own impact time, no cost of its own."""
        self._emit(
            chain,
            rec,
            limb=_limb(limb),
            piece=piece,
            string=None,
            fret=None,
            motion=f"{piece}_{limb}",
            cost=0.0,
        )

    def _emit_stroke(
        self, chain: _Chain, recs: list[_Rec], piece: str, limb: str, cost: float
    ) -> None:
        """One stroke for ``recs`` (the same piece at once): shared motion, start and impact."""
        first = recs[0]
        for i, rec in enumerate(recs):
            rec.start, rec.impact, rec.late = first.start, first.impact, first.late
            self._emit(
                chain,
                rec,
                limb=_limb(limb),
                piece=piece,
                string=None,
                fret=None,
                motion=f"{piece}_{limb}",
                cost=cost if i == 0 else 0.0,
            )

    # drums: feet --------------------------------------------------------------

    def _fix_foot(self, chain: _Chain, groups: list[list[_Rec]], n_groups: int) -> None:
        """One stroke per group (notes within the window of its first); the group's
        later notes are the beater's or the cymbals' bounce (a double trigger).  A
        very soft note (REBOUND_VELOCITY) that a stroke follows sooner than the limb
        could strike twice is the beater touching the head before that stroke."""
        for gi, group in enumerate(groups[:n_groups]):
            first = group[0]
            assert first.drum is not None
            t = first.note.time_s
            min_int = self.config.timing.get(first.kind).min_interval_s
            if (
                gi + 1 < len(groups)
                and all(r.note.velocity < REBOUND_VELOCITY for r in group)
                and groups[gi + 1][0].note.time_s - t < min_int - drums_mod.TIME_EPS_S
            ):
                for r in group:
                    self._emit_bounce(chain, r, first.drum.piece, chain.name)
                continue
            if chain.state is not None and t - chain.state < min_int - drums_mod.TIME_EPS_S:
                for r in group:
                    if r.note.velocity < REBOUND_VELOCITY:
                        self._emit_bounce(chain, r, first.drum.piece, chain.name)
                    else:
                        self._drop(r, "too_fast")
                continue
            chain.state = t
            now = [r for r in group if r.note.time_s - t <= GROUP_EPS_S]
            self._emit_stroke(chain, now, first.drum.piece, chain.name, 0.0)
            for r in group[len(now) :]:
                self._emit_bounce(chain, r, first.drum.piece, chain.name)

    # notes that arrive after later notes of their chain were fixed ---------------

    def _place_out_of_order(self, chain: _Chain, rec: _Rec) -> None:
        """Place ``rec`` around fixed motions without changing any of them."""
        t = rec.note.time_s
        same = [p for ft, p in chain.fixed if abs(ft - t) <= GROUP_EPS_S]
        if chain.name == "bass":
            twin = next((p for p in same if p.note == rec.played), None)
            if twin is not None:
                self._share(chain, rec, twin)
            elif same:
                self._drop(rec, "no_double_stop")
            else:
                opts = [(p,) for p in bass_mod.positions(self.config.bass, rec.played)]
                fingering = self.config.bass.fingering
                best = min(opts, key=lambda o: bass_mod.transition(chain.state, o, fingering)[0])
                cost, after = bass_mod.transition(chain.state, best, fingering)
                self._emit_bass_group(chain, [rec], [rec.played], best, cost, after)
            return
        assert rec.drum is not None
        piece = rec.drum.piece
        twin = next((p for p in same if p.piece == piece), None)
        if twin is not None:
            self._share(chain, rec, twin)
            return
        min_int = self.config.timing.get(rec.kind).min_interval_s

        def free(limb: str) -> bool:
            return all(
                p.limb != limb or abs(ft - t) >= min_int - drums_mod.TIME_EPS_S
                for ft, p in chain.fixed
            )

        if chain.name != "hands":
            if free(chain.name):
                self._emit_stroke(chain, [rec], piece, chain.name, 0.0)
            else:
                self._drop(rec, "no_free_limb")
            return
        costs = self.config.costs
        before = [(ft, p) for ft, p in chain.fixed if ft < t - GROUP_EPS_S]
        row = costs.none_row
        if before and t - before[-1][0] < self.config.timing.rest_s:
            row = costs.motions.index(before[-1][1].motion)
        choices = [
            (costs.table[row][costs.index(piece, h)], h)
            for h in (drums_mod.LEFT, drums_mod.RIGHT)
            if free(h)
        ]
        if not choices:
            self._drop(rec, "no_free_limb")
            return
        cost, hand = min(choices)
        self._emit_stroke(chain, [rec], piece, hand, cost)

    def _share(self, chain: _Chain, rec: _Rec, twin: PlannedNote) -> None:
        rec.start, rec.impact, rec.late = twin.start, twin.impact, twin.late
        self._emit(
            chain,
            rec,
            limb=twin.limb,
            piece=twin.piece,
            string=twin.string,
            fret=twin.fret,
            motion=twin.motion,
            cost=0.0,
        )


def _limb(name: str) -> Limb:
    if name == "left_hand":
        return "left_hand"
    if name == "right_hand":
        return "right_hand"
    if name == "left_foot":
        return "left_foot"
    if name == "right_foot":
        return "right_foot"
    raise ValueError(f"not a limb: {name!r}")


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
