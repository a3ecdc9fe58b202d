"""Planned notes for motion tests (the real PlannedNote type, built by hand)."""

from __future__ import annotations

from virja.plan.types import PlannedNote
from virja.vocab import BassPluck, DrumStroke, MotionKey, as_bass_string


def drum(motion: str, start: float, impact: float, velocity: int = 96) -> PlannedNote:
    key = MotionKey.parse(motion)
    assert isinstance(key, DrumStroke)
    return PlannedNote(
        time=impact,
        performer="drums",
        channel=9,
        note=38,
        velocity=velocity,
        limb=key.limb,
        piece=key.piece,
        string=None,
        fret=None,
        motion=key,
        start=start,
        impact=impact,
        cost=0.0,
        late=False,
    )  # type: ignore[arg-type]


def bass(string: str, fret: int, start: float, impact: float, velocity: int = 96) -> PlannedNote:
    return PlannedNote(
        time=impact,
        performer="bass",
        channel=0,
        note=40,
        velocity=velocity,
        limb="right_hand",
        piece=None,
        string=string,
        fret=fret,
        motion=BassPluck(as_bass_string(string), fret),
        start=start,
        impact=impact,
        cost=0.0,
        late=False,
    )
