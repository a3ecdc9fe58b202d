"""Planned notes for motion tests (the real PlannedNote type, built by hand)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from virja.events import NoteOn
from virja.motion.band import BandAnimator
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


def pose_live(
    a: BandAnimator,
    notes: Sequence[PlannedNote],
    ts: np.ndarray,
    known_at: Callable[[PlannedNote], float] | None = None,
) -> np.ndarray:
    """Pose ``a`` frame by frame as the live window does: at each time the notes known
    by then are told (``note_known``, in ``notes``' order, when ``known_at`` is given),
    the notes started are planned (``add_planned``), and the frame is drawn and marked
    (``mark_drawn``).  ``notes`` in order of start; returns the frames drawn."""
    drawn, told, k = [], 0, 0
    for t in ts:
        while known_at is not None and told < len(notes) and known_at(notes[told]) <= t:
            n = notes[told]
            a.note_known("drums", NoteOn(n.time, n.channel, n.note, n.velocity), float(t))
            told += 1
        while k < len(notes) and notes[k].start <= t:
            a.add_planned(notes[k])
            k += 1
        drawn.append(a.local_rotations(float(t)))
        a.mark_drawn(float(t))
    return np.array(drawn)


def assert_same_frames(a: BandAnimator, ts: np.ndarray, drawn: np.ndarray) -> None:
    """Posed again now, every frame equals the one drawn then (rotations up to sign)."""
    again = a.local_rotations_many(ts)
    np.testing.assert_allclose(np.abs(np.sum(again * drawn, axis=-1)), 1.0, atol=1e-9)
