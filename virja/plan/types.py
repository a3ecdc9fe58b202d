"""What the scheduler hands on: one :class:`PlannedNote` per played note, and a report.

``PlannedNote`` is the contract between the planner and the animator (and the
``virja plan --json`` / plan-log format): its fields, in order, are exactly the
JSON keys.  All times inside are session seconds (``float``); in JSON they are
seconds from the input's start (docs/architecture.md, "One time base"), and the
plan log adds ``session_time`` (:data:`LOG_KEYS`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from virja.events import NoteOn
from virja.vocab import LIMBS, BassString, Hand, Limb, MotionKey, Performer, Piece

__all__ = [
    "JSON_KEYS",
    "LIMBS",
    "DropReason",
    "DroppedNote",
    "HandPin",
    "Limb",
    "PHYSICAL_LIMITS",
    "MovedNote",
    "PlanReport",
    "PlannedNote",
]

JSON_KEYS: tuple[str, ...] = (
    "time",
    "performer",
    "channel",
    "note",
    "velocity",
    "limb",
    "piece",
    "string",
    "fret",
    "motion",
    "start",
    "impact",
    "cost",
    "late",
)
# the plan log's line: the note as ``virja plan --json`` prints it, then its session time
LOG_KEYS: tuple[str, ...] = (*JSON_KEYS, "session_time")
_TIMES = ("time", "start", "impact")


@dataclass(frozen=True)
class PlannedNote:
    """One note with the basic motion chosen to play it.

    ``time`` when it sounds; ``start`` when its motion starts; ``impact`` when
    stick or finger meets the instrument (== ``time`` unless ``late``).
    Drums: ``piece`` set, ``string``/``fret`` None.  Bass: ``string`` and
    ``fret`` set (``fret`` 0 = open string), ``piece`` None, ``limb`` is the
    plucking hand ``"right_hand"``; ``note`` is the pitch actually played
    (after any octave move, see :class:`MovedNote`).  ``cost`` is the
    transition cost this motion paid (docs/scheduler.md).
    """

    time: float
    performer: Performer
    channel: int
    note: int
    velocity: int
    limb: Limb
    piece: Piece | None
    string: BassString | None
    fret: int | None
    motion: MotionKey
    start: float
    impact: float
    cost: float
    late: bool

    @classmethod
    def of(
        cls,
        time: float,
        performer: Performer,
        channel: int,
        note: int,
        velocity: int,
        limb: Limb,
        piece: Piece | None,
        string: BassString | None,
        fret: int | None,
        motion: MotionKey,
        start: float,
        impact: float,
        cost: float,
        late: bool,
    ) -> PlannedNote:
        """The same note as ``PlannedNote(...)`` (equal, same hash), made without the
        frozen dataclass's ``object.__setattr__`` per field: the planner makes one per
        note it plans, and those calls were about a tenth of a beat's planning
        (docs/performance.md)."""
        p = object.__new__(cls)
        p.__dict__.update(
            time=time,
            performer=performer,
            channel=channel,
            note=note,
            velocity=velocity,
            limb=limb,
            piece=piece,
            string=string,
            fret=fret,
            motion=motion,
            start=start,
            impact=impact,
            cost=cost,
            late=late,
        )
        return p

    def to_json(self, origin_s: float = 0.0) -> dict[str, Any]:
        """A dict with exactly :data:`JSON_KEYS`, in that order; ``time``, ``start`` and
        ``impact`` in seconds from ``origin_s``, the session time of the input's start
        (0 for a MIDI file: its times are already from its start; a recording's first
        packet), rounded to the microsecond (the wire's resolution), so logs carry no
        float noise; the channel 1-16 (10 for drums) as every message and option names
        it (it is 0-15 inside)."""
        out = {key: getattr(self, key) for key in JSON_KEYS}
        out["motion"] = self.motion.name
        for key in _TIMES:  # the session time's microsecond, then from the origin
            out[key] = round(round(out[key], 6) - origin_s, 6)
        out["channel"] = self.channel + 1  # 1-16, as musicians and every message count
        return out

    def to_log_json(self, origin_s: float = 0.0) -> dict[str, Any]:
        """A plan-log line, :data:`LOG_KEYS`: :meth:`to_json` and ``session_time``, the
        session time at which the note sounds (Unix seconds for live and recorded
        sessions), so ``session_time - time`` is the origin."""
        out = self.to_json(origin_s)
        out["session_time"] = round(self.time, 6)
        return out

    @classmethod
    def from_json(cls, data: dict[str, Any], origin_s: float = 0.0) -> PlannedNote:
        """Inverse of :meth:`to_json` (times from ``origin_s``) and of :meth:`to_log_json`
        (its ``session_time`` gives the origin; ``origin_s`` is then not used); raises
        ``ValueError`` on missing or extra keys."""
        keys = set(data)
        if keys != set(JSON_KEYS) and keys != set(LOG_KEYS):
            missing = sorted(set(JSON_KEYS) - keys)
            extra = sorted(keys - set(LOG_KEYS))
            raise ValueError(f"planned note keys wrong: missing {missing}, unexpected {extra}")
        if "session_time" in data:
            origin_s = float(data["session_time"]) - float(data["time"])
        # back on the session clock, to the microsecond the JSON holds
        time, start, impact = (
            round(float(data[k]) + origin_s, 6) if origin_s else float(data[k]) for k in _TIMES
        )
        return cls(
            time=time,
            performer=data["performer"],
            channel=int(data["channel"]) - 1,
            note=int(data["note"]),
            velocity=int(data["velocity"]),
            limb=data["limb"],
            piece=data["piece"],
            string=data["string"],
            fret=None if data["fret"] is None else int(data["fret"]),
            motion=MotionKey.parse(str(data["motion"])),
            start=start,
            impact=impact,
            cost=float(data["cost"]),
            late=bool(data["late"]),
        )


DropReason = Literal[
    # three or more hand pieces within the grouping window (30 ms), the hi-hat not to the
    # foot: beyond two hands (an electronic kit's pad cross-talk); priority kept the others
    "three_pieces_at_once",
    # every hand that could strike it would pass the top speed of timing.toml [hand_speed]
    # (7 m/s of stick tip, the wrist over 8 m/s): beyond a drummer's hands (pad
    # cross-talk again, or an echo of the pedal); priority kept the others
    "beyond_hand_speed",
    "too_fast",  # the limb cannot strike again so soon (minimum inter-stroke time)
    "no_free_limb",  # came after later notes of its limbs were fixed, and no limb was free then
    "unmapped",  # a drum note outside the kit map
    "no_double_stop",  # a simultaneous bass note that cannot be stopped with the melody note
    "too_dense",  # more notes of its limbs around its time than anyone plays (plan.bounds)
    "planner_full",  # its limbs already had the most notes a plan may wait on (plan.bounds)
]

# what each reason means, for a reader of `virja plan`'s summary
DROP_REASON_TEXT: dict[str, str] = {
    "three_pieces_at_once": (
        "three or more hand pieces within 30 ms: beyond two hands, as an electronic "
        "kit's pad cross-talk makes"
    ),
    "beyond_hand_speed": (
        "no hand reaches it without passing 7 m/s of stick tip: beyond a drummer's "
        "hands, as an electronic kit's pad cross-talk makes"
    ),
    "too_fast": "no limb can strike again so soon, even at a stretch",
    "no_free_limb": "arrived after its limbs' later notes were fixed",
    "unmapped": "not in the kit map",
    "no_double_stop": "cannot be stopped with the melody note",
    "too_dense": "more notes around its time than anyone plays",
    "planner_full": "the plan already held the most notes it may wait on",
}

# the reasons that say the notes asked for more than a drummer's body can do (issue 15's
# one exception to "no kit note dropped": a physical impossibility)
PHYSICAL_LIMITS: frozenset[DropReason] = frozenset({"three_pieces_at_once", "beyond_hand_speed"})


@dataclass(frozen=True, slots=True)
class HandPin:
    """A drum note whose provisional hand has been drawn moving for it (live: the
    hand's motion toward it began at or before a frame already shown, since
    ``since_s``): the planner keeps that hand for it unless it cannot play the note
    in time (``OnlinePlanner.pin_hands``).  The note is named as the planner got it:
    channel (0-15), note number and time (session seconds)."""

    channel: int
    note: int
    time_s: float
    hand: Hand
    since_s: float


@dataclass(frozen=True)
class DroppedNote:
    """A note the planner did not play, and why."""

    performer: Performer
    note: NoteOn
    reason: DropReason


@dataclass(frozen=True)
class MovedNote:
    """A bass note outside the instrument's range, moved by octaves into it."""

    performer: Performer
    note: NoteOn
    played_note: int


@dataclass(frozen=True)
class PlanReport:
    """Everything the planner did not play as written.

    ``dropped`` and ``moved`` hold the most recent cases (a long-running daemon
    keeps a bounded number); ``counts``, when given, holds the totals since the
    start, which :meth:`summary` reports.  ``unplayed`` counts, per instrument
    name, the drum-channel notes that no kit drummer plays (congas, shakers,
    ...): routing sent them to nobody, so they are not drops.
    """

    dropped: tuple[DroppedNote, ...] = field(default_factory=tuple)
    moved: tuple[MovedNote, ...] = field(default_factory=tuple)
    counts: tuple[tuple[str, int], ...] | None = None
    unplayed: tuple[tuple[str, int], ...] = field(default_factory=tuple)

    def summary(self) -> dict[str, int]:
        """Counts by kind: ``{"dropped": n, "moved": m, "dropped_<reason>": k, ...}``."""
        if self.counts is not None:
            out = {"dropped": 0, "moved": 0}
            out.update(dict(self.counts))
            return out
        out = {"dropped": len(self.dropped), "moved": len(self.moved)}
        for d in self.dropped:
            key = f"dropped_{d.reason}"
            out[key] = out.get(key, 0) + 1
        return out
