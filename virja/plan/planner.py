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
from virja.plan.config import DrumNote, PlanConfig, default_config
from virja.plan.timing import align
from virja.plan.types import DroppedNote, DropReason, Limb, MovedNote, PlannedNote, PlanReport
from virja.tempo import DEFAULT_SECONDS_PER_BEAT, Tempo

log = logging.getLogger(__name__)

GROUP_EPS_S = 0.001  # notes this close sound together (one group, one stroke per piece)
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


def _groups(recs: list[_Rec]) -> list[list[_Rec]]:
    out: list[list[_Rec]] = []
    for r in sorted(recs, key=lambda r: (r.note.time_s, r.seq)):
        if out and r.note.time_s - out[-1][0].note.time_s <= GROUP_EPS_S:
            out[-1].append(r)
        else:
            out.append([r])
    return out


class OnlinePlanner:
    """The scheduler, fed note by note (see the module docstring).

    ``tempo`` gives seconds per beat where no BEAT has been seen; beats given to
    :meth:`add_beat` take precedence from their time on.
    """

    def __init__(self, config: PlanConfig | None = None, *, tempo: Tempo | None = None) -> None:
        self.config = _config(config)
        self._tempo = tempo
        self._beat_times: list[float] = []  # sorted; at most MAX_BEATS_KEPT, the latest
        self._beat_spb: list[float] = []
        self._chains = {n: _Chain(n) for n in ("bass", "hands", "right_foot", "left_foot")}
        self._chains["hands"].state = drums_mod.START
        self._outbox: list[PlannedNote] = []
        self._dropped: deque[DroppedNote] = deque(maxlen=MAX_REPORTED)
        self._moved: deque[MovedNote] = deque(maxlen=MAX_REPORTED)
        self._counts: Counter[str] = Counter()
        self._seq = 0

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
            groups = _groups(chain.pending)
            self._fix(chain, groups, len(groups))
        out = sorted(self._outbox, key=lambda p: (p.start, p.time))
        self._outbox = []
        return out

    @property
    def report(self) -> PlanReport:
        """Notes dropped or moved so far."""
        return PlanReport(
            tuple(self._dropped), tuple(self._moved), tuple(sorted(self._counts.items()))
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
            rec.note.time_s,
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
            groups = _groups(chain.pending)
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
        if chain.plan is not None:
            chain.plan = chain.plan[n_groups:]
        fixed = {r.seq for g in groups[:n_groups] for r in g}
        chain.pending = [r for r in chain.pending if r.seq not in fixed]
        chain.min_start = min((r.start for r in chain.pending), default=math.inf)
        chain.last_fixed_t = groups[n_groups - 1][0].note.time_s
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
        prepared = [self._bass_group(g) for g in groups]
        if chain.plan is None:
            sol = bass_mod.solve(chain.state, [opts for _, opts in prepared])
            chain.plan = list(zip(sol.choice, sol.costs, sol.states, strict=True))
        for gi in range(n_groups):
            kept, opts = prepared[gi]
            choice, cost, state = chain.plan[gi]
            self._emit_bass_group(chain, groups[gi], kept, opts[choice], cost)
            chain.state = state

    def _emit_bass_group(
        self,
        chain: _Chain,
        group: list[_Rec],
        kept: list[int],
        option: bass_mod.BassOption,
        cost: float,
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
                motion=f"pluck_{name}_fret{f}",
                cost=0.0 if paid else cost,
            )
            paid = True

    # drums: hands -------------------------------------------------------------

    def _hand_group(self, group: list[_Rec]) -> tuple[drums_mod.HandGroup, dict[str, list[_Rec]]]:
        by_piece: dict[str, list[_Rec]] = {}
        for r in group:
            assert r.drum is not None
            by_piece.setdefault(r.drum.piece, []).append(r)

        # best priority first, then the piece heard first
        rank = {
            piece: (min(r.drum.priority for r in recs if r.drum), min(r.seq for r in recs))
            for piece, recs in by_piece.items()
        }
        pieces = sorted(by_piece, key=rank.__getitem__)
        strokes = tuple(drums_mod.Stroke(p, rank[p][0]) for p in pieces)
        return drums_mod.HandGroup(group[0].note.time_s, strokes), by_piece

    def _fix_hands(self, chain: _Chain, groups: list[list[_Rec]], n_groups: int) -> None:
        prepared = [self._hand_group(g) for g in groups]
        trimmed = [drums_mod.HandGroup(hg.time, hg.strokes[:2]) for hg, _ in prepared]
        if chain.plan is None:
            sol = drums_mod.solve(self.config.costs, self.config.timing, chain.state, trimmed)
            chain.plan = list(zip(sol.assignments, sol.stroke_costs, sol.states, strict=True))
        for gi in range(n_groups):
            hg, by_piece = prepared[gi]
            assignment, stroke_costs, state = chain.plan[gi]
            for si, stroke in enumerate(hg.strokes):
                recs = by_piece[stroke.piece]
                if si >= 2:
                    for r in recs:
                        self._drop(r, "too_many_hands")
                    continue
                hand = assignment[si]
                if hand is None:
                    for r in recs:
                        self._drop(r, "too_fast")
                    continue
                self._emit_stroke(chain, recs, stroke.piece, hand, stroke_costs[si])
            chain.state = state

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
        for group in groups[:n_groups]:
            first = group[0]
            assert first.drum is not None
            t = first.note.time_s
            min_int = self.config.timing.get(first.kind).min_interval_s
            if chain.state is not None and t - chain.state < min_int - drums_mod.TIME_EPS_S:
                for r in group:
                    self._drop(r, "too_fast")
                continue
            chain.state = t
            self._emit_stroke(chain, group, first.drum.piece, chain.name, 0.0)

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
                best = min(opts, key=lambda o: bass_mod.transition(chain.state, o)[0])
                cost = bass_mod.transition(chain.state, best)[0]
                self._emit_bass_group(chain, [rec], [rec.played], best, cost)
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
) -> tuple[list[PlannedNote], PlanReport]:
    """Plan a whole performance as the live daemon would, and the report.

    Each note is revealed at :func:`reveal_time`; in reveal order the planner is
    polled at that time and then given the note; finally flushed.
    """
    planner = OnlinePlanner(config, tempo=tempo)
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
