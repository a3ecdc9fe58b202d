"""Beat extraction from sound pressure (Aozuka and Yamamoto, method B).

Steps, with the paper's numbers and the project's choices (docs/dance.md):

1. Mono, 8 kHz (the paper's rate; :mod:`virja.dance.audio`).
2. Power spectrum ``p_i(f) = |FFT(hann * frame_i)|^2`` of frames of 64 ms
   (512 samples at 8 kHz, the paper's window).  The hop is *our* choice:
   32 ms (256 samples, half the window), so a beat is located to +-16 ms.
3. Increment ``d_i(f) = p_i(f) - p_(i-1)(f)``.
4. ``D_i = sum of d_i(f) over 30 Hz <= f <= 120 Hz``.  At 8 kHz / 512 the bins
   are 15.625 Hz apart, so the band is bins 2-7 (31.25-109.4 Hz).  The paper
   sums the signed increments and so do we (``rectify=False``); decays then
   pull D_i below zero, which the threshold never admits anyway.
5. Threshold (the paper gives none): ``D_i > median(D) + k * MAD(D) / 0.6745``
   with ``k = 4`` and never below ``rel_floor`` (5 %) of max(D).  Median and
   MAD ignore the few large onsets, so the threshold follows the noise floor
   of the piece rather than its loudest beat; the floor keeps near-silent
   pieces (MAD ~ 0) from turning every ripple into a beat.
6. Candidates within three consecutive frames (``|i - j| <= 2``): keep only the
   one with the largest D_i (greedy, strongest first).

A beat's time is the centre of its frame: ``(i * hop + window / 2) / rate``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from virja.dance.audio import ANALYSIS_RATE_HZ, FloatArray

IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class BeatParams:
    """Parameters of :func:`extract_beats` (defaults: the paper's where it gives them)."""

    rate_hz: int = ANALYSIS_RATE_HZ
    window: int = 512  # 64 ms at 8 kHz (paper)
    hop: int = 256  # 32 ms (project's choice: half the window)
    low_hz: float = 30.0  # band of the paper
    high_hz: float = 120.0
    k_mad: float = 4.0  # threshold = median + k * robust std (project's choice)
    rel_floor: float = 0.05  # threshold >= rel_floor * max(D) (project's choice)
    group_frames: int = 3  # "within three consecutive frames" (paper)
    rectify: bool = False  # the paper sums signed increments


@dataclass(frozen=True)
class BeatAnalysis:
    """Everything :func:`analyse` computes, for inspection and tests.

    ``D`` is (n_frames,) with ``D[0] = 0`` (no previous frame); ``frames`` the
    indices of the kept beats; ``times_s`` their times in seconds.
    """

    D: FloatArray
    threshold: float
    candidates: IntArray
    frames: IntArray
    times_s: FloatArray


def power_spectra(x: FloatArray, params: BeatParams = BeatParams()) -> FloatArray:
    """(n_frames, window // 2 + 1) power spectra of Hann-windowed frames of ``x``.

    The signal is zero-padded at the end to fill its last frame; a signal
    shorter than one window gives one frame.
    """
    x = np.asarray(x, dtype=np.float64)
    w, h = params.window, params.hop
    n_frames = 1 + max(0, int(np.ceil((len(x) - w) / h)))
    padded = np.zeros((n_frames - 1) * h + w)
    padded[: len(x)] = x
    idx = np.arange(w)[None, :] + h * np.arange(n_frames)[:, None]
    frames = padded[idx] * np.hanning(w)[None, :]
    spec = np.fft.rfft(frames, axis=1)
    return np.asarray(spec.real**2 + spec.imag**2, dtype=np.float64)


def band_increment(x: FloatArray, params: BeatParams = BeatParams()) -> FloatArray:
    """D_i: the increment of power from frame i-1 to i summed over the low band."""
    p = power_spectra(x, params)
    freqs = np.fft.rfftfreq(params.window, 1.0 / params.rate_hz)
    band = (freqs >= params.low_hz) & (freqs <= params.high_hz)
    d = np.diff(p[:, band], axis=0)
    if params.rectify:
        d = np.maximum(d, 0.0)
    out = np.zeros(p.shape[0])
    out[1:] = d.sum(axis=1)
    return out


def adaptive_threshold(D: FloatArray, k_mad: float, rel_floor: float) -> float:
    """median(D) + k * MAD(D) / 0.6745, but at least ``rel_floor * max(D)`` and > 0."""
    D = np.asarray(D, dtype=np.float64)
    if D.size == 0:
        return float("inf")
    med = float(np.median(D))
    mad = float(np.median(np.abs(D - med))) / 0.6745
    peak = float(D.max())
    floor = rel_floor * peak if peak > 0 else float("inf")
    return max(med + k_mad * mad, floor, np.finfo(float).tiny)


def suppress_neighbours(frames: IntArray, strength: FloatArray, group: int) -> IntArray:
    """Keep, of candidates closer than ``group`` frames, only the strongest.

    "Within three consecutive frames" means frame distance <= group - 1.
    Greedy: strongest first, a candidate is dropped when a kept one is that
    close.  Ties go to the earlier frame.  Returns sorted frame indices.
    """
    frames = np.asarray(frames, dtype=np.int64)
    order = sorted(range(len(frames)), key=lambda j: (-float(strength[j]), int(frames[j])))
    kept: list[int] = []
    for j in order:
        f = int(frames[j])
        if all(abs(f - k) > group - 1 for k in kept):
            kept.append(f)
    return np.asarray(sorted(kept), dtype=np.int64)


def analyse(x: FloatArray, params: BeatParams = BeatParams()) -> BeatAnalysis:
    """Run every step on mono samples at ``params.rate_hz``."""
    D = band_increment(x, params)
    thr = adaptive_threshold(D, params.k_mad, params.rel_floor)
    cand = np.flatnonzero(thr < D).astype(np.int64)
    kept = suppress_neighbours(cand, D[cand], params.group_frames)
    times = (kept * params.hop + params.window / 2) / params.rate_hz
    return BeatAnalysis(D=D, threshold=thr, candidates=cand, frames=kept, times_s=times)


def extract_beats(x: FloatArray, params: BeatParams = BeatParams()) -> FloatArray:
    """Beat times in seconds of mono samples ``x`` at ``params.rate_hz`` (8 kHz)."""
    return analyse(x, params).times_s
