"""Correcting beat intervals so their lengths match motion-segment lengths (method B, step 2).

:func:`correct_intervals` follows the paper's steps (1)-(7) literally:

(1) take the next beat interval; stop when none is left;
(2) longer than the longest segment -> (6), else (3);
(3) a segment has exactly its length -> output it (tolerance 0), back to (1);
(4) remember (interval, distance to the closest segment length) -- the tolerance;
(5) merge with the next beat interval and go to (3); no next interval -> (6).
    A merged interval longer than the longest segment also goes to (6): the
    paper's second worked example (71 > 70) stops exactly there;
(6) among the remembered pairs take those of the smallest tolerance;
(7) of several, output the shortest; continue after its last beat interval.

Policy where the paper is silent: a *single* beat interval longer than the
longest segment leaves nothing remembered at (6).  It is output on its own
with ``tolerance = span - longest`` -- the distance to the closest segment
length, as in (4) -- so generation picks among the longest segments and
stretches the choice to the span (docs/dance.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class CorrectedInterval:
    """Beat intervals ``first..last`` (0-based, inclusive) merged into one of ``span`` frames.

    ``tolerance`` is the distance from ``span`` to the closest segment length
    (0 when a segment has exactly this length).
    """

    first: int
    last: int
    span: int
    tolerance: int


def correct_intervals(
    beat_spans: Sequence[int], segment_spans: Sequence[int]
) -> list[CorrectedInterval]:
    """Merge consecutive beat intervals (lengths in frames) to match segment lengths.

    Pure; ``beat_spans`` and ``segment_spans`` are positive integers.  The
    output covers every beat interval exactly once, in order.
    """
    spans = [int(s) for s in beat_spans]
    lengths = sorted({int(s) for s in segment_spans})
    if not lengths:
        raise ValueError("no segment lengths to match")
    if any(s <= 0 for s in spans) or lengths[0] <= 0:
        raise ValueError("beat intervals and segment lengths must be positive")
    longest = lengths[-1]
    exact = set(lengths)

    def closest_distance(span: int) -> int:
        return min(abs(span - length) for length in lengths)

    out: list[CorrectedInterval] = []
    i = 0
    n = len(spans)
    while i < n:  # (1)
        remembered: list[CorrectedInterval] = []
        j = i
        span = spans[i]
        emitted = False
        if span <= longest:  # (2)
            while True:
                if span in exact:  # (3)
                    out.append(CorrectedInterval(i, j, span, 0))
                    i = j + 1
                    emitted = True
                    break
                remembered.append(CorrectedInterval(i, j, span, closest_distance(span)))  # (4)
                if j + 1 >= n:  # (5) no next interval
                    break
                j += 1
                span += spans[j]
                if span > longest:
                    break
        if emitted:
            continue
        if not remembered:  # a single interval longer than the longest segment (policy)
            out.append(CorrectedInterval(i, i, spans[i], spans[i] - longest))
            i += 1
            continue
        best = min(c.tolerance for c in remembered)  # (6)
        choice = min((c for c in remembered if c.tolerance == best), key=lambda c: c.span)  # (7)
        out.append(choice)
        i = choice.last + 1
    return out
