"""Quaternions as numpy arrays: one convention for the whole project.

Every quaternion is an array whose last axis has 4 entries in the order
**w x y z** (scalar first), float64, unit length, shape ``(..., 4)``.  A
quaternion ``q`` rotates a vector ``v`` by ``q v q*`` (active rotation,
right-handed, angles in radians).  ``multiply(a, b)`` applies ``b`` first and
then ``a`` (like matrices: ``to_matrix(multiply(a, b)) == A @ B``).

Everything broadcasts over leading axes, so ``(n_frames, n_joints, 4)`` arrays
go through in one call.  ``slerp`` is our own: it takes the short way round
(flips the sign of ``b`` when ``dot(a, b) < 0``) *also* in its near-parallel
fallback, unlike ``pyrr.quaternion.slerp`` (see docs/motion.md and
tests/test_quat.py).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

F = NDArray[np.float64]

_AXES = {"X": 0, "Y": 1, "Z": 2}
# below this angle (radians) between a and b, slerp falls back to normalised lerp
_SLERP_LINEAR_BELOW = 1e-6
# up to this many quaternions (or matrices) a call is worked out in Python floats: a
# handful of numbers cost less so than through a numpy call per operation (the live
# window poses one frame at a time; docs/performance.md, "One frame at a time, eighth
# round").  The same IEEE operations in the same order, so the results are equal.
_FEW = 16


def asquat(q: ArrayLike) -> F:
    """``q`` as a float64 array with a last axis of 4 (w x y z); raises ValueError otherwise."""
    a = np.asarray(q, dtype=np.float64)
    if a.shape[-1:] != (4,):
        raise ValueError(f"quaternion arrays need a last axis of 4 (w x y z), got shape {a.shape}")
    return a


def identity(shape: tuple[int, ...] = ()) -> F:
    """Identity quaternions of shape ``shape + (4,)``."""
    q = np.zeros(shape + (4,), dtype=np.float64)
    q[..., 0] = 1.0
    return q


def normalize(q: ArrayLike) -> F:
    """Unit quaternions; a zero quaternion becomes the identity."""
    a = asquat(q)
    if a.size <= 4 * _FEW:
        return np.array([_unit4(r) for r in a.reshape(-1, 4).tolist()]).reshape(a.shape)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    out = np.where(n > 1e-300, a / np.where(n > 1e-300, n, 1.0), identity(a.shape[:-1]))
    return out


def _unit4(r: list[float]) -> list[float]:
    """One row of :func:`normalize` in Python floats."""
    w, x, y, z = r
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if not n > 1e-300:
        return [1.0, 0.0, 0.0, 0.0]
    return [w / n, x / n, y / n, z / n]


def conjugate(q: ArrayLike) -> F:
    """The conjugate (the inverse of a unit quaternion)."""
    a = asquat(q).copy()
    a[..., 1:] *= -1.0
    return a


def inverse(q: ArrayLike) -> F:
    """The inverse ``q^-1`` (``conjugate / |q|^2``)."""
    a = asquat(q)
    return conjugate(a) / np.sum(a * a, axis=-1, keepdims=True)


def multiply(a: ArrayLike, b: ArrayLike) -> F:
    """Hamilton product ``a * b`` (rotate by ``b`` first, then ``a``); broadcasts."""
    qa = asquat(a)
    qb = asquat(b)
    if qa.size <= 4 * _FEW and qb.size <= 4 * _FEW:
        return _multiply_few(qa, qb)
    aw, ax, ay, az = qa[..., 0], qa[..., 1], qa[..., 2], qa[..., 3]
    bw, bx, by, bz = qb[..., 0], qb[..., 1], qb[..., 2], qb[..., 3]
    out = np.empty(np.broadcast_shapes(qa.shape, qb.shape), dtype=np.float64)
    out[..., 0] = aw * bw - ax * bx - ay * by - az * bz
    out[..., 1] = aw * bx + ax * bw + ay * bz - az * by
    out[..., 2] = aw * by - ax * bz + ay * bw + az * bx
    out[..., 3] = aw * bz + ax * by - ay * bx + az * bw
    return out


def _multiply_few(qa: F, qb: F) -> F:
    """:func:`multiply` of a few quaternions in Python floats (the same operations)."""
    shape = _broadcast(qa.shape, qb.shape)
    ra, rb = qa.reshape(-1, 4).tolist(), qb.reshape(-1, 4).tolist()
    n = max(len(ra), len(rb))
    if n != len(ra) or n != len(rb):  # broadcast: repeat to the output's rows
        ra = np.broadcast_to(qa, shape).reshape(-1, 4).tolist()
        rb = np.broadcast_to(qb, shape).reshape(-1, 4).tolist()
    out = []
    for (aw, ax, ay, az), (bw, bx, by, bz) in zip(ra, rb, strict=True):
        out.append(
            [
                aw * bw - ax * bx - ay * by - az * bz,
                aw * bx + ax * bw + ay * bz - az * by,
                aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw,
            ]
        )
    return np.array(out).reshape(shape)


def rotate(q: ArrayLike, v: ArrayLike) -> F:
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4); broadcasts."""
    qa = asquat(q)
    va = np.asarray(v, dtype=np.float64)
    if qa.size <= 4 * _FEW and va.size <= 3 * _FEW:
        return _rotate_few(qa, va)
    w = qa[..., :1]
    u = qa[..., 1:]
    t = 2.0 * cross(u, va)
    return va + w * t + cross(u, t)


def _rotate_few(qa: F, va: F) -> F:
    """:func:`rotate` of a few in Python floats (the same operations)."""
    shape = _broadcast(qa.shape[:-1] + (3,), va.shape)
    out = []
    for (w, ux, uy, uz), (vx, vy, vz) in zip(
        _rows(qa, shape[:-1] + (4,), 4), _rows(va, shape, 3), strict=True
    ):
        tx = 2.0 * (uy * vz - uz * vy)
        ty = 2.0 * (uz * vx - ux * vz)
        tz = 2.0 * (ux * vy - uy * vx)
        out.append(
            [
                vx + w * tx + (uy * tz - uz * ty),
                vy + w * ty + (uz * tx - ux * tz),
                vz + w * tz + (ux * ty - uy * tx),
            ]
        )
    return np.array(out).reshape(shape)


def rotate_one(q: F, v: F) -> F:
    """Rotate one vector ``v`` (3,) by one unit quaternion ``q`` (4,): :func:`rotate`
    written out in Python floats, several times faster for a single vector (the
    renderer turns a head's forward direction with it every frame)."""
    w, x, y, z = (float(c) for c in q)
    a, b, c = (float(e) for e in v)
    # t = u x v + w v, then v + 2 u x t
    tx, ty, tz = y * c - z * b + w * a, z * a - x * c + w * b, x * b - y * a + w * c
    return np.array(
        [a + 2.0 * (y * tz - z * ty), b + 2.0 * (z * tx - x * tz), c + 2.0 * (x * ty - y * tx)]
    )


def rotate_about(v: F, axis: F, angle: F) -> F:
    """Rows of ``v`` (n, 3) turned by ``angle`` (n,) radians about unit ``axis`` rows
    (n, 3), by Rodrigues' formula (equal to ``rotate(from_axis_angle(axis, angle), v)``
    to rounding, without building quaternions)."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    ax_v = cross(axis, v)
    dot_av = np.einsum("ij,ij->i", axis, v)[:, None]
    out: F = v * c + ax_v * s + axis * dot_av * (1 - c)
    return out


def cross(a: F, b: F) -> F:
    """Cross product over the last axis; broadcasts (np.cross is slow for small arrays)."""
    if a.shape == b.shape and a.size <= 3 * _FEW:
        rows = [
            [a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0]
            for (a0, a1, a2), (b0, b1, b2) in zip(
                a.reshape(-1, 3).tolist(), b.reshape(-1, 3).tolist(), strict=True
            )
        ]
        return np.array(rows, dtype=np.float64).reshape(a.shape)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.float64)
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def dot(a: ArrayLike, b: ArrayLike) -> F:
    """Four-dimensional dot product over the last axis."""
    return np.sum(asquat(a) * asquat(b), axis=-1)


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> F:
    """Rotation by ``angle`` radians about ``axis`` (..., 3; normalised here)."""
    ax = np.asarray(axis, dtype=np.float64)
    ang = np.asarray(angle, dtype=np.float64)
    if ax.size <= 3 * _FEW and ang.size <= _FEW and ax.shape[-1:] == (3,):
        return _from_axis_angle_few(ax, ang)
    n = np.linalg.norm(ax, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("rotation axis must not be the zero vector")
    half = 0.5 * ang[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * ax / n], axis=-1)


def _broadcast(*shapes: tuple[int, ...]) -> tuple[int, ...]:
    """``np.broadcast_shapes`` of a few shapes, without its cost when they are equal or
    differ only by leading ones (a single quaternion against a row of one)."""
    first = shapes[0]
    if all(s == first for s in shapes[1:]):
        return first
    n = max(len(s) for s in shapes)
    padded = [(1,) * (n - len(s)) + s for s in shapes]
    if all(p == padded[0] for p in padded[1:]):
        return padded[0]
    return tuple(np.broadcast_shapes(*shapes))


def _rows(a: F, shape: tuple[int, ...], k: int) -> list[list[float]]:
    """``a`` broadcast to ``shape`` as Python rows of ``k`` floats."""
    if a.shape != shape:
        n = math.prod(shape) // k
        if a.size == k:  # one row for all
            return a.reshape(1, k).tolist() * n
        a = np.broadcast_to(a, shape)
    return a.reshape(-1, k).tolist()


def _from_axis_angle_few(ax: F, ang: F) -> F:
    """:func:`from_axis_angle` of a few in Python floats (the same operations)."""
    shape = _broadcast(ax.shape[:-1], ang.shape)
    axes, angles = _rows(ax, shape + (3,), 3), _rows(ang, shape, 1)
    out = []
    for (x, y, z), (a,) in zip(axes, angles, strict=True):
        n = math.sqrt(x * x + y * y + z * z)
        if n == 0:
            raise ValueError("rotation axis must not be the zero vector")
        half = 0.5 * a
        c, s = math.cos(half), math.sin(half)
        out.append([c, s * x / n, s * y / n, s * z / n])
    return np.array(out).reshape(shape + (4,))


def to_axis_angle(q: ArrayLike) -> tuple[F, F]:
    """(axis (..., 3), angle (...,) in [0, pi]) of unit quaternions; identity -> x axis, 0."""
    a = asquat(q)
    a = np.where(a[..., :1] < 0, -a, a)
    s = np.linalg.norm(a[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(s, a[..., 0])
    safe = np.where(s > 1e-12, s, 1.0)[..., None]
    axis = np.where(s[..., None] > 1e-12, a[..., 1:] / safe, np.array([1.0, 0.0, 0.0]))
    return axis, angle


def angle(q: ArrayLike) -> F:
    """Rotation angle (radians, 0..pi) of unit quaternions."""
    a = asquat(q)
    return 2.0 * np.arctan2(np.linalg.norm(a[..., 1:], axis=-1), np.abs(a[..., 0]))


def angle_between(a: ArrayLike, b: ArrayLike) -> F:
    """Angle (radians, 0..pi) of the rotation taking ``a`` to ``b``."""
    return angle(multiply(conjugate(normalize(a)), normalize(b)))


def to_matrix(q: ArrayLike) -> F:
    """Rotation matrices (..., 3, 3) of unit quaternions (column vectors: ``M @ v``)."""
    a = asquat(q)
    w, x, y, z = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    m = np.empty(a.shape[:-1] + (3, 3), dtype=np.float64)
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 0, 1] = 2 * (x * y - w * z)
    m[..., 0, 2] = 2 * (x * z + w * y)
    m[..., 1, 0] = 2 * (x * y + w * z)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 1, 2] = 2 * (y * z - w * x)
    m[..., 2, 0] = 2 * (x * z - w * y)
    m[..., 2, 1] = 2 * (y * z + w * x)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def from_matrix(m: ArrayLike) -> F:
    """Unit quaternions (w >= 0) from rotation matrices (..., 3, 3)."""
    r = np.asarray(m, dtype=np.float64)
    if r.shape[-2:] != (3, 3):
        raise ValueError(f"rotation matrices need shape (..., 3, 3), got {r.shape}")
    if r.size <= 9 * _FEW:
        found = [_from_matrix_one(m) for m in r.reshape(-1, 9).tolist()]
        return np.array(found).reshape(r.shape[:-2] + (4,))
    # Shepperd's method, vectorised: pick the largest of 4 candidates per matrix.
    # (written into one array: a stack of stacks cost more than the arithmetic)
    tr = r[..., 0, 0] + r[..., 1, 1] + r[..., 2, 2]
    d21, d02, d10 = (
        r[..., 2, 1] - r[..., 1, 2],
        r[..., 0, 2] - r[..., 2, 0],
        r[..., 1, 0] - r[..., 0, 1],
    )
    s01, s02, s12 = (
        r[..., 0, 1] + r[..., 1, 0],
        r[..., 0, 2] + r[..., 2, 0],
        r[..., 1, 2] + r[..., 2, 1],
    )
    cand = np.empty(r.shape[:-2] + (4, 4))
    rows = (
        (1 + tr, d21, d02, d10),
        (d21, 1 + 2 * r[..., 0, 0] - tr, s01, s02),
        (d02, s01, 1 + 2 * r[..., 1, 1] - tr, s12),
        (d10, s02, s12, 1 + 2 * r[..., 2, 2] - tr),
    )
    for i, row in enumerate(rows):
        for j, value in enumerate(row):
            cand[..., i, j] = value
    diag = np.stack([tr, r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]], axis=-1)
    best = np.argmax(diag, axis=-1)
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :]
    q = normalize(q)
    return np.where(q[..., :1] < 0, -q, q)


def _from_matrix_one(m: list[float]) -> list[float]:
    """:func:`from_matrix` of one matrix (its 9 entries, row by row) in Python floats."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = m
    tr = r00 + r11 + r22
    d21, d02, d10 = r21 - r12, r02 - r20, r10 - r01
    # the largest of tr, r00, r11, r22 picks the row (the first of equals, as argmax)
    best, big = 0, tr
    for i, v in ((1, r00), (2, r11), (3, r22)):
        if v > big:
            best, big = i, v
    if best == 0:
        q = [1 + tr, d21, d02, d10]
    elif best == 1:
        q = [d21, 1 + 2 * r00 - tr, r01 + r10, r02 + r20]
    elif best == 2:
        q = [d02, r01 + r10, 1 + 2 * r11 - tr, r12 + r21]
    else:
        q = [d10, r02 + r20, r12 + r21, 1 + 2 * r22 - tr]
    q = _unit4(q)
    return [-c for c in q] if q[0] < 0 else q


def from_two_vectors(a: ArrayLike, b: ArrayLike) -> F:
    """The smallest rotation taking direction ``a`` to direction ``b`` (..., 3)."""
    u = np.asarray(a, dtype=np.float64)
    v = np.asarray(b, dtype=np.float64)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    w = 1.0 + np.sum(u * v, axis=-1, keepdims=True)
    xyz = np.cross(u, v)
    # opposite directions: rotate by pi about any axis perpendicular to a
    other = np.where(np.abs(u[..., :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    perp = np.cross(u, other)
    opposite = w < 1e-12
    xyz = np.where(opposite, perp, xyz)
    w = np.where(opposite, 0.0, w)
    return normalize(np.concatenate([w, xyz], axis=-1))


def from_frame(x_axis: ArrayLike, y_axis: ArrayLike) -> F:
    """The rotation taking the world x and y axes to the (orthonormalised) given axes."""
    x = np.asarray(x_axis, dtype=np.float64)
    x = x / np.linalg.norm(x, axis=-1, keepdims=True)
    y = np.asarray(y_axis, dtype=np.float64)
    y = y - np.sum(y * x, axis=-1, keepdims=True) * x
    y = y / np.linalg.norm(y, axis=-1, keepdims=True)
    z = np.cross(x, y)
    return from_matrix(np.stack([x, y, z], axis=-1))


def slerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F:
    """Spherical linear interpolation from ``a`` (t=0) to ``b`` (t=1), the short way.

    ``a``, ``b`` (..., 4) unit quaternions, ``t`` broadcastable to ``(...)``.
    When ``dot(a, b) < 0`` the sign of ``b`` is flipped first (q and -q are one
    rotation), in *every* branch; for angles below ~1e-6 rad the result is the
    normalised linear interpolation of ``a`` and the flipped ``b``.
    """
    qa = asquat(a)
    qb = asquat(b)
    tt = np.asarray(t, dtype=np.float64)[..., None]
    if qa.size <= 4 * _FEW and qb.size <= 4 * _FEW and tt.size <= _FEW:
        return _slerp_few(qa, qb, tt)
    d = np.sum(qa * qb, axis=-1, keepdims=True)
    qb = np.where(d < 0.0, -qb, qb)
    d = np.abs(d)
    theta = np.arccos(np.clip(d, -1.0, 1.0))
    sin_theta = np.sin(theta)
    small = theta < _SLERP_LINEAR_BELOW
    safe = np.where(small, 1.0, sin_theta)
    wa = np.where(small, 1.0 - tt, np.sin((1.0 - tt) * theta) / safe)
    wb = np.where(small, tt, np.sin(tt * theta) / safe)
    return normalize(wa * qa + wb * qb)


def _slerp_few(qa: F, qb: F, tt: F) -> F:
    """:func:`slerp` of a few in Python floats (the same operations; numpy's arccos)."""
    shape = _broadcast(qa.shape, qb.shape, tt.shape)
    ra, rb = _rows(qa, shape, 4), _rows(qb, shape, 4)
    ts = [t for (t,) in _rows(tt, shape[:-1] + (1,), 1)]
    dots = [
        a0 * b0 + a1 * b1 + a2 * b2 + a3 * b3
        for (a0, a1, a2, a3), (b0, b1, b2, b3) in zip(ra, rb, strict=True)
    ]
    thetas = np.arccos(np.clip(np.abs(np.array(dots)), -1.0, 1.0)).tolist()
    out = []
    for a, b, d, theta, t in zip(ra, rb, dots, thetas, ts, strict=True):
        if d < 0.0:
            b = [-c for c in b]
        if theta < _SLERP_LINEAR_BELOW:
            wa, wb = 1.0 - t, t
        else:
            sin_theta = math.sin(theta)
            wa, wb = math.sin((1.0 - t) * theta) / sin_theta, math.sin(t * theta) / sin_theta
        out.append(_unit4([wa * x + wb * y for x, y in zip(a, b, strict=True)]))
    return np.array(out).reshape(shape)


def from_euler(angles: ArrayLike, order: str) -> F:
    """Quaternions from Euler angles (radians) applied as BVH does.

    ``angles[..., i]`` is the angle about axis ``order[i]`` (e.g. ``order="ZXY"``
    for ``Zrotation Xrotation Yrotation``); the rotation is
    ``R = R_order[0] @ R_order[1] @ R_order[2]`` (intrinsic, in channel order).
    """
    ang = np.asarray(angles, dtype=np.float64)
    _check_order(order, ang.shape[-1])
    q = identity(ang.shape[:-1])
    for i, axis_name in enumerate(order.upper()):
        axis = np.zeros(3)
        axis[_AXES[axis_name]] = 1.0
        q = multiply(q, from_axis_angle(axis, ang[..., i]))
    return q


def to_euler(q: ArrayLike, order: str) -> F:
    """Euler angles (radians, (..., 3)) with ``from_euler(to_euler(q, o), o) == ±q``.

    ``order`` is any of the 6 permutations of X, Y, Z (Tait-Bryan angles); the
    middle angle is in [-pi/2, pi/2].  Near gimbal lock the last angle is 0.
    """
    _check_order(order, 3)
    m = to_matrix(normalize(q))
    i, j, k = (_AXES[c] for c in order.upper())
    # sign of the permutation (i, j, k): +1 for cyclic XYZ, YZX, ZXY
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    # R = R_i(a) R_j(b) R_k(c):  m[i, k] = sign * sin(b)
    sb = np.clip(sign * m[..., i, k], -1.0, 1.0)
    b = np.arcsin(sb)
    cb = np.sqrt(np.maximum(0.0, 1.0 - sb * sb))
    regular = cb > 1e-9
    a = np.arctan2(-sign * m[..., j, k], m[..., k, k])
    c = np.arctan2(-sign * m[..., i, j], m[..., i, i])
    # gimbal lock: put everything into the first angle, c = 0
    a_lock = np.arctan2(sign * m[..., k, j], m[..., j, j])
    a = np.where(regular, a, a_lock)
    c = np.where(regular, c, 0.0)
    return np.stack([a, b, c], axis=-1)


def _check_order(order: str, n: int) -> None:
    o = order.upper()
    if len(o) != 3 or sorted(o) != ["X", "Y", "Z"] or n != 3:
        raise ValueError(f"Euler order must be a permutation of XYZ with 3 angles, got {order!r}")
