"""Analytic inverse kinematics used to author the basic motions.

``two_bone`` places a hinge chain (upper arm + forearm, thigh + shin) so its
end lands exactly on a target when the target is within reach; the bend
plane is fixed by a pole point.  Rotations are w x y z quaternions, vectors
(3,) metres, world frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from virja import quat


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


# up to this many rows :func:`frames` works in Python floats (one frame at a time, the
# live window's pose: docs/performance.md, "One frame at a time, eighth round")
_FEW_FRAMES = 16


def frames(d: np.ndarray, h: np.ndarray, floor: float = 1e-12) -> np.ndarray:
    """Right-handed orthonormal frames (..., 3, 3) of rows ``d``, ``h`` (..., 3): columns
    [d, h made perpendicular to d, d x h]; ``h``'s length after that is taken as at least
    ``floor`` (0: as it is).  A few rows are worked out in Python floats with the same
    operations in the same order as the arrays, so the frames are equal either way."""
    if d.shape == h.shape and d.size <= 3 * _FEW_FRAMES:
        try:
            rows = [
                _frame_row(a, b, floor)
                for a, b in zip(d.reshape(-1, 3).tolist(), h.reshape(-1, 3).tolist(), strict=True)
            ]
        except ZeroDivisionError:  # a zero direction: the arrays' nan, as before
            pass
        else:
            return np.array(rows).reshape(d.shape + (3,))
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    h = h - np.sum(h * d, axis=-1, keepdims=True) * d
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), floor)
    return np.stack([d, h, quat.cross(d, h)], axis=-1)


def _frame_row(d: list[float], h: list[float], floor: float) -> list[float]:
    """One frame of :func:`frames`, its 9 entries row by row."""
    dx, dy, dz = d
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    dx, dy, dz = dx / n, dy / n, dz / n
    hx, hy, hz = h
    k = hx * dx + hy * dy + hz * dz
    hx, hy, hz = hx - k * dx, hy - k * dy, hz - k * dz
    m = math.sqrt(hx * hx + hy * hy + hz * hz)
    m = floor if m < floor else m
    hx, hy, hz = hx / m, hy / m, hz / m
    cx, cy, cz = dy * hz - dz * hy, dz * hx - dx * hz, dx * hy - dy * hx
    return [dx, hx, cx, dy, hy, cy, dz, hz, cz]


def _frame(direction: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    d = _unit(direction)
    h = hinge - np.dot(hinge, d) * d
    h = _unit(h)
    return np.stack([d, h, np.cross(d, h)], axis=-1)


@dataclass(frozen=True)
class TwoBoneSolution:
    """World rotations of the two bones, the elbow/knee point and whether the target was reached."""

    upper: np.ndarray  # (4,) world rotation of the first joint
    lower: np.ndarray  # (4,) world rotation of the second joint
    elbow: np.ndarray  # (3,) position of the middle joint
    end: np.ndarray  # (3,) where the chain ends (== target when reached)
    reached: bool


def two_bone(
    root: np.ndarray,
    target: np.ndarray,
    pole: np.ndarray,
    upper_len: float,
    lower_len: float,
    rest_dir: np.ndarray,
    rest_hinge: np.ndarray,
) -> TwoBoneSolution:
    """Solve a two-bone chain from ``root`` to ``target`` bending toward ``pole``.

    In the rest pose both bones point along ``rest_dir`` (world) and bend
    about ``rest_hinge``; the solution keeps that hinge: the relative rotation
    of the lower bone is a pure rotation about it.  Targets out of reach are
    clamped (``reached`` False).
    """
    to = target - root
    dist = float(np.linalg.norm(to))
    lo = abs(upper_len - lower_len) + 1e-6
    hi = upper_len + lower_len - 1e-6
    reached = lo <= dist <= hi
    d = min(max(dist, lo), hi)
    u = _unit(to)
    v = pole - root
    v = v - np.dot(v, u) * u
    if np.linalg.norm(v) < 1e-9:
        v = np.cross(u, rest_hinge)
    v = _unit(v)
    cos_a = (upper_len**2 + d**2 - lower_len**2) / (2 * upper_len * d)
    a = np.arccos(np.clip(cos_a, -1.0, 1.0))
    elbow = root + upper_len * (np.cos(a) * u + np.sin(a) * v)
    end = root + d * u
    u1 = _unit(elbow - root)
    u2 = _unit(end - elbow)
    hinge = np.cross(u1, u2)
    if np.linalg.norm(hinge) < 1e-9:
        hinge = np.cross(u1, v)
    rest = _frame(rest_dir, rest_hinge)
    upper = quat.from_matrix(_frame(u1, hinge) @ rest.T)
    lower = quat.from_matrix(_frame(u2, hinge) @ rest.T)
    return TwoBoneSolution(upper, lower, elbow, end, reached)


def aim(
    rest_dir: np.ndarray, rest_side: np.ndarray, direction: np.ndarray, side: np.ndarray
) -> np.ndarray:
    """World rotation taking ``rest_dir`` to ``direction`` and ``rest_side`` as near ``side`` as it can."""
    return quat.from_matrix(_frame(direction, side) @ _frame(rest_dir, rest_side).T)


def local_from_world(parent_world: np.ndarray, world: np.ndarray) -> np.ndarray:
    """Local rotation of a joint given its parent's world rotation and its own."""
    return quat.multiply(quat.conjugate(parent_world), world)
