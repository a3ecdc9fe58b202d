"""Tests of virja.dance.ar (AR(3) by exact maximum likelihood through a Kalman filter)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from virja.dance import ar


def _simulate(a: list[float], n: int, seed: int, sigma: float = 1.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    v = sigma * rng.standard_normal(n + 1000)
    return np.asarray(lfilter([1.0], [1.0, *(-np.asarray(a))], v)[1000:])


@pytest.mark.parametrize(
    "a", [[0.5, -0.3, 0.2], [1.2, -0.6, 0.1], [-0.4, 0.2, 0.3], [2.1, -1.6, 0.45]]
)
def test_ml_recovers_known_ar3_coefficients(a: list[float]) -> None:
    y = _simulate(a, 8000, seed=11)
    fit = ar.fit_ar(y)
    assert fit.converged
    np.testing.assert_allclose(fit.coefs, a, atol=0.05)


def test_sigma2_is_estimated_on_the_original_scale() -> None:
    y = _simulate([0.5, -0.3, 0.2], 8000, seed=3, sigma=3.0)
    assert ar.fit_ar(y).sigma2 == pytest.approx(9.0, rel=0.05)


def test_sound_parameters_are_scale_invariant() -> None:
    y = _simulate([0.5, -0.3, 0.2], 2000, seed=4)
    np.testing.assert_allclose(ar.sound_parameters(y), ar.sound_parameters(1000 * y), atol=1e-4)


def test_fast_innovations_equal_the_full_kalman_recursion() -> None:
    y = _simulate([1.2, -0.6, 0.1], 200, seed=5)
    a = np.array([1.0, -0.5, 0.2])
    e1, d1 = ar.kalman_innovations(y, a, 2.0)
    e2, d2 = ar.kalman_innovations_reference(y, a, 2.0)
    np.testing.assert_allclose(e1, e2, atol=1e-10)
    np.testing.assert_allclose(d1, d2, rtol=1e-10)


def test_loglik_matches_multivariate_normal_density() -> None:
    """The Kalman log-likelihood equals log N(y; 0, Toeplitz autocovariance)."""
    from scipy.linalg import toeplitz
    from scipy.stats import multivariate_normal

    a = np.array([0.5, -0.3, 0.2])
    y = _simulate(list(a), 40, seed=6)
    # autocovariances from the stationary state covariance, extended by the AR recursion
    P = ar.stationary_cov(a, 1.5)
    gam = list(P[0, :])
    while len(gam) < len(y):
        gam.append(float(np.dot(a, gam[-1:-4:-1])))
    ref = multivariate_normal(mean=np.zeros(len(y)), cov=toeplitz(gam[: len(y)])).logpdf(y)
    assert ar.loglik(y, a, 1.5) == pytest.approx(ref, rel=1e-8)


def test_concentrated_sigma2_maximises_the_likelihood() -> None:
    y = _simulate([0.5, -0.3, 0.2], 500, seed=7)
    a = np.array([0.4, -0.2, 0.1])
    ll, s2 = ar.concentrated_loglik(y, a)
    assert ll == pytest.approx(ar.loglik(y, a, s2))
    assert ll > ar.loglik(y, a, s2 * 1.1) and ll > ar.loglik(y, a, s2 * 0.9)


def test_pacf_map_round_trips_and_is_always_stationary() -> None:
    rng = np.random.default_rng(0)
    for _ in range(50):
        r = rng.uniform(-0.999, 0.999, 3)
        a = ar.pacf_to_ar(r)
        np.testing.assert_allclose(ar.ar_to_pacf(a), r, atol=1e-9)
        assert np.max(np.abs(np.linalg.eigvals(ar.companion(a)))) < 1.0


def test_short_or_constant_series_raise_value_error() -> None:
    with pytest.raises(ValueError):
        ar.fit_ar(np.ones(100))
    with pytest.raises(ValueError):
        ar.fit_ar(np.arange(5.0))


def test_pacf_likelihood_equals_the_kalman_likelihood() -> None:
    y = _simulate([0.5, -0.3, 0.2], 300, seed=1)
    y = (y - y.mean()) / y.std()
    u = np.array([0.3, -0.2, 0.5])
    ll_k, s2_k = ar.concentrated_loglik(y, ar.pacf_to_ar(np.tanh(u)))
    ll_p, s2_p = ar.concentrated_loglik_pacf(y, u)
    assert ll_p == pytest.approx(ll_k, rel=1e-12)
    assert s2_p == pytest.approx(s2_k, rel=1e-12)


def test_pacf_likelihood_is_finite_at_the_unit_root_where_lyapunov_is_singular() -> None:
    y = np.cumsum(np.random.default_rng(0).standard_normal(200))
    ll, s2 = ar.concentrated_loglik_pacf(y / y.std(), np.array([30.0, 0.0, 0.0]))  # r1 == 1.0
    assert np.isfinite(ll) and np.isfinite(s2)


NEAR_UNIT_ROOT = {
    "ar1 0.999": [0.999, 0.0, 0.0],
    "triple root 0.99": [2.97, -2.9403, 0.970299],
    "oscillating 0.995": [0.0, 0.0, 0.985],
}


@pytest.mark.parametrize(
    "a",
    [[0.5, -0.3, 0.2], [1.2, -0.6, 0.1], [2.1, -1.6, 0.45], *NEAR_UNIT_ROOT.values()],
    ids=["plain", "smooth", "resonant", *NEAR_UNIT_ROOT],
)
def test_ml_fit_matches_or_beats_statsmodels(a: list[float]) -> None:
    """Exact ML by statsmodels' state-space ARIMA: our log-likelihood is never lower."""
    sm_arima = pytest.importorskip("statsmodels.tsa.arima.model")
    import warnings

    y = _simulate(a, 1500, seed=7)
    y = y - y.mean()
    fit = ar.fit_ar(y, demean=False)
    assert np.isfinite(fit.loglik)
    assert np.all(np.isfinite(ar.ar_to_pacf(fit.coefs)))  # stationary
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = sm_arima.ARIMA(y, order=(3, 0, 0), trend="n").fit()
    assert fit.loglik >= ref.llf - 1e-6 * abs(ref.llf)
    if fit.loglik - ref.llf < 1e-3:  # both at the same optimum: same coefficients
        np.testing.assert_allclose(fit.coefs, ref.params[:3], atol=2e-3)
    # our reported log-likelihood is the exact one at our estimate
    assert ar.loglik(y, fit.coefs, fit.sigma2) == pytest.approx(fit.loglik, rel=1e-8)


def test_random_walk_is_fitted_not_crashed() -> None:
    y = np.cumsum(np.random.default_rng(2).standard_normal(3000))
    fit = ar.fit_ar(y)
    assert np.isfinite(fit.loglik)
    assert abs(float(np.sum(fit.coefs)) - 1.0) < 0.05


@pytest.mark.parametrize(
    "y, words",
    [
        (np.ones(50), "constant"),
        (np.array([0.0, 1.0, np.nan, 2.0, 1.0, 0.0, 1.0, 2.0]), "NaN"),
        (np.arange(4.0), "at least 7"),
    ],
)
def test_unfittable_series_raise_a_clear_error(y: np.ndarray, words: str) -> None:
    with pytest.raises(ar.ARFitError, match=words):
        ar.fit_ar(y)
