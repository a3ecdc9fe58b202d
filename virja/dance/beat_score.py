"""Scoring beat times against reference beats: F-measure with a tolerance window.

:func:`match` pairs estimated and reference beats one to one, closest pairs
first, each within ``window_s`` (70 ms, the usual MIREX window); the
F-measure of :func:`beat_score` is ``2 P R / (P + R)`` with precision ``P`` = matched /
estimated and recall ``R`` = matched / reference.  :func:`beat_score` also
gives the median signed offset (estimate - reference) of the matched pairs,
the bias of a detector.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

F_WINDOW_S = 0.07


@dataclass(frozen=True)
class BeatScore:
    """``f``, ``precision``, ``recall``, ``n_est``, ``n_ref``, ``matched`` and
    ``median_offset_s`` (estimate - reference over matched pairs; nan if none)."""

    f: float
    precision: float
    recall: float
    n_est: int
    n_ref: int
    matched: int
    median_offset_s: float


def match(
    est: Sequence[float], ref: Sequence[float], window_s: float = F_WINDOW_S
) -> list[tuple[int, int]]:
    """One-to-one (est index, ref index) pairs within ``window_s``, closest first."""
    e = np.asarray(est, dtype=np.float64)
    r = np.asarray(ref, dtype=np.float64)
    if e.size == 0 or r.size == 0:
        return []
    d = np.abs(e[:, None] - r[None, :])
    ie, ir = np.nonzero(d <= window_s)
    order = np.argsort(d[ie, ir], kind="stable")
    used_e: set[int] = set()
    used_r: set[int] = set()
    pairs: list[tuple[int, int]] = []
    for k in order:
        a, b = int(ie[k]), int(ir[k])
        if a not in used_e and b not in used_r:
            used_e.add(a)
            used_r.add(b)
            pairs.append((a, b))
    return sorted(pairs)


def beat_score(
    est: Sequence[float], ref: Sequence[float], window_s: float = F_WINDOW_S
) -> BeatScore:
    """F-measure, precision, recall and bias of ``est`` against ``ref`` (seconds)."""
    pairs = match(est, ref, window_s)
    n_e, n_r, m = len(est), len(ref), len(pairs)
    p = m / n_e if n_e else 0.0
    rc = m / n_r if n_r else 0.0
    f = 2 * p * rc / (p + rc) if p + rc > 0 else 0.0
    offs = [float(est[a]) - float(ref[b]) for a, b in pairs]
    return BeatScore(f, p, rc, n_e, n_r, m, float(np.median(offs)) if offs else float("nan"))
