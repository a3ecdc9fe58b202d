"""virja.clock: the session clock and NTP-style estimation."""

from __future__ import annotations

import random

from virja.clock import ClockEstimator, ClockGuard, ClockSample, SessionClock


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


# -- hostile replies (docs/reliability.md) -------------------------------------


def test_insane_samples_rejected_out_of_range_negative_or_huge_delay() -> None:
    est = ClockEstimator(max_delay_s=1.0)
    assert est.add(1000, 1 << 63, 1 << 63, 2000) is None  # outside i64
    assert est.add(1000, 5_000, 5_000 + 10**12, 2000) is None  # t2 - t1 = 1e12: delay < 0
    assert est.add(0, 0, 0, 2_000_000) is None  # a 2 s round trip
    assert est.rejected == 3 and len(est) == 0
    big = (1 << 63) - 1  # in range and ordered: a sample (the guard refuses its offset)
    assert est.add(1000, big, big, 2000) is not None


def test_one_forged_least_delay_sample_does_not_win() -> None:
    est = ClockEstimator()
    for i in range(5):  # honest: offset 0, delay 400 us
        t0 = i * 1_000_000
        est.add(t0, t0 + 200, t0 + 200, t0 + 400)
    t0 = 6_000_000  # forged: delay 0, offset +2.5 days
    est.add(t0, t0 + 216_000_000_000, t0 + 216_000_000_000, t0)
    got = est.estimate()
    assert got is not None and abs(got.offset_us) < 1000


def test_guard_applies_small_corrections_confirms_steps_and_refuses_panics() -> None:
    guard = ClockGuard(step_s=0.128, panic_s=1000.0, agree=3)
    assert guard.decide(0, 40_000.0, [40_000.0]) == (40_000, None)
    hour = 3600e6
    assert guard.decide(0, hour, [hour]) == (None, "panic")
    step = 5e6  # +5 s: a step, needs three samples that agree
    assert guard.decide(0, step, [0.0, 0.0, step]) == (None, "unconfirmed_step")
    assert guard.decide(0, step, [step, step, step]) == (5_000_000, None)
    assert guard.decide(0, float("nan"), []) == (None, "panic")
