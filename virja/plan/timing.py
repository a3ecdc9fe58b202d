"""Impact alignment: when a basic motion starts so its impact lands on the note.

Pure functions of the timing table (motions/timing.toml), the tempo and the
time the note became known.  See docs/scheduler.md, "Impact alignment".
"""

from __future__ import annotations

from typing import NamedTuple

from virja.plan.config import Timing

LATE_EPS_S = 1e-6


def anticipation_s(timing: Timing, kind: str, seconds_per_beat: float) -> float:
    """Impact offset of ``kind`` at a tempo: proportional to the beat, clamped.

    ``clamp(a_ref * spb / spb_ref, a_min, a_ref)`` -- never longer than at the
    reference tempo, never shorter than the smallest stroke.
    """
    mt = timing.get(kind)
    scaled = mt.anticipation_s * seconds_per_beat / timing.reference_spb
    return min(max(scaled, mt.min_anticipation_s), mt.anticipation_s)


class Alignment(NamedTuple):
    """When a note's motion starts, when it strikes, and whether that is after the note
    (a tuple: made for every note the planner takes in, cheaply)."""

    start: float
    impact: float
    late: bool


def align(
    timing: Timing, kind: str, time_s: float, known_s: float, seconds_per_beat: float
) -> Alignment:
    """Start and impact of a motion for a note at ``time_s`` known since ``known_s``.

    In time: ``start = time - anticipation``, ``impact = time``.  Too late for
    the full anticipation (``known_s > time - anticipation``): compressed, it
    starts at ``known_s`` and strikes at ``max(time, known_s + min_anticipation)``.
    """
    a = anticipation_s(timing, kind, seconds_per_beat)
    start = time_s - a
    if known_s <= start:
        return Alignment(start, time_s, False)
    shortest = timing.get(kind).min_anticipation_s
    impact = max(time_s, known_s + shortest)
    allowed = shortest if timing.immediate else 0.0  # played at once: the stroke is the norm
    return Alignment(known_s, impact, impact > time_s + allowed + LATE_EPS_S)
