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

from typing import Any

import numpy as np
from numpy.typing import NDArray

from virja.geometry import BASS_STRINGS, GEOMETRY, Cymbal, Drum, Geometry
from virja.motion.pose import LEFT_FINGER_BONES, BandPose, FigurePose
from virja.render.meshes import (
    box_transforms,
    disc_transforms,
    segment_transforms,
    sphere_transforms,
)
from virja.render.renderer import DrawList

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
SKIN = (0.80, 0.58, 0.45, 0.15)
DRUMMER_SHIRT = (0.16, 0.30, 0.62, 0.1)
BASSIST_SHIRT = (0.55, 0.42, 0.12, 0.1)
TROUSERS = (0.10, 0.10, 0.12, 0.1)
DANCER_SHIRT = (0.55, 0.10, 0.35, 0.1)


def _rotation_to(axis: F64) -> F64:
    """A (3, 3) rotation whose columns are x, y=axis, z."""
    y = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    return np.stack([x, y, z], axis=1)


def add_floor(dl: DrawList, size_m: tuple[float, float]) -> None:
    """The stage floor: a slab whose top is y = 0, ``size_m`` (x, z) metres."""
    w, d = size_m
    dl.add("box", box_transforms([[0, -0.05, 0]], [[w, 0.1, d]]), FLOOR)


def static_scene(geo: Geometry = GEOMETRY) -> DrawList:
    """The floor, drum shells and stands, the throne, the bass body and neck."""
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
            foot = np.array([piece.centre[0], 0.0, piece.centre[2]])
            top = piece.centre - piece.normal * 0.02
            dl.add("cylinder", segment_transforms([foot], [top], 0.011), CHROME)
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
    for pedal in (kit.kick_pedal, kit.hihat_pedal):
        dl.add(
            "box",
            box_transforms(
                [pedal.heel + pedal.board * pedal.length / 2], [[0.09, 0.02, pedal.length]]
            ),
            CHROME,
        )
    _bass_static(dl, geo)
    return dl.freeze()


def _bass_static(dl: DrawList, geo: Geometry) -> None:
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
    # fingerboard: a long thin box from the nut down past the neck joint
    # (along the strings, which rise off the neck toward the bridge: its face stays 4 mm
    # behind them from the nut down)
    fb_end = nut_c + 0.78 * (bridge_c - nut_c)
    along = (fb_end - nut_c) / np.linalg.norm(fb_end - nut_c)
    face = b.front - np.dot(b.front, along) * along
    face /= np.linalg.norm(face)
    board = np.stack([np.cross(along, face), along, face], axis=1)
    mid = (nut_c + fb_end) / 2 - 0.011 * face
    length = float(np.linalg.norm(fb_end - nut_c))
    dl.add("box", box_transforms([mid], [[0.07, length, 0.014]], board[None]), EBONY)
    # bridge and tailpiece
    dl.add(
        "box",
        box_transforms([bridge_c - 0.02 * b.front], [[0.13, 0.08, 0.012]], _orient(b)[None]),
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


def _orient(b: Any) -> F64:
    """Rotation with columns (lateral, axis, front) of the bass."""
    lateral = np.cross(b.axis, b.front)
    lateral /= np.linalg.norm(lateral)
    return np.stack([lateral, b.axis, b.front], axis=1)


def band_scene(pose: BandPose, geo: Geometry = GEOMETRY) -> DrawList:
    """Everything that moves, from a :class:`~virja.motion.pose.BandPose`."""
    dl = DrawList()
    _kit_dynamic(dl, geo, pose)
    _strings(dl, geo, pose)
    _figure(dl, pose.drums, DRUMMER_SHIRT)
    fingers = np.asarray(pose.bass_fingers, dtype=np.float64).reshape(-1, 2, 3)
    if len(fingers):
        # fingers instead of the one-piece hands: a palm to the knuckles, two bones a finger
        _figure(dl, pose.bass, BASSIST_SHIRT, skip=("LeftHandEnd", "RightHandEnd"))
        _fingers(dl, pose.bass, fingers)
    else:
        _figure(dl, pose.bass, BASSIST_SHIRT)
    s = np.asarray(pose.sticks, dtype=np.float64).reshape(-1, 2, 3)
    dl.add("cylinder", segment_transforms(s[:, 0], s[:, 1], 0.0075), STICK)
    dl.add("sphere", sphere_transforms(s[:, 1], 0.009), STICK)
    return dl


def figure_scene(fig: FigurePose, shirt: tuple[float, ...] = DANCER_SHIRT) -> DrawList:
    """One more figure (the dancer) as solid limbs, in its own shirt colour."""
    dl = DrawList()
    _figure(dl, fig, shirt)
    return dl


def _kit_dynamic(dl: DrawList, geo: Geometry, pose: BandPose) -> None:
    kit = geo.kit
    for name, piece in kit.pieces.items():
        if isinstance(piece, Drum):
            h = float(np.clip(pose.head_hits.get(name, 0.0), 0.0, 1.0))
            color = tuple(np.array(HEAD) * (1 - h) + np.array(HEAD_HIT) * h)
            disc = disc_transforms(
                [piece.centre - piece.normal * 0.002], [piece.normal], piece.radius, 0.004
            )
            dl.add("cylinder", disc, color)
            continue
        assert isinstance(piece, Cymbal)
        normal = piece.normal
        angle = float(pose.cymbal_swing.get(name, 0.0))
        if angle:
            axis = np.cross(normal, np.array([0.0, 0.0, 1.0]))
            if np.linalg.norm(axis) < 1e-6:
                axis = np.array([1.0, 0.0, 0.0])
            normal = _rotate(normal, axis / np.linalg.norm(axis), angle)
        centre = piece.centre
        if name == "hihat":
            # the bottom cymbal stays; the top one rises off it as the pedal lets go
            bottom = centre - np.array([0.0, 0.02, 0.0])
            dl.add(
                "cylinder",
                disc_transforms([bottom], [piece.normal], piece.radius, piece.thickness),
                BRASS,
            )
            lift = 0.004 + 0.016 * float(np.clip(pose.hihat_open, 0.0, 1.0))
            centre = bottom + np.array([0.0, lift, 0.0])
        dl.add(
            "cylinder", disc_transforms([centre], [normal], piece.radius, piece.thickness), BRASS
        )
        dl.add("sphere", sphere_transforms([centre], piece.radius * 0.14), BRASS)  # the bell


def _rotate(v: F64, axis: F64, angle: float) -> F64:
    c, s = np.cos(angle), np.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * np.dot(axis, v) * (1 - c)


def _strings(dl: DrawList, geo: Geometry, pose: BandPose, segments: int = 12) -> None:
    """Strings nut -> bridge; a vibrating one bows sideways between its stop and the bridge.

    The strings drawn are the pose's (the tuning's: four, five or six)."""
    b = geo.bass
    lateral = np.cross(b.axis, b.front)
    lateral /= np.linalg.norm(lateral)
    drawn = [s for s in b.strings if s in pose.string_vibration] or list(BASS_STRINGS)
    for s in drawn:
        k = b.strings.index(s) - b.strings.index("E")  # thinner from the E string up
        a, z = b.nut[s], b.bridge[s]
        amp = float(pose.string_vibration.get(s, 0.0))
        radius = 0.0022 - 0.0003 * k
        if amp <= 1e-5:
            dl.add("cylinder", segment_transforms([a], [z], radius), STRING)
            continue
        fret = int(pose.string_stops.get(s, 0))
        stop = b.string_point(s, min(max(fret, 0), b.max_fret))
        dl.add("cylinder", segment_transforms([a], [stop], radius), STRING)
        u = np.linspace(0.0, 1.0, segments + 1)[:, None]
        pts = stop + u * (z - stop)
        # the fundamental mode of the vibrating part, swinging at a visible rate
        swing = np.cos(2 * np.pi * (9.0 + 1.3 * k) * pose.time_s)
        pts = pts + lateral * (amp * np.sin(np.pi * u) * swing)
        dl.add("cylinder", segment_transforms(pts[:-1], pts[1:], radius * 1.3), STRING_HOT)


def _fingers(dl: DrawList, fig: FigurePose, bones: F64) -> None:
    """The bassist's finger bones (k, 2, 3) with a palm from each wrist to its knuckles."""
    names = list(fig.names)
    pos = np.asarray(fig.positions, dtype=np.float64)
    half = LEFT_FINGER_BONES
    for wrist, knuckles in (
        ("LeftHand", bones[:8:2, 0]),
        ("RightHand", bones[half : half + 4 : 2, 0]),
    ):
        if len(knuckles):
            w = pos[names.index(wrist)]
            dl.add("cylinder", segment_transforms([w], [knuckles.mean(axis=0)], 0.022), SKIN)
    dl.add("cylinder", segment_transforms(bones[:, 0], bones[:, 1], 0.0075), SKIN)
    dl.add("sphere", sphere_transforms(bones[:, 1], 0.008), SKIN)


def _figure(
    dl: DrawList, fig: FigurePose, shirt: tuple[float, ...], skip: tuple[str, ...] = ()
) -> None:
    pos = np.asarray(fig.positions, dtype=np.float64)
    parents = np.asarray(fig.parents)
    radii = np.asarray(fig.radii, dtype=np.float64)
    names = list(fig.names)
    is_head = np.array([n.lower() in ("head", "headend") or n in skip for n in names])
    child = np.nonzero((parents >= 0) & ~is_head)[0]
    colors = np.array([_limb_color(names[i], shirt) for i in child])
    dl.add("cylinder", segment_transforms(pos[parents[child]], pos[child], radii[child]), colors)
    joints = np.nonzero(~is_head)[0]
    joint_colors = np.array([_limb_color(names[i], shirt) for i in joints])
    dl.add("sphere", sphere_transforms(pos[joints], radii[joints] * 1.05), joint_colors)
    if "Head" in names and "HeadEnd" in names:
        # the head: one sphere between the base of the skull and its top, a nose to show where it looks
        a, b = pos[names.index("Head")], pos[names.index("HeadEnd")]
        centre = (a + b) / 2
        dl.add("sphere", sphere_transforms([centre], 0.105), SKIN)
        rot = np.asarray(fig.rotations)[names.index("Head")]
        forward = _quat_rotate(rot, np.array([0.0, 0.0, 1.0]))
        dl.add("sphere", sphere_transforms([centre + forward * 0.1], 0.022), SKIN)


def _quat_rotate(q: F64, v: F64) -> F64:
    """Rotate ``v`` (3,) by the unit quaternion ``q`` (w, x, y, z)."""
    w, u = q[0], q[1:]
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def _limb_color(name: str, shirt: tuple[float, ...]) -> tuple[float, ...]:
    n = name.lower()
    if any(k in n for k in ("hand", "finger", "head", "neck", "thumb")):
        return SKIN
    if any(
        k in n for k in ("leg", "knee", "foot", "toe", "thigh", "shin", "ankle", "up_leg", "hip")
    ):
        return TROUSERS
    return shirt
