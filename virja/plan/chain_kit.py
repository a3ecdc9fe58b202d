"""What the drummer's chains (hands, each foot) share: the note as a kit piece,
strokes and bounces, and placing a note that arrived out of order.

A drum chain groups notes within HAND_WINDOW_S of a group's first note (humanised
"simultaneous" hits lie 2-30 ms apart; a flam's grace note leads its main note by
15-30 ms): one decision for the group, each note at its own time.  Shared rules of
every chain: :mod:`virja.plan.chain`.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass

from virja.events import NoteOn
from virja.plan import drums as drums_mod
from virja.plan.chain import Chain, Held
from virja.plan.config import DrumNote
from virja.vocab import DrumStroke, Hand, as_limb, as_piece

HAND_WINDOW_S = 0.030
# A note this soft on the piece a limb has just struck, sooner than the limb could
# strike again, is that stroke's rebound (a beater or stick bouncing off the head
# once more), heard at its own time and played by the same stroke.
REBOUND_VELOCITY = 16

# the stroke of each (piece, limb) made so far: a stroke is frozen, so one is shared by
# every note it plays (a kit has a few dozen)
_STROKES: dict[tuple[str, str], DrumStroke] = {}


def drum_stroke(piece: str, limb: str) -> DrumStroke:
    """``DrumStroke(piece, limb)``, checked (``ValueError`` for an unknown one) and made
    once."""
    stroke = _STROKES.get((piece, limb))
    if stroke is None:
        stroke = _STROKES[(piece, limb)] = DrumStroke(as_piece(piece), as_limb(limb))
    return stroke


@dataclass(slots=True, kw_only=True)
class DrumHeld(Held):
    """A drum note the planner holds: where it goes on the kit, and the hands'
    decisions about it, each taken once (the first time it is planned)."""

    drum: DrumNote
    rebound: bool | None = None  # hands: a rebound of an earlier stroke on its piece
    to_foot: bool | None = None  # hands: a hi-hat note given to the left foot
    pin: Hand | None = None  # hands, live: the hand drawn moving for it (plan.types.HandPin)


class DrumChain(Chain[DrumHeld]):
    """A chain of the drummer's (see the module docstring)."""

    window = HAND_WINDOW_S

    @abstractmethod
    def kind(self, drum: DrumNote) -> str:
        """The timing kind (motions/timing.toml) of a stroke of this chain on ``drum``."""

    def held(self, seq: int, note: NoteOn, known_s: float, drum: DrumNote) -> DrumHeld:
        return DrumHeld(seq, "drums", note, known_s, self.kind(drum), note.note, drum=drum)

    def emit_bounce(self, rec: Held, piece: str, limb: str) -> None:
        """A note played by the rebound of a stroke of ``limb`` on ``piece`` within the
        grouping window: its own impact time, no cost of its own."""
        self.emit_stroke([rec], piece, limb, 0.0)

    def emit_stroke(self, recs: Sequence[Held], piece: str, limb: str, cost: float) -> None:
        """One stroke for ``recs`` (the same piece at once): shared motion, start and impact."""
        first = recs[0]
        stroke = drum_stroke(piece, limb)
        limb_, piece_ = stroke.limb, stroke.piece
        for i, rec in enumerate(recs):
            if i:  # the first note's own timing is the stroke's
                rec.start, rec.impact, rec.late = first.start, first.impact, first.late
            self.emit(
                rec,
                limb=limb_,
                piece=piece_,
                string=None,
                fret=None,
                motion=stroke,
                cost=cost if i == 0 else 0.0,
            )

    def limb_free(self, limb: str, t: float, min_interval_s: float) -> bool:
        """No fixed stroke of ``limb`` lies within ``min_interval_s`` of ``t``."""
        return all(
            p.limb != limb or abs(ft - t) >= min_interval_s - drums_mod.TIME_EPS_S
            for ft, p in self.fixed
        )

    def place_out_of_order(self, rec: DrumHeld) -> None:
        """A fixed stroke of the same piece at its time: shared; otherwise a stroke
        of a limb free then (:meth:`place_stroke`), or dropped (``no_free_limb``)."""
        twin = next((p for p in self.fixed_at(rec.note.time_s) if p.piece == rec.drum.piece), None)
        if twin is not None:
            self.share(rec, twin)
            return
        self.place_stroke(rec, self.ctx.config.timing.get(rec.kind).min_interval_s)

    @abstractmethod
    def place_stroke(self, rec: DrumHeld, min_interval_s: float) -> None:
        """``rec`` (out of order, no stroke to share) struck by a limb free then."""
