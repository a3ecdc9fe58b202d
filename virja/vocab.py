"""The names every layer shares: performers, limbs, drum pieces, bass strings, motions.

This module sits at the very bottom of the import graph (it imports nothing of
virja), so the router, the planner, the animator, the renderer, the exporters
and ``tools/author_motions.py`` all spell these names from here.  Each name is
a ``Literal`` whose values are the spellings of the plan's JSON, the TOML
tables and the clip files, with a tuple of all of them in a fixed order.

A motion is named by a frozen :class:`MotionKey`: a :class:`DrumStroke`
(piece and limb) or a :class:`BassPluck` (string, fret and the left hand's
position).  Its :attr:`~MotionKey.name` is what ``virja plan --json`` and the
plan log write under ``"motion"``; its clip names (:attr:`DrumStroke.clip`,
:attr:`BassPluck.pluck_clip`, :attr:`BassPluck.hold_clip`) are the files in
motions/ that animate it.  Both come from the definitions below and nowhere
else; :meth:`MotionKey.parse` reads a name back.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

# -- performers and their limbs ------------------------------------------------------

Performer = Literal["bass", "drums"]
PERFORMERS: tuple[Performer, ...] = ("bass", "drums")

Limb = Literal["left_hand", "right_hand", "left_foot", "right_foot"]
LIMBS: tuple[Limb, ...] = ("left_hand", "right_hand", "left_foot", "right_foot")
Hand = Literal["left_hand", "right_hand"]
HANDS: tuple[Hand, ...] = ("left_hand", "right_hand")
Foot = Literal["left_foot", "right_foot"]
FEET: tuple[Foot, ...] = ("left_foot", "right_foot")
# the limbs each figure moves with clips (the bassist's feet stand)
PERFORMER_LIMBS: MappingProxyType[Performer, tuple[Limb, ...]] = MappingProxyType(
    {"drums": LIMBS, "bass": HANDS}
)

# -- the drum kit ----------------------------------------------------------------------

Piece = Literal[
    "kick", "snare", "tom_high", "tom_low", "tom_floor", "hihat", "ride", "crash", "crash2"
]
DRUM_PIECES: tuple[Piece, ...] = ("kick", "snare", "tom_high", "tom_low", "tom_floor")
# crash: crash 1, front left over the hi-hat; crash2: crash 2 on the right, between the
# rack toms and the ride and higher than the ride (the TD-11's second crash, GM 57)
CYMBAL_PIECES: tuple[Piece, ...] = ("hihat", "ride", "crash", "crash2")
PIECES: tuple[Piece, ...] = DRUM_PIECES + CYMBAL_PIECES
# the pieces the hands play (either hand: the planner's cost table chooses)
HAND_PIECES: tuple[Piece, ...] = (
    "snare",
    "hihat",
    "tom_high",
    "tom_low",
    "tom_floor",
    "ride",
    "crash",
    "crash2",
)
# the pieces a foot plays, and the timing kind (motions/timing.toml) of each pedal stroke
FOOT_KINDS: MappingProxyType[tuple[Piece, Foot], str] = MappingProxyType(
    {("kick", "right_foot"): "kick", ("hihat", "left_foot"): "hihat_pedal"}
)

# -- the bass --------------------------------------------------------------------------

BassString = Literal["B", "E", "A", "D", "G", "C"]
BASS_STRINGS: tuple[BassString, ...] = ("E", "A", "D", "G")  # the four-string bass, the default
ALL_BASS_STRINGS: tuple[BassString, ...] = ("B", "E", "A", "D", "G", "C")  # low to high
# sounding MIDI note of each open string in standard tuning (methods.md: E1 A1 D2 G2;
# B0 and C3 for five and six strings; drop tunings lower a string, see motions/bass.toml)
OPEN_STRING_NOTES: MappingProxyType[str, int] = MappingProxyType(
    {"B": 23, "E": 28, "A": 33, "D": 38, "G": 43, "C": 48}
)


def as_performer(name: str) -> Performer:
    """``name`` as a :data:`Performer`; ``ValueError`` if it is none."""
    for p in PERFORMERS:
        if name == p:
            return p
    raise ValueError(f"not a performer: {name!r} (expected one of {', '.join(PERFORMERS)})")


def as_limb(name: str) -> Limb:
    """``name`` as a :data:`Limb`; ``ValueError`` if it is none."""
    for limb in LIMBS:
        if name == limb:
            return limb
    raise ValueError(f"not a limb: {name!r}")


def as_piece(name: str) -> Piece:
    """``name`` as a :data:`Piece`; ``ValueError`` if it is none."""
    for piece in PIECES:
        if name == piece:
            return piece
    raise ValueError(f"not a drum piece: {name!r} (expected one of {', '.join(PIECES)})")


def as_bass_string(name: str) -> BassString:
    """``name`` as a :data:`BassString`; ``ValueError`` if it is none."""
    for s in ALL_BASS_STRINGS:
        if name == s:
            return s
    raise ValueError(f"not a bass string: {name!r} (expected one of {' '.join(ALL_BASS_STRINGS)})")


# -- motions ---------------------------------------------------------------------------


def idle_clip(performer: Performer) -> str:
    """The clip a figure rests in between motions (``idle_drums``, ``idle_bass``)."""
    return f"idle_{performer}"


FRET_OPEN_CLIP = "fret_open"  # the left hand lifting off a string that then rings open
_PLUCK_NAME = re.compile(r"pluck_([A-Z])_fret(\d+)(?:_pos(\d+))?")


@dataclass(frozen=True)
class MotionKey:
    """The basic motion that plays one planned note (a :class:`DrumStroke` or a
    :class:`BassPluck`); ``str(key)`` is its :attr:`name`."""

    @property
    def performer(self) -> Performer:
        raise NotImplementedError

    @property
    def name(self) -> str:
        """The motion's name in the plan (``virja plan --json``, the plan log)."""
        raise NotImplementedError

    @property
    def clips(self) -> tuple[str, ...]:
        """The clip files (motions/<performer>/<clip>.bvh) this motion may use."""
        raise NotImplementedError

    def __str__(self) -> str:
        return self.name

    @staticmethod
    def parse(name: str) -> MotionKey:
        """The key whose :attr:`name` is ``name``; ``ValueError`` for any other text."""
        m = _PLUCK_NAME.fullmatch(name)
        if m is not None and m.group(1) in ALL_BASS_STRINGS:
            pos = None if m.group(3) is None else int(m.group(3))
            return BassPluck(as_bass_string(m.group(1)), int(m.group(2)), pos)
        for limb in LIMBS:
            piece, sep, rest = name.rpartition("_" + limb)
            if sep and not rest and piece in PIECES:
                return DrumStroke(as_piece(piece), limb)
        raise ValueError(
            f"not a motion name: {name!r} (expected <piece>_<limb> or pluck_<string>_fret<n>)"
        )


@dataclass(frozen=True)
class DrumStroke(MotionKey):
    """A stroke of ``limb`` on ``piece``: named ``<piece>_<limb>``, animated by the clip
    of the same name (``snare_left_hand``, ``kick_right_foot``, ``hihat_left_foot``)."""

    piece: Piece
    limb: Limb

    @property
    def performer(self) -> Performer:
        return "drums"

    @property
    def name(self) -> str:
        return f"{self.piece}_{self.limb}"

    @property
    def clip(self) -> str:
        """The stroke's clip (its name: one clip per piece and limb)."""
        return self.name

    @property
    def clips(self) -> tuple[str, ...]:
        return (self.clip,)


@dataclass(frozen=True)
class BassPluck(MotionKey):
    """A plucked bass note on ``string`` at ``fret`` (0 = open), the left hand at
    ``position`` once it has one (an open string keeps the hand where it was).

    Named ``pluck_<string>_fret<fret>`` and ``_pos<position>`` when it has one;
    animated by the right hand's ``pluck_<string>`` clip and the left hand's
    ``fret_<string>_<fret>`` hold (``fret_open`` for an open string)."""

    string: BassString
    fret: int
    position: int | None = None

    @property
    def performer(self) -> Performer:
        return "bass"

    @property
    def name(self) -> str:
        base = f"pluck_{self.string}_fret{self.fret}"
        return base if self.position is None else f"{base}_pos{self.position}"

    @property
    def pluck_clip(self) -> str:
        """The right hand's clip: plucking the string."""
        return f"pluck_{self.string}"

    @property
    def hold_clip(self) -> str:
        """The left hand's clip: stopping the string at the fret, or leaving it open."""
        return FRET_OPEN_CLIP if self.fret <= 0 else f"fret_{self.string}_{self.fret}"

    @property
    def clips(self) -> tuple[str, ...]:
        return (self.pluck_clip, self.hold_clip)


__all__ = [
    "ALL_BASS_STRINGS",
    "BASS_STRINGS",
    "CYMBAL_PIECES",
    "DRUM_PIECES",
    "FEET",
    "FOOT_KINDS",
    "FRET_OPEN_CLIP",
    "HANDS",
    "HAND_PIECES",
    "LIMBS",
    "OPEN_STRING_NOTES",
    "PERFORMERS",
    "PERFORMER_LIMBS",
    "PIECES",
    "BassPluck",
    "BassString",
    "DrumStroke",
    "Foot",
    "Hand",
    "Limb",
    "MotionKey",
    "Performer",
    "Piece",
    "as_bass_string",
    "as_limb",
    "as_performer",
    "as_piece",
    "idle_clip",
]
