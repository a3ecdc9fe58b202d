"""Speed of beat extraction and AR(3) fitting on this machine (a benchmark, not a test).

``run()`` returns figures in seconds and real-time factors; ``tools/dance_eval.py``
and ``virja bench`` may print them.  The time source is passed in (default
:func:`time.perf_counter`) so library code never reads a clock by itself.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from scipy.signal import lfilter

from virja.dance.ar import fit_ar
from virja.dance.beats import extract_beats
from virja.dance.synth_music import music


def _best_of(fn: Callable[[], object], clock: Callable[[], float], repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


def run(clock: Callable[[], float] = time.perf_counter, repeat: int = 3) -> dict[str, float]:
    """Time beat extraction on 60 s of 8 kHz music and AR(3) fits of 1 s and 4 s phrases."""
    rng = np.random.default_rng(0)
    beats = np.cumsum(rng.uniform(0.3, 1.0, 100))
    beats = beats[beats < 59.5]
    x = music(beats.tolist(), 60.0, seed=0)
    t_beats = _best_of(lambda: extract_beats(x), clock, repeat)
    v = rng.standard_normal(40000)
    y = lfilter([1.0], [1.0, -0.5, 0.3, -0.2], v)
    t_ar1 = _best_of(lambda: fit_ar(y[:8000]), clock, repeat)
    t_ar4 = _best_of(lambda: fit_ar(y[:32000]), clock, repeat)
    return {
        "beats_60s_audio_s": t_beats,
        "beats_realtime_factor": 60.0 / t_beats,
        "ar3_fit_1s_phrase_s": t_ar1,
        "ar3_fit_4s_phrase_s": t_ar4,
    }
