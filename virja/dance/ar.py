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
the optimiser works on ``u``, partial autocorrelations are ``tanh(u)`` in
(-1, 1) and the Durbin-Levinson recursion turns them into ``a`` (Jones
1980), so every trial point is a stationary AR.  The fit evaluates the same
exact likelihood through the partial autocorrelations
(:func:`concentrated_loglik_pacf`: no Lyapunov solve, finite up to the unit
root), returns +inf where it cannot, and keeps the best of several
starts of a quasi-Newton method (BFGS); a series that cannot be
fitted raises :class:`ARFitError` (callers report it, never zero it).
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


class ARFitError(ValueError):
    """A series cannot be fitted (too short, constant, not finite, or no start converges)."""


def log_one_minus_tanh2(u: FloatArray) -> FloatArray:
    """``log(1 - tanh(u)^2) = -2 log cosh u``, finite for every finite ``u``."""
    u = np.abs(np.asarray(u, dtype=np.float64))
    return np.asarray(2.0 * np.log(2.0) - 2.0 * u - 2.0 * np.log1p(np.exp(-2.0 * u)))


def concentrated_loglik_pacf(y: FloatArray, u: FloatArray) -> tuple[float, float]:
    """(max over sigma^2 of l, sigma^2) for partial autocorrelations ``tanh(u)``.

    The same exact likelihood as :func:`concentrated_loglik`, with the first
    m prediction variances from the Durbin-Levinson recursion instead of a
    Lyapunov solve: ``d_n = sigma^2 / prod_(j > n) (1 - r_j^2)`` and
    ``y_(n|n-1)`` by the order-n coefficients.  ``log(1 - r^2)`` is taken in
    ``u`` (:func:`log_one_minus_tanh2`), so it stays finite as |r| -> 1 where
    the Lyapunov equation becomes singular.
    """
    y = np.asarray(y, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)
    m, N = u.size, y.size
    r = np.tanh(u)
    l1r = log_one_minus_tanh2(u)
    e = np.empty(N)
    logd = np.zeros(N)  # log d_n for sigma^2 = 1
    for n in range(min(m, N)):
        phi = pacf_to_ar(r[:n])
        e[n] = y[n] - float(np.dot(phi, y[n - 1 :: -1][:n])) if n > 0 else y[0]
        logd[n] = -float(np.sum(l1r[n:]))
    if m < N:
        a = pacf_to_ar(r)
        pred = np.zeros(N - m)
        for j in range(1, m + 1):
            pred += a[j - 1] * y[m - j : N - j]
        e[m:] = y[m:] - pred
    s2 = float(np.mean(e**2 * np.exp(-logd)))
    if not np.isfinite(s2) or s2 <= 0.0:
        return float("-inf"), float("nan")
    ll = -0.5 * N * (np.log(2 * np.pi) + 1.0 + np.log(s2)) - 0.5 * float(np.sum(logd))
    return float(ll), s2


U_BOUND = 12.0
"""|u| <= 12: |r| <= 1 - 7.6e-11, a root modulus within 1e-10 of the unit circle at most."""

N_RANDOM_STARTS = 3


def fit_ar(y: FloatArray, m: int = AR_ORDER, demean: bool = True, seed: int = 0) -> ARFit:
    """Maximum-likelihood AR(m) fit of ``y`` (quasi-Newton over tanh-parameterised PACF).

    Robustness: the objective is the exact likelihood in the partial
    autocorrelations ``r = tanh(u)`` (never at the unit root; :func:`concentrated_loglik_pacf`),
    it returns +inf where it cannot be evaluated, and the quasi-Newton method
    (BFGS, ``u`` clipped to ``|u| <= U_BOUND``) starts from Yule-Walker and from white
    noise, and, when neither converges, from ``N_RANDOM_STARTS`` seeded random
    points; the best start wins.
    ``demean`` subtracts the mean first (the model has no constant).  A series
    that cannot be fitted (shorter than ``2 m + 1``, constant, not finite, no
    start with a finite likelihood) raises :class:`ARFitError`.
    """
    y = np.asarray(y, dtype=np.float64)
    if y.ndim != 1 or y.size < 2 * m + 1:
        raise ARFitError(
            f"AR({m}) needs a 1-D series of at least {2 * m + 1} samples, got {y.shape}"
        )
    if not np.all(np.isfinite(y)):
        raise ARFitError("AR fit of a series with NaN or infinite samples")
    if demean:
        y = y - y.mean()
    scale = float(np.std(y))
    if not np.isfinite(scale) or scale == 0.0:
        raise ARFitError("AR fit of a constant series is undefined")
    y = y / scale  # the likelihood's maximiser in a does not depend on scale

    def objective(u: FloatArray) -> float:
        u = np.clip(u, -U_BOUND, U_BOUND)
        try:
            with np.errstate(all="ignore"):
                ll, _ = concentrated_loglik_pacf(y, u)
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            return float("inf")
        return -ll / y.size if np.isfinite(ll) else float("inf")

    r_yw = np.nan_to_num(np.clip(ar_to_pacf(yule_walker(y, m)), -0.999, 0.999))
    rng = np.random.default_rng(seed)
    starts = [np.arctanh(r_yw), np.zeros(m), *rng.uniform(-1.5, 1.5, (N_RANDOM_STARTS, m))]
    best_u: FloatArray | None = None
    best_f = float("inf")
    n_iter = 0
    converged = False
    for k, u0 in enumerate(starts):
        if k >= 2 and converged:  # random restarts only when neither fixed start converged
            break
        if not np.isfinite(objective(u0)):
            continue
        res = minimize(objective, u0, method="BFGS", options={"gtol": 1e-6, "maxiter": 200})
        n_iter += int(res.nit)
        if np.isfinite(res.fun) and res.fun < best_f - 1e-12:
            best_u, best_f = np.asarray(res.x), float(res.fun)
            converged = bool(res.success) or res.status == 2  # 2: precision lost at the optimum
    if best_u is None:
        raise ARFitError(f"AR({m}) fit failed: the likelihood is not finite at any start")
    best_u = np.clip(best_u, -U_BOUND, U_BOUND)
    a = pacf_to_ar(np.tanh(best_u))
    ll, s2 = concentrated_loglik_pacf(y, best_u)
    # Back to the original scale: sigma^2 scales by scale^2, l by -N log(scale).
    return ARFit(
        coefs=a,
        sigma2=s2 * scale**2,
        loglik=float(ll - y.size * np.log(scale)),
        n_iter=n_iter,
        converged=converged,
    )


def sound_parameters(y: FloatArray, m: int = AR_ORDER) -> FloatArray:
    """The paper's sound parameters of a music phrase: (a_1, ..., a_m), sigma^2 dropped."""
    return fit_ar(y, m).coefs
