"""Reading audio for method B: any file libsndfile reads (WAV, FLAC, OGG...) to mono 8 kHz.

The paper records the accompaniment at 44.1 kHz and downsamples it to 8 kHz;
:func:`to_rate` does that with a polyphase filter
(:func:`scipy.signal.resample_poly`, which low-passes before decimating).
Samples are float64 in [-1, 1].
"""

from __future__ import annotations

from math import gcd
from pathlib import Path

import numpy as np
import numpy.typing as npt
from scipy.signal import resample_poly

from virja.errors import InputFileError

FloatArray = npt.NDArray[np.float64]

ANALYSIS_RATE_HZ = 8000
"""The paper's analysis rate: 44.1 kHz sound pressure downsampled to 8 kHz."""


def to_mono(samples: npt.ArrayLike) -> FloatArray:
    """(n,) or (n, channels) samples -> (n,) float64, the mean of the channels."""
    x = np.asarray(samples, dtype=np.float64)
    if x.ndim == 1:
        return x
    if x.ndim == 2:
        return np.asarray(x.mean(axis=1), dtype=np.float64)
    raise ValueError(f"audio must be (n,) or (n, channels), got shape {x.shape}")


def to_rate(samples: npt.ArrayLike, rate_hz: int, target_hz: int = ANALYSIS_RATE_HZ) -> FloatArray:
    """Resample mono ``samples`` from ``rate_hz`` to ``target_hz`` (polyphase, anti-aliased)."""
    x = np.asarray(samples, dtype=np.float64)
    if rate_hz <= 0 or target_hz <= 0:
        raise ValueError(f"sample rates must be positive, got {rate_hz} -> {target_hz}")
    if rate_hz == target_hz:
        return x.copy()
    g = gcd(int(rate_hz), int(target_hz))
    return np.asarray(resample_poly(x, target_hz // g, rate_hz // g), dtype=np.float64)


def read_audio(path: str | Path) -> tuple[FloatArray, int]:
    """Read an audio file: (mono float64 samples, sample rate in Hz).

    Raises :class:`~virja.errors.InputFileError` naming the file when it is
    missing, unreadable or empty.
    """
    import soundfile  # libsndfile; imported here so the rest of virja.dance never needs it

    p = Path(path)
    if not p.is_file():
        raise InputFileError(p, "no such audio file")
    try:
        data, rate = soundfile.read(str(p), dtype="float64", always_2d=True)
    except (RuntimeError, soundfile.LibsndfileError, TypeError, ValueError) as exc:
        raise InputFileError(p, f"not a readable audio file ({exc})") from exc
    if data.shape[0] == 0:
        raise InputFileError(p, "audio file has no samples")
    return to_mono(data), int(rate)


def read_audio_8k(path: str | Path) -> FloatArray:
    """Read an audio file as mono samples at :data:`ANALYSIS_RATE_HZ`."""
    x, rate = read_audio(path)
    return to_rate(x, rate, ANALYSIS_RATE_HZ)
