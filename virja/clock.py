"""The session clock (Unix time in µs) and NTP-style offset estimation.

:class:`SessionClock` is the only place in virja that reads the OS clock: Unix
time taken once at start, advanced by the monotonic clock (so it never jumps
when NTP steps the wall clock), plus an ``offset_us`` correction that the
``--clock-server`` estimate sets.

:class:`ClockEstimator` is pure: samples (t0, t1, t2, t3) of CLOCK_REQUEST /
CLOCK_REPLY exchanges in, estimated offset (server minus local) and drift out.
It takes only sane samples (inside the i64 range, ordered, a delay that is not
negative and at most ``max_delay_s``) and picks the least-delay sample among
those that agree with the median of the best, so one forged reply cannot win.

:class:`ClockGuard` decides whether an estimate may move the session clock:
small corrections at once; a step (beyond ``step_s``) only when the last
``agree`` samples all say so; never beyond ``panic_s`` from the local clock
(NTP's panic threshold), which is refused and reported (docs/reliability.md).
"""

from __future__ import annotations

import statistics
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass


class SessionClock:
    """Unix time in microseconds from a monotonic base, plus ``offset_us``."""

    def __init__(
        self,
        *,
        offset_us: int = 0,
        wall_ns: Callable[[], int] = time.time_ns,
        monotonic_ns: Callable[[], int] = time.monotonic_ns,
    ) -> None:
        self._monotonic_ns = monotonic_ns
        self._base_mono_ns = monotonic_ns()
        self._base_wall_ns = wall_ns()
        self.offset_us = offset_us

    def now_us(self) -> int:
        """Session time now, in µs since the Unix epoch."""
        elapsed_ns = self._monotonic_ns() - self._base_mono_ns
        return (self._base_wall_ns + elapsed_ns) // 1000 + self.offset_us

    def now_s(self) -> float:
        return self.now_us() / 1_000_000

    def local_us(self) -> int:
        """Session time without the offset correction (what clock samples use)."""
        return self.now_us() - self.offset_us


@dataclass(frozen=True, slots=True)
class ClockSample:
    """One exchange: offset = ((t1 - t0) + (t2 - t3)) / 2, delay = (t3 - t0) - (t2 - t1)."""

    t0_us: int
    t1_us: int
    t2_us: int
    t3_us: int

    @property
    def offset_us(self) -> float:
        return ((self.t1_us - self.t0_us) + (self.t2_us - self.t3_us)) / 2

    @property
    def delay_us(self) -> int:
        return (self.t3_us - self.t0_us) - (self.t2_us - self.t1_us)


@dataclass(frozen=True, slots=True)
class ClockEstimate:
    """Server clock minus local clock at ``at_us`` (local), and its drift.

    ``delay_us`` is the round-trip delay of the best sample; the error of the
    offset is at most half of it.
    """

    offset_us: float
    delay_us: int
    drift_ppm: float
    samples: int


I64_MIN, I64_MAX = -(1 << 63), (1 << 63) - 1


class ClockEstimator:
    """Offset and drift from the samples of least delay among the last ``window``.

    The offset is the least-delay sample's among the ``best`` least-delay ones
    that agree (within ``agree_s``) with their median offset, carried to ``at_us``
    with the drift; the drift is a least-squares line of offset over local time
    through those samples (needs ``min_span_s`` of spread, else 0).
    """

    def __init__(
        self,
        *,
        window: int = 64,
        best: int = 8,
        min_span_s: float = 10.0,
        max_delay_s: float = 1.0,
        agree_s: float = 0.128,
    ) -> None:
        if window < 1 or best < 1:
            raise ValueError("window and best must be >= 1")
        self._samples: deque[ClockSample] = deque(maxlen=window)
        self._best = best
        self._min_span_us = min_span_s * 1_000_000
        self._max_delay_us = max_delay_s * 1_000_000
        self._agree_us = agree_s * 1_000_000
        self.rejected = 0

    def add(self, t0_us: int, t1_us: int, t2_us: int, t3_us: int) -> ClockSample | None:
        """Add one exchange; returns the sample, or None when it is not sane (a time
        outside i64, t3 < t0, t2 < t1, a negative delay or one over ``max_delay_s``)."""
        ts = (t0_us, t1_us, t2_us, t3_us)
        if not all(isinstance(t, int) and I64_MIN <= t <= I64_MAX for t in ts):
            self.rejected += 1
            return None
        s = ClockSample(t0_us, t1_us, t2_us, t3_us)
        if t3_us < t0_us or t2_us < t1_us or not 0 <= s.delay_us <= self._max_delay_us:
            self.rejected += 1
            return None
        self._samples.append(s)
        return s

    def __len__(self) -> int:
        return len(self._samples)

    def recent_offsets(self, n: int) -> list[float]:
        """The offsets of the last ``n`` samples, oldest first."""
        return [s.offset_us for s in list(self._samples)[-n:]]

    def estimate(self, at_us: int | None = None) -> ClockEstimate | None:
        """The estimate at local time ``at_us`` (default: the last sample's t3)."""
        if not self._samples:
            return None
        good = sorted(self._samples, key=lambda s: s.delay_us)[: self._best]
        median = statistics.median(s.offset_us for s in good)
        good = [s for s in good if abs(s.offset_us - median) <= self._agree_us] or good
        best = good[0]
        drift = _slope([(s.t3_us, s.offset_us) for s in good], self._min_span_us)
        at = self._samples[-1].t3_us if at_us is None else at_us
        offset = best.offset_us + drift * (at - best.t3_us)
        return ClockEstimate(offset, best.delay_us, drift * 1e6, len(self._samples))


def _slope(points: list[tuple[int, float]], min_span_us: float) -> float:
    """Least-squares slope of y over x; 0 with fewer than 3 points or a short span."""
    if len(points) < 3:
        return 0.0
    xs = [p[0] for p in points]
    if max(xs) - min(xs) < min_span_us:
        return 0.0
    mx = sum(xs) / len(xs)
    my = sum(p[1] for p in points) / len(points)
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in points)
    return sxy / sxx if sxx else 0.0


class ClockGuard:
    """Whether a new offset estimate may be applied to the session clock.

    A change of at most ``step_s`` is applied at once.  A larger one (a step)
    only when each of the last ``agree`` samples' offsets is within ``step_s`` of
    the estimate.  An offset beyond ``panic_s`` (either way) is never applied.
    ``decide`` returns the offset to apply (None: keep the clock) and a reason
    for a refusal ("panic", "unconfirmed_step") or None.
    """

    def __init__(self, *, step_s: float = 0.128, panic_s: float = 1000.0, agree: int = 3) -> None:
        if not (step_s > 0 and panic_s > step_s and agree >= 1):
            raise ValueError("need step_s > 0, panic_s > step_s and agree >= 1")
        self.step_us = step_s * 1_000_000
        self.panic_us = panic_s * 1_000_000
        self.agree = agree

    def decide(
        self, current_us: int, estimate_us: float, recent: list[float]
    ) -> tuple[int | None, str | None]:
        """``recent``: the offsets of the latest samples, oldest first."""
        if not abs(estimate_us) <= self.panic_us:  # also catches nan
            return None, "panic"
        if abs(estimate_us - current_us) <= self.step_us:
            return round(estimate_us), None
        last = recent[-self.agree :]
        if len(last) >= self.agree and all(abs(o - estimate_us) <= self.step_us for o in last):
            return round(estimate_us), None
        return None, "unconfirmed_step"
