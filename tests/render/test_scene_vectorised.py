"""The vectorised band scene equals the plain one (one numpy call per instance, as
written before the speed work), row for row, on real poses of the demo: drum heads
lit by hits, cymbals swinging, the hi-hat opening, strings vibrating at stops."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from virja import quat
from virja.bench import _demo_animator
from virja.geometry import GEOMETRY, Cymbal, Drum, Geometry
from virja.motion.pose import LEFT_FINGER_BONES, BandPose, FigurePose
from virja.render.meshes import disc_transforms, segment_transforms, sphere_transforms
from virja.render.pedals import BEATER_BALL_M, beater, footboards
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
    _bass_static,
    _limb_color,
    band_scene,
)
from virja.vocab import BASS_STRINGS

F64 = Any


def plain_band_scene(pose: BandPose, geo: Geometry = GEOMETRY) -> DrawList:
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
    boards, (kick_down, _hihat_down) = footboards(geo, pose)
    axle, ball = beater(geo, kick_down)
    dl.add("cylinder", segment_transforms([axle], [ball], 0.006), CHROME)
    dl.add("sphere", sphere_transforms([ball], BEATER_BALL_M), BEATER)
    dl.add("box", boards, CHROME)
    # the bass, leaning with its player: its parts in its own frame, moved as one
    own = DrawList()
    _bass_static(own, geo)
    for kind in own.models:
        for models, colors in zip(own.models[kind], own.colors[kind], strict=True):
            dl.add(kind, pose.bass_transform @ models, colors)
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
            dl.add("cylinder", segment_transforms(*_leaned(pose, [a], [z]), radius), STRING)
            continue
        fret = int(pose.string_stops.get(s, 0))
        stop = b.string_point(s, min(max(fret, 0), b.max_fret))
        dl.add("cylinder", segment_transforms(*_leaned(pose, [a], [stop]), radius), STRING)
        u = np.linspace(0.0, 1.0, segments + 1)[:, None]
        pts = stop + u * (z - stop)
        # the fundamental mode of the vibrating part, swinging at a visible rate
        swing = np.cos(2 * np.pi * (9.0 + 1.3 * k) * pose.time_s)
        pts = pts + lateral * (amp * np.sin(np.pi * u) * swing)
        dl.add(
            "cylinder",
            segment_transforms(*_leaned(pose, pts[:-1], pts[1:]), radius * 1.3),
            STRING_HOT,
        )


def _leaned(pose: BandPose, a: Any, z: Any) -> tuple[F64, F64]:
    """Segment ends moved with the bass (it leans with its player)."""
    m = pose.bass_transform
    return np.asarray(a) @ m[:3, :3].T + m[:3, 3], np.asarray(z) @ m[:3, :3].T + m[:3, 3]


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
        forward = quat.rotate_one(rot, np.array([0.0, 0.0, 1.0]))
        dl.add("sphere", sphere_transforms([centre + forward * 0.1], 0.022), SKIN)


@pytest.fixture(scope="module")
def poses() -> list[BandPose]:
    animator, t0, t1 = _demo_animator()
    return [animator.pose(float(t)) for t in np.arange(t0, min(t1, 12.0), 1 / 8)]


def test_band_scene_equals_the_plain_one(poses: list[BandPose]) -> None:
    lit = swung = vibrating = 0
    for pose in poses:
        lit += any(v > 0.05 for v in pose.head_hits.values())
        swung += any(abs(v) > 1e-4 for v in pose.cymbal_swing.values())
        vibrating += any(v > 1e-5 for v in pose.string_vibration.values())
        fast, plain = band_scene(pose), plain_band_scene(pose)
        for kind in ("cylinder", "sphere", "box"):
            np.testing.assert_allclose(fast.packed(kind), plain.packed(kind), rtol=0, atol=1e-6)
    # the poses exercise every moving part
    assert lit > 5 and swung > 5 and vibrating > 5
    assert any(len(p.bass_fingers) for p in poses)  # the bassist's fingers drawn too
    assert any(not np.allclose(p.bass_transform, np.eye(4)) for p in poses)  # the bass leans
