"""The moving band's instances for a chunk of frames at once (the render loops' path).

:func:`band_scenes` turns a :class:`~virja.motion.pose_batch.BandPoses` (``m``
frames) into ``m`` DrawLists with the same rows, in the same order, as
:func:`virja.render.scene.band_scene` gives frame by frame
(tests/render/test_scene_batch.py), but builds them with one numpy pass per part
over all frames: every segment (strings, limbs, palms, fingers, sticks, the
beater) of every frame becomes a matrix in one call, every sphere in another,
and the rows are packed to the renderer's float32 layout once for the chunk.
The layout of a frame is fixed by the geometry, the skeleton and the tuning
(each string has a slot for its bowed pieces, kept only while it vibrates), so
a frame is a slice of the chunk's table.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from virja import quat
from virja.geometry import GEOMETRY, Geometry
from virja.motion.pose import LEFT_FINGER_BONES
from virja.motion.pose_batch import BandPoses
from virja.render.meshes import (
    disc_transforms,
    pack_instances,
    segment_transforms,
    sphere_transforms,
)
from virja.render.pedals import BEATER_BALL_M, beater_many, footboards_many
from virja.render.renderer import DrawList
from virja.render.scene import (
    BASSIST_SHIRT,
    BEATER,
    BRASS,
    CHROME,
    DRUMMER_SHIRT,
    HEAD,
    HEAD_HIT,
    SKIN,
    STICK,
    STRING,
    STRING_HOT,
    _bass_table,
    _figure_table,
    _kit_table,
    _mode,
    _string_table,
)
from virja.vocab import BASS_STRINGS

F64 = NDArray[np.float64]
BOWED = 12  # pieces of a vibrating string (scene._string_parts' default)


class _Rows:
    """Segments or spheres of all frames, gathered part by part (m frames each)."""

    def __init__(self, m: int) -> None:
        self.m = m
        self.a: list[F64] = []
        self.z: list[F64] = []
        self.r: list[F64] = []
        self.c: list[F64] = []
        self.keep: list[NDArray[np.bool_]] = []

    def add(
        self,
        a: F64,
        z: F64 | None,
        radius: F64,
        color: F64 | tuple[float, ...],
        keep: NDArray[np.bool_] | None = None,
    ) -> None:
        """``a``, ``z`` (m, n, 3) (``z`` None for spheres), radius (n,) or (m, n),
        colour (4,), (n, 4) or (m, n, 4); ``keep`` (m, n) the rows each frame draws."""
        n = a.shape[1]
        self.a.append(a)
        if z is not None:
            self.z.append(z)
        self.r.append(np.broadcast_to(radius, (self.m, n)))
        self.c.append(np.broadcast_to(np.asarray(color, dtype=np.float64), (self.m, n, 4)))
        self.keep.append(np.ones((self.m, n), dtype=bool) if keep is None else keep)

    def matrices(self, spheres: bool) -> tuple[F64, F64, NDArray[np.bool_]]:
        """(m, n, 4, 4) models, (m, n, 4) colours, (m, n) kept rows."""
        a = np.concatenate(self.a, axis=1)
        m, n = a.shape[:2]
        r = np.concatenate(self.r, axis=1).reshape(-1)
        if spheres:
            models = sphere_transforms(a.reshape(-1, 3), r)
        else:
            z = np.concatenate(self.z, axis=1)
            models = segment_transforms(a.reshape(-1, 3), z.reshape(-1, 3), r)
        color = np.concatenate(self.c, axis=1)
        return models.reshape(m, n, 4, 4), color, np.concatenate(self.keep, axis=1)


def band_scenes(batch: BandPoses, geo: Geometry = GEOMETRY) -> list[DrawList]:
    """The moving band of each frame of ``batch``: ``band_scene(batch.pose(k))`` for
    every ``k``, built for all the frames at once."""
    m = len(batch)
    if m == 0:
        return []
    segs, sphs = _Rows(m), _Rows(m)
    kit_cyl, kit_color = _kit(geo, batch, sphs)
    _strings(geo, batch, segs)
    fingers = np.asarray(batch.bass_fingers, dtype=np.float64)
    _figure(batch, 0, DRUMMER_SHIRT, (), segs, sphs)
    if fingers.shape[1]:
        _figure(batch, 1, BASSIST_SHIRT, ("LeftHandEnd", "RightHandEnd"), segs, sphs)
        _fingers(batch, fingers, segs, sphs)
    else:
        _figure(batch, 1, BASSIST_SHIRT, (), segs, sphs)
    s = np.asarray(batch.sticks, dtype=np.float64)
    segs.add(s[:, :, 0], s[:, :, 1], np.full(2, 0.0075), STICK)
    sphs.add(s[:, :, 1], None, np.full(2, 0.009), STICK)
    names = batch.names
    toe_r = batch.positions[:, 0, names.index("RightToe"), 1]
    toe_l = batch.positions[:, 0, names.index("LeftToe"), 1]
    boards, downs = footboards_many(geo, toe_r, toe_l)
    axle, ball = beater_many(geo, downs[:, 0])
    segs.add(axle[:, None], ball[:, None], np.full(1, 0.006), CHROME)
    sphs.add(ball[:, None], None, np.full(1, BEATER_BALL_M), BEATER)

    seg, seg_color, seg_keep = segs.matrices(spheres=False)
    sph, sph_color, _ = sphs.matrices(spheres=True)
    cyl_keep = np.concatenate([np.ones(kit_cyl.shape[:2], dtype=bool), seg_keep], axis=1)
    per_kind: dict[str, list[tuple[F64, F64]]] = {
        "box": [(boards, np.broadcast_to(np.asarray(CHROME), boards.shape[:2] + (4,)))],
        # the kit's and the segments' rows joined once, with the bass's, below
        "cylinder": [(kit_cyl, kit_color), (seg, seg_color)],
        "sphere": [(sph, sph_color)],
    }
    lean = np.asarray(batch.bass_transform, dtype=np.float64)
    # the fingerboard as wide as the tuning's strings (virja.fingerboard), as band_scene
    tuning = tuple(x for x in geo.bass.strings if x in batch.strings) or BASS_STRINGS
    for kind, (models, colors) in _bass_table(geo, tuning).items():
        moved = lean[:, None] @ models[None]  # the bass leans with its player
        per_kind.setdefault(kind, []).append((moved, np.broadcast_to(colors, (m,) + colors.shape)))
    packed: dict[str, NDArray[np.float32]] = {}
    keep: dict[str, NDArray[np.bool_] | None] = {}
    for kind, parts in per_kind.items():
        models = np.concatenate([p[0] for p in parts], axis=1)
        colors = np.concatenate([p[1] for p in parts], axis=1)
        n = models.shape[1]
        rows = pack_instances(models.reshape(-1, 4, 4), colors.reshape(-1, 4))
        packed[kind] = rows.reshape(m, n, 20)
        if kind == "cylinder":
            extra = n - cyl_keep.shape[1]
            k = np.concatenate([cyl_keep, np.ones((m, extra), dtype=bool)], axis=1)
            keep[kind] = None if k.all() else k
        else:
            keep[kind] = None
    out = []
    for f in range(m):
        rows_of: dict[str, NDArray[np.float32]] = {}
        for kind, rows in packed.items():
            kept = keep[kind]
            rows_of[kind] = rows[f] if kept is None or kept[f].all() else rows[f][kept[f]]
        out.append(DrawList.prepacked(rows_of))
    return out


def _column(names: tuple[str, ...], values: F64, wanted: tuple[str, ...]) -> F64:
    """Columns of ``values`` (m, len(names)) in the order of ``wanted`` (0 when absent)."""
    out = np.zeros((values.shape[0], len(wanted)))
    for j, name in enumerate(wanted):
        if name in names:
            out[:, j] = values[:, names.index(name)]
    return out


def _kit(geo: Geometry, batch: BandPoses, sphs: _Rows) -> tuple[F64, F64]:
    """The kit's cylinders (m, n, 4, 4) and colours (m, n, 4); its bells into ``sphs``."""
    t = _kit_table(geo)
    m = len(batch)
    cyl = np.broadcast_to(t.cyl_base, (m,) + t.cyl_base.shape).copy()
    color = np.broadcast_to(t.cyl_color, (m,) + t.cyl_color.shape).copy()
    if t.drums:
        h = np.clip(_column(batch.drums, batch.head_hits, t.drums), 0.0, 1.0)[..., None]
        color[:, t.drum_rows] = np.array(HEAD) * (1 - h) + np.array(HEAD_HIT) * h
    if not t.cymbals:
        return cyl, color
    nc = len(t.cymbals)
    angle = _column(batch.cymbals, batch.cymbal_swing, t.cymbals).reshape(-1)
    normal = quat.rotate_about(
        np.tile(t.normal, (m, 1)), np.tile(t.swing_axis, (m, 1)), angle
    ).reshape(m, nc, 3)
    centre = np.broadcast_to(t.centre, (m, nc, 3)).copy()
    if t.hihat >= 0:
        lift = 0.004 + 0.016 * np.clip(np.asarray(batch.hihat_open, dtype=np.float64), 0.0, 1.0)
        centre[:, t.hihat, 1] += lift
    discs = disc_transforms(
        centre.reshape(-1, 3), normal.reshape(-1, 3), np.tile(t.radius, m), np.tile(t.thickness, m)
    )
    cyl[:, t.cymbal_rows] = discs.reshape(m, nc, 4, 4)
    sphs.add(centre, None, t.radius * 0.14, BRASS)
    return cyl, color


def _strings(geo: Geometry, batch: BandPoses, segs: _Rows) -> None:
    """Each string: a slot nut -> bridge (or -> its stop while it vibrates) and
    :data:`BOWED` slots for its bowed part, kept only while it vibrates."""
    full = _string_table(geo)
    b = geo.bass
    m = len(batch)
    strings = [s for s in b.strings if s in batch.strings] or list(BASS_STRINGS)
    t = full.subset([b.strings.index(s) for s in strings])
    ns = len(strings)
    amp = _column(batch.strings, batch.string_vibration, tuple(strings))
    vib = amp > 1e-5
    fret = np.zeros((m, ns), dtype=np.intp)
    for j, s in enumerate(strings):
        if s in batch.strings:
            fret[:, j] = batch.string_stops[:, batch.strings.index(s)]
    fret = np.clip(fret, 0, t.points.shape[1] - 1)
    stop = t.points[np.arange(ns)[None, :], fret]  # (m, ns, 3)
    plain_end = np.where(vib[..., None], stop, t.bridge)
    u, shape = _mode(BOWED)
    pts = stop[:, :, None] + u * (t.bridge[None, :, None] - stop[:, :, None])
    swing = np.cos(2 * np.pi * (9.0 + 1.3 * t.index) * np.asarray(batch.times)[:, None])
    bow = amp[..., None] * shape * swing[..., None]
    pts = pts + t.lateral * bow[..., None]  # (m, ns, BOWED + 1, 3)
    a = np.concatenate([t.nut[None, :, None].repeat(m, 0), pts[:, :, :-1]], axis=2)
    z = np.concatenate([plain_end[:, :, None], pts[:, :, 1:]], axis=2)
    radius = np.concatenate([t.radius[:, None], np.repeat(t.radius[:, None] * 1.3, BOWED, 1)], 1)
    color = np.empty((ns, BOWED + 1, 4))
    color[:, 0] = STRING
    color[:, 1:] = STRING_HOT
    keep = np.concatenate([np.ones((m, ns, 1), dtype=bool), vib[..., None].repeat(BOWED, 2)], 2)
    lean = np.asarray(batch.bass_transform, dtype=np.float64)
    rot, shift = lean[:, None, :3, :3], lean[:, None, :3, 3]
    n = ns * (BOWED + 1)
    a = a.reshape(m, n, 3)
    z = z.reshape(m, n, 3)
    a = np.einsum("mnj,mij->mni", a, rot[:, 0]) + shift  # the strings lean with the bass
    z = np.einsum("mnj,mij->mni", z, rot[:, 0]) + shift
    segs.add(a, z, radius.reshape(-1), color.reshape(-1, 4), keep.reshape(m, n))


def _figure(
    batch: BandPoses,
    fi: int,
    shirt: tuple[float, ...],
    skip: tuple[str, ...],
    segs: _Rows,
    sphs: _Rows,
) -> None:
    """Limbs and joints of figure ``fi``, its head and nose (as scene._figure_parts)."""
    pos = batch.positions[:, fi]
    radii = np.asarray(batch.radii, dtype=np.float64)
    t = _figure_table(batch.names, np.asarray(batch.parents).tobytes(), tuple(shirt), skip)
    segs.add(pos[:, t.limb_parent], pos[:, t.limb_child], radii[t.limb_child], t.limb_color)
    sphs.add(pos[:, t.joints], None, radii[t.joints] * 1.05, t.joint_color)
    if t.head >= 0:
        centre = (pos[:, t.head] + pos[:, t.head_end]) / 2
        q = batch.rotations[:, fi, t.head]
        w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
        # quat.rotate_one(q, (0, 0, 1)) written out over the frames (the same arithmetic)
        a, b, c = 0.0, 0.0, 1.0
        tx, ty, tz = y * c - z * b + w * a, z * a - x * c + w * b, x * b - y * a + w * c
        forward = np.stack(
            [a + 2.0 * (y * tz - z * ty), b + 2.0 * (z * tx - x * tz), c + 2.0 * (x * ty - y * tx)],
            axis=-1,
        )
        head = np.stack([centre, centre + forward * 0.1], axis=1)
        sphs.add(head, None, np.array([0.105, 0.022]), SKIN)


def _fingers(batch: BandPoses, bones: F64, segs: _Rows, sphs: _Rows) -> None:
    """The palms (wrist -> mean knuckle) and finger bones (as scene._finger_parts)."""
    names = batch.names
    pos = batch.positions[:, 1]
    half = LEFT_FINGER_BONES
    palms = [
        (pos[:, names.index(wrist)], knuckles.mean(axis=1))
        for wrist, knuckles in (
            ("LeftHand", bones[:, :8:2, 0]),
            ("RightHand", bones[:, half : half + 4 : 2, 0]),
        )
        if knuckles.shape[1]
    ]
    k = bones.shape[1]
    if palms:
        a = np.stack([p[0] for p in palms], axis=1)
        z = np.stack([p[1] for p in palms], axis=1)
        segs.add(a, z, np.full(len(palms), 0.022), SKIN)
    segs.add(bones[:, :, 0], bones[:, :, 1], np.full(k, 0.0075), SKIN)
    sphs.add(bones[:, :, 1], None, np.full(k, 0.008), SKIN)


__all__ = ["band_scenes"]
