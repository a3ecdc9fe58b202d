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
    return aligned(_offsets(timing, kind, seconds_per_beat), time_s, known_s)


def aligned(offsets: tuple[float, float, float], time_s: float, known_s: float) -> Alignment:
    """:func:`align` given its kind's and tempo's :func:`offsets` (the chains keep
    those per kind and tempo, and align every note they take in with this)."""
    a, shortest, allowed = offsets
    start = time_s - a
    if known_s <= start:
        return _new(Alignment, (start, time_s, False))
    impact = max(time_s, known_s + shortest)
    return _new(Alignment, (known_s, impact, impact > time_s + allowed + LATE_EPS_S))


# made as the named tuple's own constructor makes it, without its Python-level frame
# (align runs for every note the planner takes in)
_new = tuple.__new__


# per (kind, seconds per beat): the anticipation, the shortest one and the lateness
# allowed, for the last timing used (matched by identity, as virja.plan.drums keeps its
# compiled options; a timing is never changed); reading the global once makes it safe
# across threads
_OFFSETS_LIMIT = 4096  # a session has a few kinds at a few tempi
_offsets_cache: tuple[Timing, dict[tuple[str, float], tuple[float, float, float]]] | None = None


def _offsets(timing: Timing, kind: str, seconds_per_beat: float) -> tuple[float, float, float]:
    """:func:`anticipation_s`, ``min_anticipation_s`` and what :func:`align` allows a
    note played at once (the shortest stroke, else 0), worked out once per kind and tempo."""
    global _offsets_cache
    entry = _offsets_cache
    if entry is None or entry[0] is not timing:
        entry = _offsets_cache = (timing, {})
    key = (kind, seconds_per_beat)
    found = entry[1].get(key)
    if found is None:
        if len(entry[1]) >= _OFFSETS_LIMIT:
            entry[1].clear()
        found = entry[1][key] = offsets(timing, kind, seconds_per_beat)
    return found


def offsets(timing: Timing, kind: str, seconds_per_beat: float) -> tuple[float, float, float]:
    """:func:`anticipation_s`, ``min_anticipation_s`` and what :func:`align` allows a
    note played at once (the shortest stroke, else 0)."""
    shortest = timing.get(kind).min_anticipation_s
    # played at once: the stroke is the norm
    allowed = shortest if timing.immediate else 0.0
    return (anticipation_s(timing, kind, seconds_per_beat), shortest, allowed)
