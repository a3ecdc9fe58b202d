"""What is on stage, as instances: the floor, the kit, the bass, the two players.

:func:`static_scene` builds what never moves (frozen once); :func:`band_scene`
builds, from a ``BandPose``, what moves each frame: the skeletons as solid
limbs, the sticks, the parts of the instruments that respond to playing (the
hi-hat closing, cymbals swaying, heads flashing when hit, plucked strings
vibrating).  Geometry comes from :mod:`virja.geometry`, the same data the
motions were authored against, so a stick that lands on a head in the motion
lands on the drawn head.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from virja import quat
from virja.fingerboard import fingerboard
from virja.geometry import GEOMETRY, Cymbal, Drum, Geometry
from virja.motion.pose import LEFT_FINGER_BONES, BandPose, FigurePose
from virja.render.meshes import (
    box_transforms,
    disc_transforms,
    segment_transforms,
    sphere_transforms,
)
from virja.render.pedals import BEATER_BALL_M, beater, footboards
from virja.render.renderer import DrawList
from virja.vocab import BASS_STRINGS

F64 = NDArray[np.float64]

# linear RGB, alpha = shininess
FLOOR = (0.075, 0.05, 0.04, 0.15)
RUG = (0.32, 0.06, 0.07, 0.0)
SHELL = (0.45, 0.05, 0.06, 0.55)
HEAD = (0.86, 0.84, 0.78, 0.1)
HEAD_HIT = (1.0, 0.95, 0.55, 0.1)
BRASS = (0.78, 0.56, 0.18, 0.9)
CHROME = (0.62, 0.64, 0.68, 0.9)
BLACK = (0.03, 0.03, 0.035, 0.4)
WOOD = (0.42, 0.18, 0.06, 0.6)
EBONY = (0.04, 0.03, 0.03, 0.5)
STRING = (0.75, 0.72, 0.62, 0.8)
STRING_HOT = (1.0, 0.85, 0.35, 0.8)
STICK = (0.85, 0.72, 0.48, 0.3)
BEATER = (0.92, 0.90, 0.86, 0.2)  # a felt beater
SKIN = (0.80, 0.58, 0.45, 0.15)
DRUMMER_SHIRT = (0.16, 0.30, 0.62, 0.1)
BASSIST_SHIRT = (0.55, 0.42, 0.12, 0.1)
TROUSERS = (0.10, 0.10, 0.12, 0.1)
DANCER_SHIRT = (0.55, 0.10, 0.35, 0.1)


def add_floor(dl: DrawList, size_m: tuple[float, float]) -> None:
    """The stage floor: a slab whose top is y = 0, ``size_m`` (x, z) metres."""
    w, d = size_m
    dl.add("box", box_transforms([[0, -0.05, 0]], [[w, 0.1, d]]), FLOOR)


def static_scene(geo: Geometry = GEOMETRY) -> DrawList:
    """The floor, drum shells and stands, the throne (the bass leans with its player:
    it is drawn with what moves, :func:`band_scene`)."""
    dl = DrawList()
    add_floor(dl, geo.stage.floor_size)
    kit = geo.kit
    dl.add(
        "cylinder",
        segment_transforms([kit.throne_centre - [0, 0.5, 0]], [kit.throne_centre], 0.03),
        CHROME,
    )
    dl.add(
        "cylinder",
        segment_transforms(
            [kit.throne_centre - [0, 0.05, 0]], [kit.throne_centre], kit.throne_radius
        ),
        BLACK,
    )
    rug_centre = geo.stage.drummer_origin + np.array([0.0, 0.004, 0.3])
    dl.add("cylinder", disc_transforms([rug_centre], [[0.0, 1.0, 0.0]], 1.05, 0.008), RUG)
    for name, piece in kit.pieces.items():
        if isinstance(piece, Drum):
            back = piece.centre - piece.normal * piece.depth
            dl.add(
                "cylinder",
                segment_transforms([back], [piece.centre - piece.normal * 0.004], piece.radius),
                SHELL,
            )
            # hoop
            dl.add(
                "cylinder",
                segment_transforms(
                    [piece.centre - piece.normal * 0.012],
                    [piece.centre + piece.normal * 0.006],
                    piece.radius + 0.008,
                ),
                CHROME,
            )
            if name != "kick":
                foot = np.array([piece.centre[0], 0.0, piece.centre[2]])
                dl.add("cylinder", segment_transforms([foot], [back], 0.012), CHROME)
        else:
            assert isinstance(piece, Cymbal)
            path = piece.stand()  # floor to under the cymbal: a stand, or mast and boom
            foot = path[0]
            dl.add("cylinder", segment_transforms(path[:-1], path[1:], 0.011), CHROME)
            for k in (0, 1, 2):  # tripod legs
                a = 2 * np.pi * k / 3
                dl.add(
                    "cylinder",
                    segment_transforms(
                        [foot + [0.22 * np.cos(a), 0.0, 0.22 * np.sin(a)]],
                        [foot + [0, 0.25, 0]],
                        0.008,
                    ),
                    CHROME,
                )
    # the footboards and the kick's beater move with the feet, the bass leans with its
    # player: both in band_scene (virja.render.pedals, BandPose.bass_transform)
    return dl.freeze()


_BASS_TABLES: dict[tuple[int, tuple[str, ...]], tuple[Geometry, dict[str, tuple[F64, F64]]]] = {}


def _bass_table(
    geo: Geometry, strings: tuple[str, ...] = BASS_STRINGS
) -> dict[str, tuple[F64, F64]]:
    """The upright bass's instances (models, colours) per kind in its own frame, built once
    per geometry and tuning (the fingerboard is as wide as the tuning's strings)."""
    hit = _BASS_TABLES.get((id(geo), strings))
    if hit is not None and hit[0] is geo:
        return hit[1]
    dl = DrawList()
    _bass_static(dl, geo, strings)
    table = {k: (np.concatenate(dl.models[k]), np.concatenate(dl.colors[k])) for k in dl.models}
    _BASS_TABLES[(id(geo), strings)] = (geo, table)
    return table


def _tuning(geo: Geometry, pose: BandPose) -> tuple[str, ...]:
    """The strings of the pose's tuning (four, five or six), low to high."""
    return tuple(s for s in geo.bass.strings if s in pose.string_vibration) or BASS_STRINGS


def _bass_instrument(
    dl: DrawList, geo: Geometry, transform: F64, strings: tuple[str, ...] = BASS_STRINGS
) -> None:
    """The bass's body, neck, fingerboard, bridge, tailpiece and endpin, leaning as
    ``transform`` (4, 4) says (``BandPose.bass_transform``)."""
    m = np.asarray(transform, dtype=np.float64)
    for kind, (models, colors) in _bass_table(geo, strings).items():
        dl.add(kind, models if np.array_equal(m, _EYE) else m @ models, colors)


_EYE = np.eye(4)


def _bass_static(dl: DrawList, geo: Geometry, strings: tuple[str, ...] = BASS_STRINGS) -> None:
    """The bass's parts in its own frame (:mod:`virja.geometry`, not leaning), its
    fingerboard and bridge as wide as ``strings`` (the tuning's) need."""
    b = geo.bass
    up = b.axis
    # the body: lower and upper bouts as flattened spheres, a waist between
    lower = b.body_centre - 0.22 * up
    upper = b.body_centre + 0.28 * up
    scale_lower = np.array([b.body_width / 2, 0.34, b.body_depth / 2])
    scale_upper = np.array([b.body_width / 2 * 0.8, 0.26, b.body_depth / 2])
    for c, s in ((lower, scale_lower), (upper, scale_upper)):
        m = np.eye(4)[None]
        m[0, :3, :3] = _orient(b) * s[None, :]
        m[0, :3, 3] = c
        dl.add("sphere", m, WOOD)
    dl.add(
        "box",
        box_transforms(
            [b.body_centre + 0.05 * up],
            [[b.body_width * 0.55, 0.3, b.body_depth * 0.9]],
            _orient(b)[None],
        ),
        WOOD,
    )
    # neck and scroll
    nut_c = np.mean([b.nut[s] for s in b.nut], axis=0)
    bridge_c = np.mean([b.bridge[s] for s in b.bridge], axis=0)
    dl.add(
        "cylinder",
        segment_transforms(
            [b.body_centre + 0.5 * up - 0.03 * b.front], [nut_c - 0.02 * b.front + 0.02 * up], 0.028
        ),
        WOOD,
    )
    dl.add("sphere", sphere_transforms([nut_c + 0.10 * up - 0.02 * b.front], 0.05), WOOD)
    # the fingerboard: from the nut down past the neck joint, tapering with the tuning's
    # strings (virja.fingerboard; its face 4 mm behind them), drawn as three sheared boxes
    board = fingerboard(b, strings)
    dl.add("box", board.pieces(), EBONY)
    # bridge and tailpiece
    dl.add(
        "box",
        box_transforms(
            [bridge_c - 0.02 * b.front],
            [[_bridge_width(b, strings), 0.08, 0.012]],
            _orient(b)[None],
        ),
        (0.75, 0.6, 0.4, 0.2),
    )
    dl.add(
        "box",
        box_transforms(
            [bridge_c - 0.20 * up + 0.0 * b.front], [[0.09, 0.22, 0.012]], _orient(b)[None]
        ),
        EBONY,
    )
    dl.add("cylinder", segment_transforms([b.endpin], [b.endpin + 0.2 * up], 0.008), CHROME)


def _bridge_width(b: Any, strings: tuple[str, ...]) -> float:
    """The bridge: 13 cm, or the tuning's strings' spread on it and 1 cm beyond each."""
    lateral = _orient(b)[:, 0]
    lat = [float(b.bridge[s] @ lateral) for s in strings]
    return max(0.13, max(lat) - min(lat) + 0.02)


def _orient(b: Any) -> F64:
    """Rotation with columns (lateral, axis, front) of the bass."""
    lateral = np.cross(b.axis, b.front)
    lateral /= np.linalg.norm(lateral)
    return np.stack([lateral, b.axis, b.front], axis=1)


def band_scene(pose: BandPose, geo: Geometry = GEOMETRY) -> DrawList:
    """Everything that moves, from a :class:`~virja.motion.pose.BandPose`.

    Vectorised: what depends only on the geometry (drum-head discs, colour and
    index arrays of each figure) is built once per geometry and skeleton
    (:func:`_kit_table`, :func:`_figure_table`); a frame gathers the segments
    (strings, limbs, sticks) and spheres of every part and turns them into
    instance matrices in one numpy pass each: no loop over hits, strings or
    joints.  Rows keep the order of the plain per-part version
    (tests/render/test_scene_vectorised.py).
    """
    kit_cyl, kit_color, bells = _kit_rows(geo, pose)
    s = np.asarray(pose.sticks, dtype=np.float64).reshape(-1, 2, 3)
    stick = _Parts(
        segments=[(s[:, 0], s[:, 1], np.full(len(s), 0.0075), _rows(STICK, len(s)))],
        spheres=[(s[:, 1], np.full(len(s), 0.009), _rows(STICK, len(s)))],
    )
    fingers = np.asarray(pose.bass_fingers, dtype=np.float64).reshape(-1, 2, 3)
    parts = [bells, _string_parts(geo, pose), _figure_parts(pose.drums, DRUMMER_SHIRT)]
    if len(fingers):
        # fingers instead of the one-piece hands: a palm to the knuckles, two bones a finger
        parts.append(_figure_parts(pose.bass, BASSIST_SHIRT, skip=("LeftHandEnd", "RightHandEnd")))
        parts.append(_finger_parts(pose.bass, fingers))
    else:
        parts.append(_figure_parts(pose.bass, BASSIST_SHIRT))
    parts.append(stick)
    boards, (kick_down, _hh_down) = footboards(geo, pose)
    axle, ball = beater(geo, kick_down)
    parts.append(
        _Parts(
            segments=[(axle[None], ball[None], np.full(1, 0.006), _rows(CHROME, 1))],
            spheres=[(ball[None], np.full(1, BEATER_BALL_M), _rows(BEATER, 1))],
        )
    )
    dl = DrawList()
    dl.add("box", boards, CHROME)
    seg, seg_color = _segment_rows(parts)
    dl.add("cylinder", np.concatenate([kit_cyl, seg]), np.concatenate([kit_color, seg_color]))
    sph, sph_color = _sphere_rows(parts)
    dl.add("sphere", sph, sph_color)
    _bass_instrument(dl, geo, pose.bass_transform, _tuning(geo, pose))
    return dl


def figure_scene(fig: FigurePose, shirt: tuple[float, ...] = DANCER_SHIRT) -> DrawList:
    """One more figure (the dancer) as solid limbs, in its own shirt colour."""
    dl = DrawList()
    _figure(dl, fig, shirt)
    return dl


Segments = tuple[F64, F64, F64, F64]  # from (n, 3), to (n, 3), radius (n,), colour (n, 4)
Spheres = tuple[F64, F64, F64]  # centre (n, 3), radius (n,), colour (n, 4)


@dataclass
class _Parts:
    """Cylinders (as segments) and spheres of some moving parts, not yet matrices."""

    segments: list[Segments]
    spheres: list[Spheres]


def _rows(color: tuple[float, ...], n: int) -> F64:
    return np.broadcast_to(np.asarray(color, dtype=np.float64), (n, 4))


def _segment_rows(parts: list[_Parts]) -> tuple[F64, F64]:
    segs = [x for p in parts for x in p.segments]
    a = np.concatenate([x[0] for x in segs])
    b = np.concatenate([x[1] for x in segs])
    r = np.concatenate([x[2] for x in segs])
    return segment_transforms(a, b, r), np.concatenate([x[3] for x in segs])


def _sphere_rows(parts: list[_Parts]) -> tuple[F64, F64]:
    sph = [x for p in parts for x in p.spheres]
    c = np.concatenate([x[0] for x in sph])
    r = np.concatenate([x[1] for x in sph])
    return sphere_transforms(c, r), np.concatenate([x[2] for x in sph])


@dataclass(frozen=True)
class _KitTable:
    """The kit's moving parts, laid out once per geometry (pieces in the kit's order).

    Cylinder rows: each drum's head, the hi-hat's bottom cymbal, each cymbal's
    disc; sphere rows: each cymbal's bell.  Heads and the bottom hi-hat never
    move (``cyl_base``); a frame writes the heads' colours and the cymbals'
    transforms.
    """

    cyl_base: F64  # (n_cyl, 4, 4)
    cyl_color: F64  # (n_cyl, 4)
    drums: tuple[str, ...]
    drum_rows: NDArray[np.intp]
    cymbals: tuple[str, ...]
    cymbal_rows: NDArray[np.intp]
    centre: F64  # (n_cym, 3)
    normal: F64  # (n_cym, 3)
    swing_axis: F64  # (n_cym, 3) unit
    radius: F64  # (n_cym,)
    thickness: F64  # (n_cym,)
    hihat: int  # index of the hi-hat among the cymbals, or -1


_KIT_TABLES: dict[int, tuple[Geometry, _KitTable]] = {}


def _kit_table(geo: Geometry) -> _KitTable:
    hit = _KIT_TABLES.get(id(geo))
    if hit is not None and hit[0] is geo:
        return hit[1]
    rows: list[F64] = []
    colors: list[tuple[float, ...]] = []
    drums: list[str] = []
    drum_rows: list[int] = []
    cymbals: list[str] = []
    cymbal_rows: list[int] = []
    cym: list[tuple[F64, F64, F64, float, float]] = []
    hihat = -1
    for name, piece in geo.kit.pieces.items():
        if isinstance(piece, Drum):
            drums.append(name)
            drum_rows.append(len(rows))
            rows.append(
                disc_transforms(
                    [piece.centre - piece.normal * 0.002], [piece.normal], piece.radius, 0.004
                )[0]
            )
            colors.append(HEAD)
            continue
        assert isinstance(piece, Cymbal)
        centre = np.asarray(piece.centre, dtype=np.float64)
        normal = np.asarray(piece.normal, dtype=np.float64)
        if name == "hihat":
            # the bottom cymbal stays; the top one rises off it as the pedal lets go
            hihat = len(cymbals)
            centre = centre - np.array([0.0, 0.02, 0.0])
            rows.append(disc_transforms([centre], [normal], piece.radius, piece.thickness)[0])
            colors.append(BRASS)
        axis = np.cross(normal, np.array([0.0, 0.0, 1.0]))
        if np.linalg.norm(axis) < 1e-6:
            axis = np.array([1.0, 0.0, 0.0])
        cymbals.append(name)
        cymbal_rows.append(len(rows))
        rows.append(np.eye(4))
        colors.append(BRASS)
        cym.append((centre, normal, axis / np.linalg.norm(axis), piece.radius, piece.thickness))
    table = _KitTable(
        cyl_base=np.array(rows).reshape(-1, 4, 4),
        cyl_color=np.array(colors, dtype=np.float64).reshape(-1, 4),
        drums=tuple(drums),
        drum_rows=np.array(drum_rows, dtype=np.intp),
        cymbals=tuple(cymbals),
        cymbal_rows=np.array(cymbal_rows, dtype=np.intp),
        centre=np.array([c[0] for c in cym]).reshape(-1, 3),
        normal=np.array([c[1] for c in cym]).reshape(-1, 3),
        swing_axis=np.array([c[2] for c in cym]).reshape(-1, 3),
        radius=np.array([c[3] for c in cym], dtype=np.float64),
        thickness=np.array([c[4] for c in cym], dtype=np.float64),
        hihat=hihat,
    )
    _KIT_TABLES[id(geo)] = (geo, table)
    return table


def _kit_rows(geo: Geometry, pose: BandPose) -> tuple[F64, F64, _Parts]:
    """The kit's cylinder matrices and colours, and its bells as spheres."""
    t = _kit_table(geo)
    cyl = t.cyl_base.copy()
    color = t.cyl_color.copy()
    if t.drums:
        hits = np.array([pose.head_hits.get(n, 0.0) for n in t.drums], dtype=np.float64)
        h = np.clip(hits, 0.0, 1.0)[:, None]
        color[t.drum_rows] = np.array(HEAD) * (1 - h) + np.array(HEAD_HIT) * h
    if not t.cymbals:
        return cyl, color, _Parts([], [])
    angle = np.array([pose.cymbal_swing.get(n, 0.0) for n in t.cymbals], dtype=np.float64)
    normal = quat.rotate_about(t.normal, t.swing_axis, angle)
    centre = t.centre.copy()
    if t.hihat >= 0:
        lift = 0.004 + 0.016 * float(np.clip(pose.hihat_open, 0.0, 1.0))
        centre[t.hihat, 1] += lift
    cyl[t.cymbal_rows] = disc_transforms(centre, normal, t.radius, t.thickness)
    bells = _Parts([], [(centre, t.radius * 0.14, _rows(BRASS, len(centre)))])
    return cyl, color, bells


def _kit_dynamic(dl: DrawList, geo: Geometry, pose: BandPose) -> None:
    cyl, color, bells = _kit_rows(geo, pose)
    dl.add("cylinder", cyl, color)
    if bells.spheres:
        sph, sph_color = _sphere_rows([bells])
        dl.add("sphere", sph, sph_color)


@dataclass(frozen=True)
class _StringTable:
    nut: F64  # (n, 3)
    bridge: F64  # (n, 3)
    points: F64  # (n, max_fret + 1, 3): where each fret stops each string
    radius: F64  # (n,)
    lateral: F64  # (3,)
    index: NDArray[np.float64]  # (n,) k of each string from the E string up (its rate)
    _subsets: dict[tuple[int, ...], _StringTable]

    def subset(self, rows: list[int]) -> _StringTable:
        """The table of some strings (the tuning's), cached per choice."""
        key = tuple(rows)
        if key == tuple(range(len(self.nut))):
            return self
        hit = self._subsets.get(key)
        if hit is None:
            r = np.asarray(rows, dtype=np.intp)
            hit = _StringTable(
                self.nut[r],
                self.bridge[r],
                self.points[r],
                self.radius[r],
                self.lateral,
                self.index[r],
                {},
            )
            self._subsets[key] = hit
        return hit


_STRING_TABLES: dict[int, tuple[Geometry, _StringTable]] = {}


def _string_table(geo: Geometry) -> _StringTable:
    hit = _STRING_TABLES.get(id(geo))
    if hit is not None and hit[0] is geo:
        return hit[1]
    b = geo.bass
    lateral = np.cross(b.axis, b.front)
    lateral /= np.linalg.norm(lateral)
    strings = list(b.strings)
    k = np.arange(len(strings), dtype=np.float64) - strings.index("E")  # thinner from E up
    table = _StringTable(
        nut=np.array([b.nut[s] for s in strings], dtype=np.float64),
        bridge=np.array([b.bridge[s] for s in strings], dtype=np.float64),
        points=np.array(
            [[b.string_point(s, f) for f in range(b.max_fret + 1)] for s in strings],
            dtype=np.float64,
        ),
        radius=0.0022 - 0.0003 * k,
        lateral=lateral,
        index=k,
        _subsets={},
    )
    _STRING_TABLES[id(geo)] = (geo, table)
    return table


def _strings(dl: DrawList, geo: Geometry, pose: BandPose, segments: int = 12) -> None:
    seg, color = _segment_rows([_string_parts(geo, pose, segments)])
    dl.add("cylinder", seg, color)


def _string_parts(geo: Geometry, pose: BandPose, segments: int = 12) -> _Parts:
    """Strings nut -> bridge; a vibrating one bows sideways between its stop and the bridge.

    All strings in one batch: a still string is one segment nut -> bridge; a
    vibrating one is nut -> its stop, then ``segments`` bowed pieces to the
    bridge (rows in string order, as drawn one by one before)."""
    full = _string_table(geo)
    b = geo.bass
    # the strings drawn are the pose's (the tuning's: four, five or six)
    strings = [s for s in b.strings if s in pose.string_vibration] or list(BASS_STRINGS)
    t = full.subset([b.strings.index(s) for s in strings])
    amp = np.array([pose.string_vibration.get(s, 0.0) for s in strings], dtype=np.float64)
    vib = amp > 1e-5
    fret = np.array([pose.string_stops.get(s, 0) for s in strings], dtype=np.intp)
    fret = np.clip(fret, 0, t.points.shape[1] - 1)
    stop = t.points[np.arange(len(strings)), fret]
    plain_end = np.where(vib[:, None], stop, t.bridge)
    counts = 1 + segments * vib.astype(np.intp)
    first = np.cumsum(counts) - counts  # each string's first row
    n = int(counts.sum())
    a = np.empty((n, 3))
    z = np.empty((n, 3))
    radius = np.empty(n)
    color = np.empty((n, 4))
    a[first] = t.nut
    z[first] = plain_end
    radius[first] = t.radius
    color[first] = STRING
    if vib.any():
        v = np.flatnonzero(vib)
        u, shape = _mode(segments)
        pts = stop[v, None] + u * (t.bridge[v, None] - stop[v, None])
        # the fundamental mode of the vibrating part, swinging at a visible rate
        swing = np.cos(2 * np.pi * (9.0 + 1.3 * t.index[v]) * pose.time_s)
        bow = amp[v, None] * shape * swing[:, None]
        pts = pts + t.lateral * bow[..., None]
        rows = (first[v, None] + 1 + np.arange(segments)[None, :]).reshape(-1)
        a[rows] = pts[:, :-1].reshape(-1, 3)
        z[rows] = pts[:, 1:].reshape(-1, 3)
        radius[rows] = np.repeat(t.radius[v] * 1.3, segments)
        color[rows] = STRING_HOT
    m = np.asarray(pose.bass_transform, dtype=np.float64)
    if not np.array_equal(m, _EYE):  # the strings lean with the bass
        a = a @ m[:3, :3].T + m[:3, 3]
        z = z @ m[:3, :3].T + m[:3, 3]
    return _Parts([(a, z, radius, color)], [])


@cache
def _mode(segments: int) -> tuple[F64, F64]:
    """Points along a vibrating part (1, segments + 1, 1) and its mode shape sin(pi u)."""
    u = np.linspace(0.0, 1.0, segments + 1)[None, :, None]
    return u, np.sin(np.pi * u[..., 0])


@dataclass(frozen=True)
class _FigureTable:
    """Index and colour arrays of one skeleton in one shirt (built once, not per frame)."""

    limb_child: NDArray[np.intp]
    limb_parent: NDArray[np.intp]
    limb_color: F64
    joints: NDArray[np.intp]
    joint_color: F64
    head: int  # -1 when the skeleton has no Head / HeadEnd
    head_end: int


@cache
def _figure_table(
    names: tuple[str, ...], parents: bytes, shirt: tuple[float, ...], skip: tuple[str, ...] = ()
) -> _FigureTable:
    """``parents``: the int64 parent indices' bytes (hashable, cheap to make each frame);
    ``skip``: joints drawn otherwise (the bassist's hands, drawn with fingers)."""
    par = np.frombuffer(parents, dtype=np.int64).astype(np.intp)
    is_head = np.array([n.lower() in ("head", "headend") or n in skip for n in names], dtype=bool)
    child = np.nonzero((par >= 0) & ~is_head)[0]
    joints = np.nonzero(~is_head)[0]
    has_head = "Head" in names and "HeadEnd" in names
    return _FigureTable(
        limb_child=child,
        limb_parent=par[child],
        limb_color=np.array([_limb_color(names[i], shirt) for i in child]).reshape(-1, 4),
        joints=joints,
        joint_color=np.array([_limb_color(names[i], shirt) for i in joints]).reshape(-1, 4),
        head=names.index("Head") if has_head else -1,
        head_end=names.index("HeadEnd") if has_head else -1,
    )


def _fingers(dl: DrawList, fig: FigurePose, bones: F64) -> None:
    """The bassist's finger bones (k, 2, 3) with a palm from each wrist to its knuckles."""
    parts = [_finger_parts(fig, bones)]
    seg, seg_color = _segment_rows(parts)
    dl.add("cylinder", seg, seg_color)
    sph, sph_color = _sphere_rows(parts)
    dl.add("sphere", sph, sph_color)


def _finger_parts(fig: FigurePose, bones: F64) -> _Parts:
    names = fig.names
    pos = np.asarray(fig.positions, dtype=np.float64)
    half = LEFT_FINGER_BONES
    palms = [
        (pos[names.index(wrist)], knuckles.mean(axis=0))
        for wrist, knuckles in (
            ("LeftHand", bones[:8:2, 0]),
            ("RightHand", bones[half : half + 4 : 2, 0]),
        )
        if len(knuckles)
    ]
    n, k = len(palms), len(bones)
    segments: list[Segments] = []
    if n:
        a = np.array([p[0] for p in palms])
        z = np.array([p[1] for p in palms])
        segments.append((a, z, np.full(n, 0.022), _rows(SKIN, n)))
    segments.append((bones[:, 0], bones[:, 1], np.full(k, 0.0075), _rows(SKIN, k)))
    return _Parts(segments, [(bones[:, 1], np.full(k, 0.008), _rows(SKIN, k))])


def _figure(
    dl: DrawList, fig: FigurePose, shirt: tuple[float, ...], skip: tuple[str, ...] = ()
) -> None:
    parts = [_figure_parts(fig, shirt, skip)]
    seg, seg_color = _segment_rows(parts)
    dl.add("cylinder", seg, seg_color)
    sph, sph_color = _sphere_rows(parts)
    dl.add("sphere", sph, sph_color)


def _figure_parts(fig: FigurePose, shirt: tuple[float, ...], skip: tuple[str, ...] = ()) -> _Parts:
    """Limbs (parent joint -> joint) and joints of a figure; the head and its nose."""
    pos = np.asarray(fig.positions, dtype=np.float64)
    radii = np.asarray(fig.radii, dtype=np.float64)
    t = _figure_table(tuple(fig.names), np.asarray(fig.parents).tobytes(), tuple(shirt), skip)
    parts = _Parts(
        [(pos[t.limb_parent], pos[t.limb_child], radii[t.limb_child], t.limb_color)],
        [(pos[t.joints], radii[t.joints] * 1.05, t.joint_color)],
    )
    if t.head >= 0:
        # the head: one sphere between the base of the skull and its top, a nose to show where it looks
        centre = (pos[t.head] + pos[t.head_end]) / 2
        rot = np.asarray(fig.rotations)[t.head]
        forward = quat.rotate_one(rot, np.array([0.0, 0.0, 1.0]))
        parts.spheres.append(
            (np.stack([centre, centre + forward * 0.1]), np.array([0.105, 0.022]), _rows(SKIN, 2))
        )
    return parts


def _limb_color(name: str, shirt: tuple[float, ...]) -> tuple[float, ...]:
    n = name.lower()
    if any(k in n for k in ("hand", "finger", "head", "neck", "thumb")):
        return SKIN
    if any(
        k in n for k in ("leg", "knee", "foot", "toe", "thigh", "shin", "ankle", "up_leg", "hip")
    ):
        return TROUSERS
    return shirt
