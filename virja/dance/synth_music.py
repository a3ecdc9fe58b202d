"""Synthetic music for tests and evaluation: low thumps on known beats plus coloured noise.

Each beat is a decaying sine at ``thump_hz`` (60 Hz: inside the paper's
30-120 Hz beat band), like a bass drum.  Between beats runs noise coloured by
an AR(2) filter chosen per phrase, so phrases differ in their sound
parameters (the AR(3) fit of method B) and generation can be checked to
pick segments by the music.  Everything is seeded.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.signal import lfilter

from virja.dance.audio import ANALYSIS_RATE_HZ, FloatArray

# Noise colours (AR(2) coefficients of the filter 1 / (1 - c1 z^-1 - c2 z^-2)).
# Chosen far apart in their AR fit: a low rumble, white-ish noise, a high hiss.
COLOURS: tuple[tuple[float, float], ...] = ((1.6, -0.8), (0.0, 0.0), (-1.2, -0.5))


def thumps(
    beat_times_s: Sequence[float],
    duration_s: float,
    rate_hz: int = ANALYSIS_RATE_HZ,
    thump_hz: float = 60.0,
    decay_s: float = 0.08,
    amplitude: float = 1.0,
) -> FloatArray:
    """Decaying ``thump_hz`` sine bursts starting at each beat time."""
    n = int(round(duration_s * rate_hz))
    x = np.zeros(n)
    t = np.arange(n) / rate_hz
    for b in beat_times_s:
        start = int(round(b * rate_hz))
        if not 0 <= start < n:
            continue
        tt = t[start:] - t[start]
        x[start:] += amplitude * np.sin(2 * np.pi * thump_hz * tt) * np.exp(-tt / decay_s)
    return x


def coloured_noise(n: int, colour: tuple[float, float], rng: np.random.Generator) -> FloatArray:
    """``n`` samples of white noise through the AR(2) filter ``colour``, unit std."""
    burn = 200
    v = rng.standard_normal(n + burn)
    y = lfilter([1.0], [1.0, -colour[0], -colour[1]], v)[burn:]
    s = float(np.std(y))
    return np.asarray(y / s if s > 0 else y, dtype=np.float64)


def music(
    beat_times_s: Sequence[float],
    duration_s: float,
    phrase_colours: Sequence[int] | None = None,
    noise_level: float = 0.05,
    seed: int = 0,
    rate_hz: int = ANALYSIS_RATE_HZ,
) -> FloatArray:
    """Thumps on ``beat_times_s`` plus noise; phrase ``j`` (beat j to j+1) has colour
    ``COLOURS[phrase_colours[j]]`` (before the first beat and after the last: colour 1).
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration_s * rate_hz))
    x = thumps(beat_times_s, duration_s, rate_hz)
    bounds = [0, *[int(round(b * rate_hz)) for b in beat_times_s], n]
    colours = [
        1,
        *(phrase_colours if phrase_colours is not None else [1] * (len(beat_times_s) - 1)),
        1,
    ]
    for k in range(len(bounds) - 1):
        lo, hi = max(0, bounds[k]), min(n, bounds[k + 1])
        if hi > lo:
            colour = COLOURS[colours[k] % len(COLOURS)] if k < len(colours) else COLOURS[1]
            x[lo:hi] += noise_level * coloured_noise(hi - lo, colour, rng)
    return x
