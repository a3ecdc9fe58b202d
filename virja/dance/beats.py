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
from scipy.fft import next_fast_len
from scipy.ndimage import maximum_filter, median_filter
from scipy.signal import butter, hilbert, sosfiltfilt

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
    k_mad: float = 1.5  # threshold = local median + k * robust std (project's choice)
    local_window_s: float = 4.0  # window of the local median and MAD (0: whole piece)
    rel_local: float = 0.4  # threshold >= rel_local * the largest D within local_max_s
    local_max_s: float = 0.5
    rel_floor: float = 0.02  # threshold >= rel_floor * max(D) of the piece
    min_peak_mads: float = 5.0  # no beats unless max(D) > median + this many MADs
    group_frames: int = 3  # "within three consecutive frames" (paper)
    rectify: bool = False  # the paper sums signed increments
    onsets: bool = True  # time stamps at the onset (False: the frame centre)
    onset_rise: float = 0.2  # share of the envelope's rise that marks the onset
    periodicity: bool = True  # the extension (not in the paper): gaps filled on the beat period


@dataclass(frozen=True)
class BeatAnalysis:
    """Everything :func:`analyse` computes, for inspection and tests.

    ``D`` is (n_frames,) with ``D[0] = 0`` (no previous frame); ``frames`` the
    indices of the kept beats; ``times_s`` their times in seconds.
    """

    D: FloatArray
    threshold: FloatArray
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
    """median(D) + k * MAD(D) / 0.6745 of the whole piece, but at least ``rel_floor * max(D)``.

    The global rule of earlier versions, kept for comparison (``BeatParams(local_window_s=0)``).
    """
    D = np.asarray(D, dtype=np.float64)
    if D.size == 0:
        return float("inf")
    med = float(np.median(D))
    mad = float(np.median(np.abs(D - med))) / 0.6745
    peak = float(D.max())
    floor = rel_floor * peak if peak > 0 else float("inf")
    return max(med + k_mad * mad, floor, np.finfo(float).tiny)


def _odd(n: float) -> int:
    return max(3, int(round(n)) | 1)


def local_threshold(D: FloatArray, params: BeatParams) -> FloatArray:
    """Per-frame threshold: the largest of

    - ``median + k * MAD / 0.6745`` over ``local_window_s`` centred on the frame
      (follows the piece's noise floor and its changes of loudness),
    - ``rel_local * max(D)`` over ``local_max_s`` centred on the frame (a weak
      ripple beside a strong onset is not a beat of its own),
    - ``rel_floor * max(D)`` of the whole piece (silence makes no beats);

    and infinite (no beat at all) when the piece's largest ``D`` is less than
    ``min_peak_mads`` robust deviations above its median: stationary noise
    reaches 3-4, the quietest rendered jazz clip 6 (docs/dance.md).
    """
    D = np.asarray(D, dtype=np.float64)
    if D.size == 0:
        return D.copy()
    med_all = float(np.median(D))
    mad_all = float(np.median(np.abs(D - med_all))) / 0.6745
    if float(D.max()) - med_all < params.min_peak_mads * mad_all:
        return np.full(D.shape, np.inf)
    fps = params.rate_hz / params.hop
    if params.local_window_s <= 0:
        return np.full(D.shape, adaptive_threshold(D, params.k_mad, params.rel_floor))
    n = _odd(params.local_window_s * fps)
    med = median_filter(D, n, mode="nearest")
    mad = median_filter(np.abs(D - med), n, mode="nearest") / 0.6745
    near = maximum_filter(D, _odd(params.local_max_s * fps), mode="nearest")
    peak = float(D.max())
    floor = params.rel_floor * peak if peak > 0 else float("inf")
    thr = np.maximum(med + params.k_mad * mad, params.rel_local * near)
    return np.asarray(np.maximum(thr, max(floor, np.finfo(float).tiny)), dtype=np.float64)


def band_envelope(x: FloatArray, params: BeatParams = BeatParams()) -> FloatArray:
    """Amplitude envelope of the 30-120 Hz band at full rate (zero-phase band-pass, Hilbert)."""
    x = np.asarray(x, dtype=np.float64)
    if x.size < 64:
        return np.abs(x)
    sos = butter(
        4, [params.low_hz, params.high_hz], btype="bandpass", fs=params.rate_hz, output="sos"
    )
    n = x.size
    analytic = hilbert(sosfiltfilt(sos, x), N=next_fast_len(n))[:n]  # a prime n is slow
    return np.asarray(np.abs(analytic), dtype=np.float64)


def onset_times(x: FloatArray, frames: IntArray, params: BeatParams = BeatParams()) -> FloatArray:
    """Onset time (s) of each beat frame: where its low-band rise begins.

    The increment ``D_i`` compares the frames centred at ``c_(i-1)`` and
    ``c_i``; a step onset at ``t0`` gives the largest increment when
    ``c_(i-1) <= t0 <= c_i``.  Within ``[c_(i-1) - hop, c_i]`` the band's
    amplitude envelope is searched: the onset is the first instant after its
    minimum where it has made ``onset_rise`` (20 %) of its rise to the maximum
    (a time stamp at the start of the note, not at a frame centre nor at the
    synthesiser's attack peak).
    """
    frames = np.asarray(frames, dtype=np.int64)
    centre = (frames * params.hop + params.window / 2) / params.rate_hz
    if frames.size == 0:
        return centre
    env = band_envelope(x, params)
    out = np.empty(frames.size)
    r = params.rate_hz
    for j, c in enumerate(centre):
        lo = max(0, int((c - 2 * params.hop / r) * r))
        hi = min(env.size, int(c * r) + 1)
        seg = env[lo:hi]
        if seg.size < 4:
            out[j] = c - params.hop / (2 * r)
            continue
        top = int(np.argmax(seg))
        bottom = int(np.argmin(seg[: top + 1]))
        level = seg[bottom] + params.onset_rise * (seg[top] - seg[bottom])
        above = np.flatnonzero(seg[bottom : top + 1] >= level)
        at = bottom + (int(above[0]) if above.size else 0)
        out[j] = (lo + at) / r
    return out


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
    thr = local_threshold(D, params)
    cand = np.flatnonzero(thr < D).astype(np.int64)
    kept = suppress_neighbours(cand, D[cand], params.group_frames)
    if params.onsets:
        times = onset_times(x, kept, params)
    else:
        times = (kept * params.hop + params.window / 2) / params.rate_hz
    if params.periodicity:
        times = periodic_beats(times, D[kept])
    return BeatAnalysis(D=D, threshold=thr, candidates=cand, frames=kept, times_s=times)


def extract_beats(x: FloatArray, params: BeatParams = BeatParams()) -> FloatArray:
    """Beat times in seconds of mono samples ``x`` at ``params.rate_hz`` (8 kHz)."""
    return analyse(x, params).times_s


def beat_period(times_s: FloatArray, longest_s: float = 1.2) -> float:
    """The piece's beat period: the median interval between consecutive beats under
    ``longest_s``, refined by least squares on the intervals as multiples of it."""
    ioi = np.diff(np.asarray(times_s, dtype=np.float64))
    ioi = ioi[(ioi > 0) & (ioi < longest_s)]
    if ioi.size == 0:
        return float("nan")
    period = float(np.median(ioi))
    for _ in range(3):  # least squares over intervals read as whole numbers of periods
        n = np.maximum(np.round(ioi / period), 1.0)
        period = float(np.sum(ioi * n) / np.sum(n * n))
    return period


def pulse_steadiness(times_s: FloatArray, period_s: float, slack: float = 0.2) -> float:
    """Share of intervals between consecutive beats within ``slack * P`` of a multiple of ``P``."""
    ioi = np.diff(np.asarray(times_s, dtype=np.float64))
    if ioi.size == 0 or not np.isfinite(period_s) or period_s <= 0:
        return 0.0
    n = np.maximum(np.round(ioi / period_s), 1.0)
    return float(np.mean(np.abs(ioi - n * period_s) <= slack * period_s))


STEADY_SHARE = 0.6
"""The periodicity stage runs only where this share of intervals fits the period..."""

MIN_PULSE_BEATS = 16
"""...and on at least this many beats (four bars): on fewer, irregular beats fit by chance."""


def periodic_beats(
    times_s: FloatArray, strength: FloatArray, close: float = 0.6, slack: float = 0.25
) -> FloatArray:
    """The periodicity stage (an extension, not in the paper).

    Only for a steady pulse (at least ``MIN_PULSE_BEATS`` beats and
    :func:`pulse_steadiness` of the beats left after dropping >=
    ``STEADY_SHARE``; otherwise the beats are returned unchanged: music
    without a pulse keeps the paper's beats).
    With ``P`` = :func:`beat_period`: of two beats closer than ``close * P``
    the weaker is dropped (off-beat pickups, anticipations), then a gap of
    ``n * P`` (n >= 2, within ``slack * P``) between consecutive beats is
    filled with ``n - 1`` evenly spaced beats (quarters the low band did not
    sound: a two-feel bass, a waltz's empty beats).
    """
    t = np.asarray(times_s, dtype=np.float64)
    if t.size < MIN_PULSE_BEATS:
        return t
    period = beat_period(t)
    if not np.isfinite(period):
        return t
    s = np.asarray(strength, dtype=np.float64)
    kept: list[int] = []
    for j in sorted(range(t.size), key=lambda j: (-float(s[j]), float(t[j]))):
        if all(abs(t[j] - t[k]) >= close * period for k in kept):
            kept.append(j)
    beats = np.sort(t[kept])
    if pulse_steadiness(beats, period) < STEADY_SHARE:
        return t
    out = [float(beats[0])]
    for a, b in zip(beats[:-1], beats[1:], strict=True):
        n = int(round((b - a) / period))
        if n >= 2 and abs((b - a) - n * period) <= slack * period:
            out += [float(a + (b - a) * q / n) for q in range(1, n)]
        out.append(float(b))
    return np.asarray(out, dtype=np.float64)
