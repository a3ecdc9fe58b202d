"""Planned notes for motion tests (the real PlannedNote type, built by hand)."""

from __future__ import annotations

from virja.plan.types import PlannedNote


def drum(motion: str, start: float, impact: float, velocity: int = 96) -> PlannedNote:
    piece, _, limb = (
        motion.partition("_left_") if "_left_" in motion else motion.partition("_right_")
    )
    side = "left_" if "_left_" in motion else "right_"
    return PlannedNote(
        time=impact,
        performer="drums",
        channel=9,
        note=38,
        velocity=velocity,
        limb=side + limb,
        piece=piece,
        string=None,
        fret=None,
        motion=motion,
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
        motion=f"pluck_{string}_fret{fret}",
        start=start,
        impact=impact,
        cost=0.0,
        late=False,
    )
