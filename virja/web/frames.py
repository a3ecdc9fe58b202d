"""The browser viewer's wire format: the stage once, then the moving instances per frame.

The browser draws exactly what the native renderer draws: the instances of
:func:`virja.render.scene.static_scene` (sent once, in the ``hello`` message,
as float32) and of :func:`virja.render.scene.band_scene` (sent per frame),
with the same unit meshes (:mod:`virja.render.meshes`), the same camera
presets and the same shader file.  Nothing of the band is rebuilt in
JavaScript, so the figures, the instruments and their responses cannot drift
apart from the native picture.

A frame is one binary WebSocket message, little-endian::

    u8  type (2)   u8 version (1)   u16 reserved
    u32 seq        f64 time_s (session seconds the frame shows)
    u16 count per kind (cylinder, sphere, box)   u16 reserved     -> 24 bytes
    n x 9  float16  the 3 x 3 linear part, column-major (rotation times scale)
    n x 3  int16    the translation, metres x POS_SCALE (+-8 m at 0.24 mm)
    n x 4  uint8    linear RGB and shininess, x 255

28 bytes per instance; instances ordered by kind as in :data:`KINDS`.
Every frame stands alone (no deltas), so a viewer that drops frames never
needs a resend.  Text messages are JSON: ``hello``, ``beat``, ``chord`` and
``pong`` (see :mod:`virja.web.feed`).
"""

from __future__ import annotations

import struct
from typing import Any

import numpy as np
from numpy.typing import NDArray

from virja.render.camera import PRESETS
from virja.render.meshes import MESHES
from virja.render.renderer import BACKGROUND, DrawList
from virja.render.scene import FLOOR, RUG

KINDS: tuple[str, ...] = ("cylinder", "sphere", "box")
FRAME = 2
VERSION = 1
HEADER = struct.Struct("<BBHId4H")
POS_SCALE = 4096.0  # int16 units per metre
BYTES_PER_INSTANCE = 9 * 2 + 3 * 2 + 4
PROTOCOL = 1


def instances(dl: DrawList) -> tuple[list[int], NDArray[np.float32]]:
    """Counts per kind (in :data:`KINDS` order) and the (n, 20) packed rows, concatenated."""
    rows = [dl.packed(k) for k in KINDS]
    return [len(r) for r in rows], np.concatenate(rows)


def encode_frame(seq: int, time_s: float, dl: DrawList) -> bytes:
    """One frame message: the DrawList's instances, quantised (see the module doc)."""
    counts, rows = instances(dl)
    # packed rows are column-major matrices: columns 0-2 hold the linear part in their first
    # 3 entries (row 3 is 0), column 3 the translation
    cols = rows[:, :16].reshape(-1, 4, 4)
    lin = cols[:, :3, :3].reshape(-1, 9).astype(np.float16)
    pos = np.clip(np.rint(cols[:, 3, :3] * POS_SCALE), -32767, 32767).astype("<i2")
    rgba = np.clip(np.rint(rows[:, 16:20] * 255.0), 0, 255).astype(np.uint8)
    head = HEADER.pack(FRAME, VERSION, 0, seq & 0xFFFFFFFF, time_s, *counts, 0)
    return head + lin.astype("<f2").tobytes() + pos.tobytes() + rgba.tobytes()


def decode_frame(data: bytes) -> tuple[int, float, dict[str, NDArray[np.float32]]]:
    """The inverse of :func:`encode_frame` (tests, tools): seq, time and (n, 20) rows per kind."""
    if len(data) < HEADER.size:
        raise ValueError(f"frame truncated: {len(data)} of {HEADER.size} header bytes")
    kind, version, _, seq, time_s, *counts, _ = HEADER.unpack_from(data)
    if kind != FRAME or version != VERSION:
        raise ValueError(f"not a version {VERSION} frame (type {kind}, version {version})")
    n = sum(counts)
    want = HEADER.size + n * BYTES_PER_INSTANCE
    if len(data) != want:
        raise ValueError(f"frame of {n} instances must be {want} bytes, got {len(data)}")
    off = HEADER.size
    lin = np.frombuffer(data, "<f2", 9 * n, off).astype(np.float32).reshape(n, 3, 3)
    off += 18 * n
    pos = np.frombuffer(data, "<i2", 3 * n, off).astype(np.float32).reshape(n, 3) / POS_SCALE
    off += 6 * n
    rgba = np.frombuffer(data, np.uint8, 4 * n, off).astype(np.float32).reshape(n, 4) / 255.0
    rows = np.zeros((n, 20), np.float32)
    cols = rows[:, :16].reshape(n, 4, 4)
    cols[:, :3, :3] = lin
    cols[:, 3, :3] = pos
    cols[:, 3, 3] = 1.0
    rows[:, :16] = cols.reshape(n, 16)
    rows[:, 16:] = rgba
    out: dict[str, NDArray[np.float32]] = {}
    start = 0
    for k, c in zip(KINDS, counts, strict=True):
        out[k] = rows[start : start + c]
        start += c
    return seq, time_s, out


def _floats(a: NDArray[Any], digits: int = 5) -> list[float]:
    return [round(float(x), digits) for x in np.asarray(a, dtype=np.float64).ravel()]


def hello(static: DrawList, *, fps: float, lead_s: float) -> dict[str, Any]:
    """The first message to every viewer: meshes, the stage, the cameras, the lighting."""
    from virja.render.renderer import LIGHTS

    stage_colours = np.array([FLOOR, RUG], dtype=np.float32)
    static_out: dict[str, Any] = {}
    for k in KINDS:
        rows = static.packed(k)
        is_stage = (np.abs(rows[:, None, 16:20] - stage_colours[None]).max(axis=2) < 1e-6).any(1)
        static_out[k] = {
            "rows": _floats(rows, 6),
            "stage": [bool(s) for s in is_stage],
        }
    return {
        "type": "hello",
        "protocol": PROTOCOL,
        "kinds": list(KINDS),
        "meshes": {k: _floats(MESHES[k]()) for k in KINDS},
        "static": static_out,
        "background": list(BACKGROUND),
        "lights": {k: list(v) for k, v in LIGHTS.items()},
        "cameras": {
            name: {
                "target": list(c.target),
                "yaw_deg": c.yaw_deg,
                "pitch_deg": c.pitch_deg,
                "distance_m": c.distance_m,
                "fov_deg": c.fov_deg,
                "near_m": c.near_m,
                "far_m": c.far_m,
            }
            for name, c in PRESETS.items()
        },
        "fps": fps,
        "lead_s": lead_s,
        "pos_scale": POS_SCALE,
    }
