"""Impacts as arrays, for what rings on after them: drum heads lit, cymbals swinging,
strings vibrating (the kit and string state of :class:`virja.motion.band.BandAnimator`).

``HitTable`` keeps the impacts in time order and, per piece or string, their times
and velocities as numpy arrays (rebuilt only after an impact is added or forgotten),
so that a frame's state is a few vectorised sums, not a Python loop over the hits of
the last seconds.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Hit:
    """An impact for the kit/string state: ``what`` is a piece or a string name."""

    time: float
    what: str
    velocity: int


class HitTable:
    """Impacts in time order; per-name arrays of their times and velocities."""

    def __init__(self) -> None:
        self._hits: list[Hit] = []
        self._times: list[float] = []
        self._by_name: dict[str, tuple[list[float], np.ndarray, np.ndarray]] | None = None

    def __len__(self) -> int:
        return len(self._hits)

    def add(self, h: Hit) -> None:
        i = bisect.bisect_right(self._times, h.time)
        self._times.insert(i, h.time)
        self._hits.insert(i, h)
        self._by_name = None

    def forget_before(self, time_s: float) -> None:
        k = bisect.bisect_left(self._times, time_s)
        if k:
            del self._hits[:k]
            del self._times[:k]
            self._by_name = None

    def _window(self, name: str, t: float, span: float) -> tuple[np.ndarray, np.ndarray]:
        """``name``'s impacts in [t - span, t]: (times, velocities), in time order (ties
        as added).  The window is found by bisection in a list (cheaper than numpy for
        one time), the arrays sliced."""
        if self._by_name is None:
            lists: dict[str, tuple[list[float], list[float]]] = {}
            for h in self._hits:
                times, vels = lists.setdefault(h.what, ([], []))
                times.append(h.time)
                vels.append(float(h.velocity))
            self._by_name = {k: (a, np.array(a), np.array(b)) for k, (a, b) in lists.items()}
        found = self._by_name.get(name)
        if found is None:
            return _EMPTY, _EMPTY
        keys, time_arr, vel_arr = found
        lo = bisect.bisect_left(keys, t - span)
        hi = bisect.bisect_right(keys, t)
        return time_arr[lo:hi], vel_arr[lo:hi]

    def swings(
        self, t: float, swing: Iterable[tuple[str, float, float, float]]
    ) -> dict[str, float]:
        """Each cymbal's swing at ``t``: a damped sine per impact of the last 8 s, summed;
        ``swing`` is (piece, amplitude, decay s, frequency Hz) per cymbal."""
        out = {}
        for piece, amp, tau, freq in swing:
            times, vels = self._window(piece, t, 8.0)
            if not times.size:
                out[piece] = 0.0
                continue
            dt = t - times
            terms = amp * vels / 127 * np.exp(-dt / tau) * np.sin(2 * np.pi * freq * dt)
            out[piece] = float(terms.sum())
        return out

    def head_hits(self, t: float, pieces: Iterable[str], tau: float) -> dict[str, float]:
        """How lit each drum head is at ``t``: its loudest impact of the last ``8 tau``
        seconds, decaying over ``tau``."""
        out = {}
        for piece in pieces:
            times, vels = self._window(piece, t, 8 * tau)
            if not times.size:
                out[piece] = 0.0
                continue
            lit = vels / 127 * np.exp(-(t - times) / tau)
            out[piece] = max(float(lit.max()), 0.0)
        return out

    def strings(
        self, t: float, strings: Iterable[str], amp_m: float, decay_s: float
    ) -> dict[str, float]:
        """Each string's vibration (m) at ``t``: its latest pluck of the last
        ``8 decay_s`` seconds, decaying over ``decay_s``."""
        out = {}
        for name in strings:
            times, vels = self._window(name, t, 8 * decay_s)
            if times.size:
                out[name] = float(amp_m * vels[-1] / 127 * np.exp(-(t - times[-1]) / decay_s))
            else:
                out[name] = 0.0
        return out

    # -- many times at once (the render loops ask for chunks of frames) --------------

    def _windows(
        self, name: str, ts: np.ndarray, span: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """``name``'s impacts in [t - span, t] for each of ``ts`` (m,), padded to the widest
        window: (times (m, w), velocities (m, w), valid (m, w)), each row in time order;
        None when ``name`` has no impact at all."""
        self._window(name, 0.0, 0.0)  # builds the per-name arrays
        assert self._by_name is not None
        found = self._by_name.get(name)
        if found is None:
            return None
        _keys, time_arr, vel_arr = found
        lo = np.searchsorted(time_arr, ts - span, side="left")
        hi = np.searchsorted(time_arr, ts, side="right")
        w = int(np.max(hi - lo, initial=0))
        idx = lo[:, None] + np.arange(max(w, 1))[None, :]
        valid = idx < hi[:, None]
        idx = np.minimum(idx, time_arr.size - 1)
        return time_arr[idx], vel_arr[idx], valid

    def swings_many(
        self, ts: np.ndarray, swing: Iterable[tuple[str, float, float, float]]
    ) -> np.ndarray:
        """:meth:`swings` at each of ``ts`` (m,): (m, cymbals) in ``swing``'s order.  The
        terms are added in time order, one window position at a time, as ``swings`` adds
        them."""
        spec = list(swing)
        out = np.zeros((ts.size, len(spec)))
        for j, (piece, amp, tau, freq) in enumerate(spec):
            win = self._windows(piece, ts, 8.0)
            if win is None:
                continue
            times, vels, valid = win
            dt = ts[:, None] - times
            terms = amp * vels / 127 * np.exp(-dt / tau) * np.sin(2 * np.pi * freq * dt)
            out[:, j] = np.where(valid, terms, 0.0).sum(axis=1)
        return out

    def head_hits_many(self, ts: np.ndarray, pieces: Iterable[str], tau: float) -> np.ndarray:
        """:meth:`head_hits` at each of ``ts`` (m,): (m, pieces) in ``pieces``' order."""
        names = list(pieces)
        out = np.zeros((ts.size, len(names)))
        for j, piece in enumerate(names):
            win = self._windows(piece, ts, 8 * tau)
            if win is None:
                continue
            times, vels, valid = win
            lit = np.where(valid, vels / 127 * np.exp(-(ts[:, None] - times) / tau), -np.inf)
            out[:, j] = np.maximum(lit.max(axis=1), 0.0)
        return out

    def strings_many(
        self, ts: np.ndarray, strings: Iterable[str], amp_m: float, decay_s: float
    ) -> np.ndarray:
        """:meth:`strings` at each of ``ts`` (m,): (m, strings) in ``strings``' order."""
        names = list(strings)
        out = np.zeros((ts.size, len(names)))
        self._window("", 0.0, 0.0)  # builds the per-name arrays
        assert self._by_name is not None
        for j, name in enumerate(names):
            found = self._by_name.get(name)
            if found is None:
                continue
            _keys, time_arr, vel_arr = found
            lo = np.searchsorted(time_arr, ts - 8 * decay_s, side="left")
            hi = np.searchsorted(time_arr, ts, side="right")
            last = np.maximum(hi - 1, 0)
            value = amp_m * vel_arr[last] / 127 * np.exp(-(ts - time_arr[last]) / decay_s)
            out[:, j] = np.where(hi > lo, value, 0.0)
        return out


_EMPTY = np.zeros(0)
