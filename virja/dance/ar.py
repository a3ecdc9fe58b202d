"""AR(m) sound parameters by exact maximum likelihood (method B, m = 3).

Model: ``y_n = sum_(j=1..m) a_j y_(n-j) + v_n``, ``v_n ~ N(0, sigma^2)``.

State-space form (used by the Kalman filter): state
``x_n = (y_n, y_(n-1), ..., y_(n-m+1))``, transition the companion matrix
``F`` (first row ``a``, ones below the diagonal), state noise
``sigma^2 e1 e1^T``, observation ``y_n = e1 . x_n`` without noise, and the
filter started from the stationary covariance (``P = F P F^T + Q``).  It
yields the one-step predictions ``y_(n|n-1)`` and variances ``d_(n|n-1)`` of
the paper's log-likelihood

    l(theta) = -N/2 log 2 pi - 1/2 sum log d_(n|n-1)
               - 1/2 sum (y_n - y_(n|n-1))^2 / d_(n|n-1).

Exactness and speed: with no observation noise the state is known after m
observations, so from n = m on ``y_(n|n-1) = sum a_j y_(n-j)`` and
``d_(n|n-1) = sigma^2`` exactly.  :func:`kalman_innovations` therefore runs the
filter recursion for the first m observations and the (identical) closed
form, vectorised, for the rest; ``tests/dance/test_ar.py`` checks it against
the plain recursion over every sample.

sigma^2 is concentrated out (its ML value ``mean(e^2 / d)`` with d computed
for sigma^2 = 1), leaving an m-dimensional problem.  Stationarity is built in:
the optimiser works on unconstrained ``u``, partial autocorrelations are
``tanh(u)`` in (-1, 1) and the Durbin-Levinson recursion turns them into
``a`` (Jones 1980), so every trial point is a stationary AR.  The maximiser is
BFGS (scipy), started from Yule-Walker.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_discrete_lyapunov, toeplitz
from scipy.optimize import minimize

from virja.dance.audio import FloatArray

AR_ORDER = 3
"""The paper's order m."""


@dataclass(frozen=True)
class ARFit:
    """An ML fit: ``coefs`` (a_1..a_m), ``sigma2``, ``loglik`` and optimiser status."""

    coefs: FloatArray
    sigma2: float
    loglik: float
    n_iter: int
    converged: bool


def companion(a: FloatArray) -> FloatArray:
    """The (m, m) transition matrix of AR coefficients ``a``."""
    a = np.asarray(a, dtype=np.float64)
    m = a.size
    F = np.zeros((m, m))
    F[0, :] = a
    F[1:, :-1] = np.eye(m - 1)
    return F


def stationary_cov(a: FloatArray, sigma2: float = 1.0) -> FloatArray:
    """Stationary covariance of the AR state vector (solves P = F P F^T + Q)."""
    m = len(a)
    Q = np.zeros((m, m))
    Q[0, 0] = sigma2
    return np.asarray(solve_discrete_lyapunov(companion(a), Q), dtype=np.float64)


def kalman_innovations(
    y: FloatArray, a: FloatArray, sigma2: float = 1.0
) -> tuple[FloatArray, FloatArray]:
    """Innovations ``e_n = y_n - y_(n|n-1)`` and variances ``d_(n|n-1)``, each (N,)."""
    y = np.asarray(y, dtype=np.float64)
    a = np.asarray(a, dtype=np.float64)
    m, N = a.size, y.size
    F = companion(a)
    x = np.zeros(m)
    P = stationary_cov(a, sigma2)
    Q = np.zeros((m, m))
    Q[0, 0] = sigma2
    e = np.empty(N)
    d = np.empty(N)
    head = min(m, N)
    for n in range(head):
        if n > 0:
            x = F @ x
            P = F @ P @ F.T + Q
        d[n] = P[0, 0]
        e[n] = y[n] - x[0]
        k = P[:, 0] / d[n]
        x = x + k * e[n]
        P = P - np.outer(k, P[0, :])
    if m < N:
        # State known exactly from here on: y_(n|n-1) = sum_j a_j y_(n-j), d = sigma^2.
        pred = np.zeros(N - m)
        for j in range(1, m + 1):
            pred += a[j - 1] * y[m - j : N - j]
        e[m:] = y[m:] - pred
        d[m:] = sigma2
    return e, d


def kalman_innovations_reference(
    y: FloatArray, a: FloatArray, sigma2: float = 1.0
) -> tuple[FloatArray, FloatArray]:
    """The plain Kalman recursion over every sample (slow; the reference for tests)."""
    y = np.asarray(y, dtype=np.float64)
    m = len(a)
    F = companion(np.asarray(a, dtype=np.float64))
    Q = np.zeros((m, m))
    Q[0, 0] = sigma2
    x = np.zeros(m)
    P = stationary_cov(a, sigma2)
    e = np.empty(len(y))
    d = np.empty(len(y))
    for n in range(len(y)):
        if n > 0:
            x = F @ x
            P = F @ P @ F.T + Q
        d[n] = P[0, 0]
        e[n] = y[n] - x[0]
        k = P[:, 0] / d[n]
        x = x + k * e[n]
        P = P - np.outer(k, P[0, :])
    return e, d


def loglik(y: FloatArray, a: FloatArray, sigma2: float) -> float:
    """The paper's exact Gaussian log-likelihood l(theta) of ``y`` under AR(a, sigma2)."""
    e, d = kalman_innovations(y, a, sigma2)
    return float(
        -0.5 * len(y) * np.log(2 * np.pi) - 0.5 * np.sum(np.log(d)) - 0.5 * np.sum(e**2 / d)
    )


def concentrated_loglik(y: FloatArray, a: FloatArray) -> tuple[float, float]:
    """(max over sigma^2 of l(a, sigma^2), the maximising sigma^2)."""
    e, d = kalman_innovations(y, a, 1.0)
    N = len(y)
    s2 = float(np.mean(e**2 / d))
    s2 = max(s2, np.finfo(float).tiny)
    ll = -0.5 * N * (np.log(2 * np.pi) + 1.0 + np.log(s2)) - 0.5 * float(np.sum(np.log(d)))
    return float(ll), s2


def pacf_to_ar(r: FloatArray) -> FloatArray:
    """Partial autocorrelations in (-1, 1) -> stationary AR coefficients (Durbin-Levinson)."""
    a = np.zeros(0)
    for k, rk in enumerate(np.asarray(r, dtype=np.float64)):
        new = np.empty(k + 1)
        new[:k] = a - rk * a[::-1]
        new[k] = rk
        a = new
    return a


def ar_to_pacf(a: FloatArray) -> FloatArray:
    """Inverse of :func:`pacf_to_ar` (step-down); |r| >= 1 means non-stationary."""
    a = np.asarray(a, dtype=np.float64).copy()
    m = a.size
    r = np.zeros(m)
    for k in range(m - 1, -1, -1):
        rk = a[k]
        r[k] = rk
        if k == 0:
            break
        if abs(rk) >= 1.0:
            return np.full(m, np.nan)
        a = (a[:k] + rk * a[:k][::-1]) / (1.0 - rk * rk)
    return r


def yule_walker(y: FloatArray, m: int = AR_ORDER) -> FloatArray:
    """Yule-Walker AR(m) estimate (biased autocovariances: always stationary)."""
    y = np.asarray(y, dtype=np.float64)
    N = y.size
    c = np.array([np.dot(y[: N - k], y[k:]) / N for k in range(m + 1)])
    if c[0] <= 0:
        return np.zeros(m)
    R = toeplitz(c[:m]) + np.eye(m) * c[0] * 1e-10
    return np.asarray(np.linalg.solve(R, c[1 : m + 1]), dtype=np.float64)


def fit_ar(y: FloatArray, m: int = AR_ORDER, demean: bool = True) -> ARFit:
    """Maximum-likelihood AR(m) fit of ``y`` (BFGS over tanh-parameterised PACF).

    ``demean`` subtracts the mean first (the model has no constant).  A series
    shorter than ``2 m + 1`` samples or constant raises ValueError.
    """
    y = np.asarray(y, dtype=np.float64)
    if y.ndim != 1 or y.size < 2 * m + 1:
        raise ValueError(
            f"AR({m}) needs a 1-D series of at least {2 * m + 1} samples, got {y.shape}"
        )
    if demean:
        y = y - y.mean()
    scale = float(np.std(y))
    if not np.isfinite(scale) or scale == 0.0:
        raise ValueError("AR fit of a constant series is undefined")
    y = y / scale  # the likelihood's maximiser in a does not depend on scale

    r0 = np.clip(ar_to_pacf(yule_walker(y, m)), -0.99, 0.99)
    r0 = np.nan_to_num(r0)
    u0 = np.arctanh(r0)

    def objective(u: FloatArray) -> float:
        ll, _ = concentrated_loglik(y, pacf_to_ar(np.tanh(u)))
        return -ll / y.size

    res = minimize(objective, u0, method="BFGS", options={"gtol": 1e-7, "maxiter": 200})
    a = pacf_to_ar(np.tanh(res.x))
    ll, s2 = concentrated_loglik(y, a)
    # Back to the original scale: sigma^2 scales by scale^2, l by -N log(scale).
    return ARFit(
        coefs=a,
        sigma2=s2 * scale**2,
        loglik=float(ll - y.size * np.log(scale)),
        n_iter=int(res.nit),
        converged=bool(res.success),
    )


def sound_parameters(y: FloatArray, m: int = AR_ORDER) -> FloatArray:
    """The paper's sound parameters of a music phrase: (a_1, ..., a_m), sigma^2 dropped."""
    return fit_ar(y, m).coefs
