"""Speed of the animator, for ``virja bench`` (a figure, not a test)."""

from __future__ import annotations

import time

from virja.motion.band import BandAnimator
from virja.vocab import BASS_STRINGS, BassPluck, DrumStroke, MotionKey


class _Note:
    """A planned note with just the fields the animator reads."""

    def __init__(
        self,
        performer: str,
        motion: MotionKey,
        limb: str,
        start: float,
        impact: float,
        string: str | None = None,
        fret: int | None = None,
        piece: str | None = None,
    ) -> None:
        self.time = impact
        self.performer = performer
        self.velocity = 90
        self.note = 40
        self.limb = limb
        self.piece = piece
        self.string = string
        self.fret = fret
        self.motion = motion
        self.start = start
        self.impact = impact


def busy_animator(seconds: float = 8.0) -> BandAnimator:
    """An animator with a busy groove: 8th-note ride, snare on 2 and 4, kick, hi-hat, walking bass."""
    a = BandAnimator()
    spb = 0.5
    t = 1.0
    i = 0
    while t < seconds:
        a.add_planned(
            _Note("drums", DrumStroke("ride", "right_hand"), "right_hand", t - 0.2, t, piece="ride")
        )
        if i % 4 in (2, 6):
            a.add_planned(
                _Note(
                    "drums",
                    DrumStroke("snare", "left_hand"),
                    "left_hand",
                    t - 0.2,
                    t,
                    piece="snare",
                )
            )
            a.add_planned(
                _Note(
                    "drums",
                    DrumStroke("hihat", "left_foot"),
                    "left_foot",
                    t - 0.15,
                    t,
                    piece="hihat",
                )
            )
        if i % 2 == 0:
            a.add_planned(
                _Note(
                    "drums",
                    DrumStroke("kick", "right_foot"),
                    "right_foot",
                    t - 0.15,
                    t,
                    piece="kick",
                )
            )
            s = BASS_STRINGS[(i // 2) % 4]
            f = 1 + (i * 3) % 12
            a.add_planned(
                _Note("bass", BassPluck(s, f), "right_hand", t - 0.15, t, string=s, fret=f)
            )
        t += spb / 2
        i += 1
    return a


def pose_ms(n_frames: int = 600, fps: float = 60.0) -> float:
    """Mean milliseconds per :meth:`BandAnimator.pose` (both players) over a busy groove."""
    a = busy_animator(2.0 + n_frames / fps)
    a.pose(1.0)  # warm up
    t0 = time.perf_counter()
    for i in range(n_frames):
        a.pose(1.0 + i / fps)
    return (time.perf_counter() - t0) * 1e3 / n_frames
