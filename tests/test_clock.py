"""virja.clock: the session clock and NTP-style estimation."""

from __future__ import annotations

import random

from virja.clock import ClockEstimator, ClockSample, SessionClock


def test_sample_formulas() -> None:
    s = ClockSample(t0_us=1000, t1_us=6100, t2_us=6200, t3_us=1400)
    assert s.offset_us == ((6100 - 1000) + (6200 - 1400)) / 2
    assert s.delay_us == (1400 - 1000) - (6200 - 6100)


def test_session_clock_is_wall_at_start_plus_monotonic_plus_offset() -> None:
    mono = [5_000_000_000]
    clock = SessionClock(wall_ns=lambda: 1_700_000_000_000_000_000, monotonic_ns=lambda: mono[0])
    assert clock.now_us() == 1_700_000_000_000_000
    mono[0] += 2_500_000
    assert clock.now_us() == 1_700_000_000_002_500
    clock.offset_us = -500
    assert clock.now_us() == 1_700_000_000_002_000
    assert clock.local_us() == 1_700_000_000_002_500


def simulate(offset_us: float, drift_ppm: float, n: int, seed: int = 1) -> ClockEstimator:
    """Server = local + offset + drift * t; forward delay larger than return delay."""
    rng = random.Random(seed)
    est = ClockEstimator(window=64, best=8, min_span_s=10.0)
    for i in range(n):
        t0 = i * 1_000_000
        fwd = 2000 + rng.expovariate(1 / 3000)  # asymmetric: fwd path queues more
        back = 500 + rng.expovariate(1 / 300)
        t1_local = t0 + fwd
        server = lambda t: t + offset_us + drift_ppm * 1e-6 * t  # noqa: E731
        t1 = round(server(t1_local))
        t2 = t1 + 50
        t3 = round(t1_local + 50 + back)
        est.add(t0, t1, t2, t3)
    return est


def test_offset_estimated_within_half_the_least_delay() -> None:
    est = simulate(offset_us=250_000, drift_ppm=0.0, n=40)
    e = est.estimate()
    assert e is not None
    assert abs(e.offset_us - 250_000) <= e.delay_us / 2 + 1
    assert abs(e.offset_us - 250_000) < 1000
    assert e.drift_ppm == 0.0 or abs(e.drift_ppm) < 50


def test_drift_estimated_from_least_delay_samples() -> None:
    est = simulate(offset_us=-80_000, drift_ppm=100.0, n=60)
    e = est.estimate()
    assert e is not None
    assert 50 < e.drift_ppm < 150
    true_offset = -80_000 + 100e-6 * 59_000_000
    assert abs(e.offset_us - true_offset) < 1500


def test_impossible_sample_rejected() -> None:
    est = ClockEstimator()
    assert est.add(10, 0, 0, 5) is None
    assert est.estimate() is None
