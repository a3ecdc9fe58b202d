"""Unit meshes and per-instance transforms for the primitives the scene is made of.

Kinds:
- ``cylinder``: radius 1, axis +y from y=0 to y=1, capped.  Limbs, drum shells,
  sticks, strings, stands.
- ``sphere``: radius 1 at the origin.  Joints, heads, capsule ends.
- ``box``: the cube [-0.5, 0.5]^3.  The stage, the bass body, the fingerboard.

Meshes are (n_vertices, 6) float32 arrays of position and normal, drawn as
triangles.  Instance transforms are (n, 4, 4) float64 matrices in
column-vector form (world = M @ p); :func:`pack_instances` lays them out
column-major for GLSL's ``mat4``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from virja import quat

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]


def cylinder_mesh(segments: int = 14) -> F32:
    a = np.linspace(0.0, 2 * np.pi, segments + 1)
    c, s = np.cos(a), np.sin(a)
    tris: list[list[float]] = []
    for i in range(segments):
        p0 = (c[i], 0.0, s[i])
        p1 = (c[i + 1], 0.0, s[i + 1])
        q0 = (c[i], 1.0, s[i])
        q1 = (c[i + 1], 1.0, s[i + 1])
        n0 = (c[i], 0.0, s[i])
        n1 = (c[i + 1], 0.0, s[i + 1])
        tris += [[*p0, *n0], [*q0, *n0], [*p1, *n1], [*p1, *n1], [*q0, *n0], [*q1, *n1]]
        tris += [[0, 1, 0, 0, 1, 0], [*q1, 0, 1, 0], [*q0, 0, 1, 0]]  # top cap
        tris += [[0, 0, 0, 0, -1, 0], [*p0, 0, -1, 0], [*p1, 0, -1, 0]]  # bottom cap
    return np.asarray(tris, dtype=np.float32)


def sphere_mesh(rings: int = 8, segments: int = 12) -> F32:
    th = np.linspace(0, np.pi, rings + 1)
    ph = np.linspace(0, 2 * np.pi, segments + 1)

    def p(i: int, j: int) -> tuple[float, float, float]:
        return (
            float(np.sin(th[i]) * np.cos(ph[j])),
            float(np.cos(th[i])),
            float(np.sin(th[i]) * np.sin(ph[j])),
        )

    tris: list[list[float]] = []
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = p(i, j), p(i + 1, j), p(i, j + 1), p(i + 1, j + 1)
            for v in (a, c, b, c, d, b):  # counter-clockwise seen from outside
                tris.append([*v, *v])
    return np.asarray(tris, dtype=np.float32)


def box_mesh() -> F32:
    tris: list[list[float]] = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            corners = []
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                q = [0.0, 0.0, 0.0]
                q[axis] = 0.5 * sign
                q[u] = 0.5 * du
                q[v] = 0.5 * dv
                corners.append(q)
            order = (0, 1, 2, 0, 2, 3) if sign > 0 else (0, 2, 1, 0, 3, 2)
            for k in order:
                tris.append([*corners[k], *n])
    return np.asarray(tris, dtype=np.float32)


MESHES: dict[str, Callable[[], F32]] = {
    "cylinder": cylinder_mesh,
    "sphere": sphere_mesh,
    "box": box_mesh,
}


def _row_norm(v: F64) -> F64:
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def _basis_from_y(axis: F64) -> F64:
    """(n, 3, 3) rotations taking +y onto each unit ``axis`` (n, 3)."""
    y = axis / np.maximum(_row_norm(axis), 1e-12)[:, None]
    helper = np.zeros_like(y)
    near_y = np.abs(y[:, 1]) >= 0.99
    helper[~near_y, 1] = 1.0
    helper[near_y, 0] = 1.0
    x = quat.cross(helper, y)
    x /= np.maximum(_row_norm(x), 1e-12)[:, None]
    z = quat.cross(x, y)
    return np.stack([x, y, z], axis=2)  # columns x, y, z


def segment_transforms(a: ArrayLike, b: ArrayLike, radius: ArrayLike) -> F64:
    """Unit-cylinder instances spanning points ``a`` -> ``b`` (n, 3) with radii (n,)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 3)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radius, dtype=np.float64), (a.shape[0],))
    d = b - a
    length = _row_norm(d)
    d[length <= 1e-12] = (0.0, 1.0, 0.0)
    rot = _basis_from_y(d)
    m = np.zeros((a.shape[0], 4, 4))
    m[:, :3, 0] = rot[:, :, 0] * r[:, None]
    m[:, :3, 1] = rot[:, :, 1] * length[:, None]
    m[:, :3, 2] = rot[:, :, 2] * r[:, None]
    m[:, :3, 3] = a
    m[:, 3, 3] = 1.0
    return m


def sphere_transforms(center: ArrayLike, radius: ArrayLike) -> F64:
    """Unit-sphere instances at ``center`` (n, 3) with radii (n,)."""
    c = np.asarray(center, dtype=np.float64).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radius, dtype=np.float64), (c.shape[0],))
    m = np.zeros((c.shape[0], 4, 4))
    m[:, 0, 0] = m[:, 1, 1] = m[:, 2, 2] = r
    m[:, :3, 3] = c
    m[:, 3, 3] = 1.0
    return m


def disc_transforms(
    center: ArrayLike, normal: ArrayLike, radius: ArrayLike, thickness: ArrayLike
) -> F64:
    """Flat cylinders (drum heads, cymbals) centred at ``center``, axis ``normal``."""
    c = np.asarray(center, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normal, dtype=np.float64).reshape(-1, 3)
    t = np.broadcast_to(np.asarray(thickness, dtype=np.float64), (c.shape[0],))
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return segment_transforms(c - n * (t / 2)[:, None], c + n * (t / 2)[:, None], radius)


def box_transforms(center: ArrayLike, size: ArrayLike, rotation: ArrayLike | None = None) -> F64:
    """Box instances: centre (n, 3), full size (n, 3), optional rotation (n, 3, 3)."""
    c = np.asarray(center, dtype=np.float64).reshape(-1, 3)
    s = np.asarray(size, dtype=np.float64).reshape(-1, 3)
    rot = (
        np.broadcast_to(np.eye(3), (c.shape[0], 3, 3)) if rotation is None else np.asarray(rotation)
    )
    m = np.zeros((c.shape[0], 4, 4))
    m[:, :3, :3] = rot * s[:, None, :]
    m[:, :3, 3] = c
    m[:, 3, 3] = 1.0
    return m


def pack_instances(models: F64, colors: ArrayLike) -> F32:
    """(n, 20) float32 rows: the column-major matrix then RGBA."""
    n = models.shape[0]
    out = np.empty((n, 20), dtype=np.float32)
    # the transposed matrices cast straight into the rows (no float64 copy between)
    out[:, :16].reshape(n, 4, 4)[...] = np.transpose(models, (0, 2, 1))
    out[:, 16:] = np.broadcast_to(colors, (n, 4))
    return out
