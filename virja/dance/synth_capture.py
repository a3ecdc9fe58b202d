"""Synthetic teachers: a small skeleton whose legs move in beat-aligned segments.

A :class:`Teacher` capture is built from known segment boundaries (frames).
In each segment the legs (and the waist's sway) move from one key pose to the
next along the minimum-jerk profile ``10 s^3 - 15 s^4 + 6 s^5``: velocity and
acceleration are zero at both ends, so the legs' alpha(t) is exactly 0 at
every boundary (and, by the profile's symmetry, at each segment's midpoint).
The arms swing on a slow sine unrelated to the beats, so only ``--parts
legs`` sees the boundaries cleanly.  Key poses are drawn from a *style*
(:data:`STYLES`), so teachers differ in character.  Everything is seeded.

The music beats of a teacher are the boundaries plus, inside segments of at
least 24 frames, an off-beat at ``s = 0.21`` of the segment -- where the
legs' acceleration peaks, so segmentation must not cut there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.dance.audio import FloatArray
from virja.motion.bvh import Bvh, BvhJoint

FPS = 30.0
_ROT = ("Zrotation", "Xrotation", "Yrotation")
_ROOT = ("Xposition", "Yposition", "Zposition", *_ROT)

# name, parent, offset (centimetres, y up); listed depth-first, the order BVH
# files store joints in (format_bvh writes the frame columns in list order).
SKELETON: tuple[tuple[str, int, tuple[float, float, float]], ...] = (
    ("Hips", -1, (0.0, 95.0, 0.0)),
    ("Spine", 0, (0.0, 15.0, 0.0)),
    ("Head", 1, (0.0, 45.0, 0.0)),
    ("LeftArm", 1, (18.0, 40.0, 0.0)),
    ("LeftForeArm", 3, (28.0, 0.0, 0.0)),
    ("RightArm", 1, (-18.0, 40.0, 0.0)),
    ("RightForeArm", 5, (-28.0, 0.0, 0.0)),
    ("LeftUpLeg", 0, (10.0, -5.0, 0.0)),
    ("LeftLeg", 7, (0.0, -42.0, 0.0)),
    ("LeftFoot", 8, (0.0, -42.0, 0.0)),
    ("RightUpLeg", 0, (-10.0, -5.0, 0.0)),
    ("RightLeg", 10, (0.0, -42.0, 0.0)),
    ("RightFoot", 11, (0.0, -42.0, 0.0)),
)
JOINTS = {name: i for i, (name, _, _) in enumerate(SKELETON)}

# A style: for each degree of freedom (joint, Euler axis index in ZXY order:
# 0 = Z, 1 = X, 2 = Y) the range of key-pose angles in degrees, and whether the
# left/right legs mirror each other.  Distinct on purpose: knee bends, hip
# sway, alternating kicks.
STYLES: dict[str, dict[str, object]] = {
    "bounce": {  # both knees bend together, deep, hips flex with them
        "dofs": {
            ("LeftLeg", 1): (5.0, 60.0),
            ("LeftUpLeg", 1): (-35.0, -2.0),
            ("Hips", 1): (-5.0, 5.0),
        },
        "mirror": True,
    },
    "sway": {  # legs spread and close sideways, the waist turns
        "dofs": {
            ("LeftUpLeg", 0): (-25.0, 5.0),
            ("Hips", 2): (-25.0, 25.0),
            ("LeftLeg", 1): (0.0, 10.0),
        },
        "mirror": True,
    },
    "kick": {  # one leg at a time kicks forward
        "dofs": {
            ("LeftUpLeg", 1): (-70.0, 0.0),
            ("RightUpLeg", 1): (-70.0, 0.0),
            ("LeftLeg", 1): (0.0, 40.0),
            ("RightLeg", 1): (0.0, 40.0),
        },
        "mirror": False,
    },
}

_MIRROR = {"LeftUpLeg": "RightUpLeg", "LeftLeg": "RightLeg", "LeftFoot": "RightFoot"}


@dataclass(frozen=True)
class Teacher:
    """A synthetic capture: ``bvh``, its ``boundaries`` (frames) and music ``beats_s``."""

    style: str
    bvh: Bvh
    boundaries: tuple[int, ...]
    beats_s: tuple[float, ...]


def min_jerk(s: FloatArray) -> FloatArray:
    """The minimum-jerk profile 0 -> 1 on s in [0, 1] (zero velocity and acceleration at ends)."""
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
    return np.asarray(10 * s**3 - 15 * s**4 + 6 * s**5, dtype=np.float64)


def random_boundaries(
    n_segments: int, rng: np.random.Generator, lo: int = 8, hi: int = 40, start: int = 10
) -> list[int]:
    """Boundary frames of ``n_segments`` segments of ``lo``..``hi`` frames after ``start`` lead-in frames."""
    lengths = rng.integers(lo, hi + 1, n_segments)
    return [start, *(start + np.cumsum(lengths)).tolist()]


def off_beats(boundaries: Sequence[int], min_len: int = 24, at: float = 0.21) -> list[float]:
    """Frames (fractional) of the off-beats inside segments of at least ``min_len`` frames."""
    return [
        a + at * (b - a)
        for a, b in zip(boundaries[:-1], boundaries[1:], strict=True)
        if b - a >= min_len
    ]


def key_curve(knots: Sequence[int], keys: FloatArray, n: int, hold: int) -> FloatArray:
    """(n,) angles: ``keys[k]`` held for ``hold`` frames either side of ``knots[k]``,
    minimum-jerk transitions in between; before the first and after the last
    knot the curve moves from/to the neighbouring key's mirror image so the
    first and last knots are also interior minima of acceleration.
    """
    t = np.arange(n, dtype=np.float64)
    ext_knots = [0, *knots, n - 1]
    ext_keys = [2 * keys[0] - keys[1] if len(keys) > 1 else keys[0], *keys]
    ext_keys.append(2 * keys[-1] - keys[-2] if len(keys) > 1 else keys[-1])
    curve = np.empty(n)
    for k in range(len(ext_knots) - 1):
        a, b = ext_knots[k], ext_knots[k + 1]
        ha = 0 if k == 0 else hold
        hb = 0 if k == len(ext_knots) - 2 else hold
        lo, hi = a + ha, b - hb
        seg = (t >= a) & (t <= b)
        s = (t[seg] - lo) / max(hi - lo, 1)
        curve[seg] = ext_keys[k] + (ext_keys[k + 1] - ext_keys[k]) * min_jerk(s)
    return curve


def make_teacher(
    style: str, boundaries: Sequence[int], seed: int = 0, tail: int = 8, hold: int = 2
) -> Teacher:
    """A capture of ``style`` whose leg segments end exactly on ``boundaries``.

    The legs hold each key pose for ``hold`` frames either side of its
    boundary (the dancer "hits" the beat), so alpha's minimum is a flat
    bottom centred on the boundary.  ``tail`` frames follow the last one.
    """
    if style not in STYLES:
        raise ValueError(f"unknown style {style!r}; known: {sorted(STYLES)}")
    rng = np.random.default_rng(seed)
    spec = STYLES[style]
    dofs: dict[tuple[str, int], tuple[float, float]] = spec["dofs"]  # type: ignore[assignment]
    mirror = bool(spec["mirror"])
    b = [int(x) for x in boundaries]
    n = b[-1] + tail + 1
    euler = np.zeros((n, len(SKELETON), 3))  # degrees, Z X Y
    t = np.arange(n)
    for (name, axis), (lo, hi) in dofs.items():
        keys = rng.uniform(lo, hi, len(b))
        curve = key_curve(b, keys, n, hold)
        euler[:, JOINTS[name], axis] = curve
        if mirror and name in _MIRROR:
            sign = -1.0 if axis in (0, 2) else 1.0  # sideways and twist mirror, flexion does not
            euler[:, JOINTS[_MIRROR[name]], axis] = sign * curve
    # Arms: slow sines unrelated to the beats (period 47 and 61 frames).
    phase = rng.uniform(0, 2 * np.pi, 2)
    euler[:, JOINTS["LeftArm"], 0] = -60 + 20 * np.sin(2 * np.pi * t / 47 + phase[0])
    euler[:, JOINTS["RightArm"], 0] = 60 + 20 * np.sin(2 * np.pi * t / 61 + phase[1])
    euler[:, JOINTS["LeftForeArm"], 2] = 15 * np.sin(2 * np.pi * t / 53 + phase[1])
    rotations = quat.from_euler(np.radians(euler), "ZXY")
    positions = np.broadcast_to(np.array([o for _, _, o in SKELETON]), (n, len(SKELETON), 3)).copy()
    # The waist sinks as the knees bend (cosine of the knee angle), stays in place otherwise.
    knee = np.radians(euler[:, JOINTS["LeftLeg"], 1])
    positions[:, 0, 1] = 95.0 - 42.0 * (1 - np.cos(knee))
    joints = [
        BvhJoint(
            name,
            parent,
            offset,
            _ROOT if parent < 0 else _ROT,
            (0.0, 10.0, 0.0)
            if name in ("Head",)
            else ((0.0, -5.0, 12.0) if "Foot" in name else None),
        )
        for name, parent, offset in SKELETON
    ]
    joints = [
        BvhJoint(j.name, j.parent, j.offset, j.channels, (20.0, 0.0, 0.0))
        if j.name == "LeftForeArm"
        else BvhJoint(j.name, j.parent, j.offset, j.channels, (-20.0, 0.0, 0.0))
        if j.name == "RightForeArm"
        else j
        for j in joints
    ]
    beats = sorted([float(x) for x in b] + off_beats(b))
    bvh = Bvh(joints, 1.0 / FPS, rotations, positions, source=f"<synthetic {style}>")
    return Teacher(style, bvh, tuple(b), tuple(x / FPS for x in beats))
