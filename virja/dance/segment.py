"""Cutting a capture into motion segments at beats (method B, motion segmentation).

For each part k, the angular velocity relative to its parent is taken from
consecutive *local* rotations (w x y z): ``dq = q_k(t)^-1 q_k(t+1)`` is the
step in the part's own axes, and ``omega_k(t + 1/2) = axis(dq) * angle(dq) * fps``
(rad/s, short way round).  Its derivative ``(omega(t+1/2) - omega(t-1/2)) * fps``
gives ``a_k(t) = sum over x, y, z of (d omega / dt)^2`` at frames 1..n-2 (the end
frames copy their neighbours) and

    alpha(t) = sqrt( sum_k w_k a_k(t) ),   w_k in {0, 1} by part (see PART_PATTERNS).

``alpha`` is smoothed by a local-level Kalman filter with a Rauch-Tung-Striebel
smoother (:func:`kalman_smooth`): ``x_t = x_(t-1) + w_t``, ``y_t = x_t + v_t``,
``var w / var v = q_over_r`` (default 3.0; the smoothed curve then depends only
on the ratio, not on the units of alpha; ``None`` skips smoothing).  Heavier
smoothing moves a minimum towards the side where alpha rises more slowly;
docs/dance.md has the measured trade-off that set the default.

Cut points (:func:`cut_points`): frames where smoothed alpha has a local
minimum and a beat falls within ``tolerance_frames`` (default 3 frames =
0.1 s at 30 fps).  Beats and minima are paired greedily, closest pair first,
each used once.  The motion is cut at the *minimum's* frame; the music
phrase runs between the paired *beats'* times.  Motion before the first cut
and after the last is not part of any segment.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from virja import quat
from virja.dance.audio import FloatArray

Parts = Literal["legs", "arms", "all"]
PARTS: tuple[Parts, ...] = ("legs", "arms", "all")

# Joint-name patterns (case-insensitive regular expressions, searched anywhere in
# the name) that get weight 1 for each choice of parts; every other joint gets 0.
# They cover the usual BVH namings (CMU "LeftUpLeg", "RightForeArm"; Mixamo
# "LeftHand"; "l_knee" styles).  The root (the waist) never counts as a leg or
# an arm: its rotation is relative to the world, not to a parent part.
PART_PATTERNS: dict[str, str] = {
    "legs": r"leg|thigh|knee|shin|calf|ankle|foot|toe|hip",
    "arms": r"arm|shoulder|clavicle|collar|elbow|wrist|hand|finger|thumb",
}


DEFAULT_Q_OVER_R = 3.0
"""State-to-measurement noise ratio of the alpha smoother (docs/dance.md)."""

DEFAULT_TOLERANCE_FRAMES = 3.0
"""How far (frames) a beat may be from alpha's minimum to make a cut: 0.1 s at 30 fps."""


@dataclass(frozen=True)
class CutPoint:
    """A cut: motion ``frame`` (the alpha minimum) paired with music ``beat_s``."""

    frame: int
    beat_s: float


def part_weights(joint_names: Sequence[str], parts: Parts, root: int = 0) -> FloatArray:
    """(n_joints,) weights w_k: 1 for joints of ``parts`` (``all``: every joint), else 0."""
    if parts not in PARTS:
        raise ValueError(f"parts must be one of {PARTS}, got {parts!r}")
    n = len(joint_names)
    if parts == "all":
        return np.ones(n)
    pattern = re.compile(PART_PATTERNS[parts], re.IGNORECASE)
    w = np.array([1.0 if pattern.search(name) else 0.0 for name in joint_names])
    if 0 <= root < n:
        w[root] = 0.0
    return w


def angular_velocity(local_rotations: FloatArray, fps: float) -> FloatArray:
    """(n-1, n_joints, 3) angular velocity (rad/s) of each part in its own axes."""
    q = np.asarray(local_rotations, dtype=np.float64)
    if q.ndim != 3 or q.shape[-1] != 4:
        raise ValueError(f"local rotations must be (n_frames, n_joints, 4), got {q.shape}")
    dq = quat.multiply(quat.conjugate(q[:-1]), q[1:])
    axis, ang = quat.to_axis_angle(quat.normalize(dq))
    return np.asarray(axis * ang[..., None] * fps, dtype=np.float64)


def part_acceleration(local_rotations: FloatArray, fps: float) -> FloatArray:
    """(n_frames, n_joints) a_k(t): the squared norm of d omega / dt, ends copied."""
    q = np.asarray(local_rotations, dtype=np.float64)
    if q.shape[0] < 3:
        raise ValueError(f"need at least 3 frames to differentiate twice, got {q.shape[0]}")
    omega = angular_velocity(q, fps)
    acc = np.diff(omega, axis=0) * fps
    a = np.sum(acc * acc, axis=-1)
    return np.concatenate([a[:1], a, a[-1:]], axis=0)


def mean_angular_acceleration(
    local_rotations: FloatArray, fps: float, weights: FloatArray
) -> FloatArray:
    """(n_frames,) alpha(t) = sqrt(sum_k w_k a_k(t))."""
    w = np.asarray(weights, dtype=np.float64)
    if np.any(w < 0):
        raise ValueError("part weights must be >= 0")
    return np.asarray(np.sqrt(part_acceleration(local_rotations, fps) @ w), dtype=np.float64)


def kalman_smooth(y: FloatArray, q_over_r: float = DEFAULT_Q_OVER_R) -> FloatArray:
    """Local-level Kalman filter + RTS smoother; the measurement variance is 1, state q_over_r."""
    y = np.asarray(y, dtype=np.float64)
    n = y.size
    if n == 0:
        return y.copy()
    if q_over_r <= 0:
        raise ValueError("q_over_r must be positive")
    r, q = 1.0, float(q_over_r)
    xf = np.empty(n)
    pf = np.empty(n)
    xp = np.empty(n)
    pp = np.empty(n)
    x, p = y[0], r  # start at the first sample with the measurement's variance
    for t in range(n):
        if t > 0:
            x, p = x, p + q
        xp[t], pp[t] = x, p
        k = p / (p + r)
        x = x + k * (y[t] - x)
        p = (1 - k) * p
        xf[t], pf[t] = x, p
    xs = xf.copy()
    for t in range(n - 2, -1, -1):
        g = pf[t] / pp[t + 1]
        xs[t] = xf[t] + g * (xs[t + 1] - xp[t + 1])
    return xs


def local_minima(x: FloatArray, rel_tol: float = 1e-9) -> FloatArray:
    """Interior local minima of ``x``; a flat bottom counts once, at its middle frame.

    Values within ``rel_tol * max|x|`` of each other count as equal (a still
    pose gives alpha = 0 up to rounding).  A flat run counts when both of its
    neighbours are higher; of an even-length run the earlier middle frame is
    returned.  The ends of ``x`` are never minima.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if n < 3:
        return np.zeros(0, dtype=np.int64)
    eps = rel_tol * max(float(np.max(np.abs(x))), np.finfo(float).tiny)
    out: list[int] = []
    i = 1
    while i < n - 1:
        j = i
        while j + 1 < n and abs(x[j + 1] - x[i]) <= eps:
            j += 1
        if j < n - 1 and x[i - 1] > x[i] + eps and x[j + 1] > x[i] + eps:
            out.append((i + j) // 2)
        i = j + 1
    return np.asarray(out, dtype=np.int64)


def cut_points(
    alpha: FloatArray,
    beat_times_s: Sequence[float],
    fps: float,
    tolerance_frames: float = DEFAULT_TOLERANCE_FRAMES,
) -> list[CutPoint]:
    """Pair local minima of ``alpha`` with beats within ``tolerance_frames``; sorted by frame."""
    minima = local_minima(alpha)
    beats = np.asarray(beat_times_s, dtype=np.float64)
    pairs = sorted(
        (abs(int(m) - b * fps), int(m), float(b))
        for m in minima
        for b in beats
        if abs(int(m) - b * fps) <= tolerance_frames
    )
    used_m: set[int] = set()
    used_b: set[float] = set()
    cuts: list[CutPoint] = []
    for _, m, b in pairs:
        if m in used_m or b in used_b:
            continue
        used_m.add(m)
        used_b.add(b)
        cuts.append(CutPoint(m, b))
    cuts.sort(key=lambda c: c.frame)
    # Pairs must keep the order of time on both sides; drop any that would cross.
    out: list[CutPoint] = []
    for c in cuts:
        if out and c.beat_s <= out[-1].beat_s:
            continue
        out.append(c)
    return out


def segment_motion(
    local_rotations: FloatArray,
    fps: float,
    beat_times_s: Sequence[float],
    weights: FloatArray,
    tolerance_frames: float = DEFAULT_TOLERANCE_FRAMES,
    q_over_r: float | None = DEFAULT_Q_OVER_R,
) -> tuple[list[CutPoint], FloatArray]:
    """Cut points of a capture and the (smoothed) alpha they came from."""
    alpha = mean_angular_acceleration(local_rotations, fps, weights)
    if q_over_r is not None:
        alpha = kalman_smooth(alpha, q_over_r)
    return cut_points(alpha, beat_times_s, fps, tolerance_frames), alpha
