"""The kit's pedals as they move (issue 15, deliverable 4): footboards and the kick's beater.

Each footboard turns about its heel from its raised direction toward its
pressed one as far as the foot's toe has pressed it (the toe's height between
the two toe points of :class:`virja.geometry.Pedal`; a toe above the raised
board leaves it raised).  The kick's beater turns with its footboard: back
toward the drummer at rest, its ball on the batter head when the board is
down, so the beater hits the head on the kick notes the right foot plays.
Vectorised over the pedals; drawn by :func:`virja.render.scene.band_scene`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from virja.geometry import Drum, Geometry, Pedal
from virja.motion.pose import BandPose
from virja.render.meshes import box_transforms

F64 = NDArray[np.float64]

BOARD_SIZE = (0.09, 0.02)  # width, thickness (m); the length is the pedal's
BEATER_SHAFT_M = 0.17
BEATER_BALL_M = 0.03
BEATER_PIVOT_IN_FRONT_M = 0.06  # the beater's axle, this far in front of the head
BEATER_REST_DEG = 50.0  # the beater leans back this far toward the drummer at rest


def pressed(pedal: Pedal, toe_y: float) -> float:
    """How far (0 raised .. 1 pressed) a toe at height ``toe_y`` has pressed ``pedal``."""
    up_y, down_y = float(pedal.toe_point(False)[1]), float(pedal.toe_point(True)[1])
    return float(np.clip((up_y - toe_y) / max(up_y - down_y, 1e-6), 0.0, 1.0))


def board_direction(pedal: Pedal, down: float) -> F64:
    """The footboard's unit direction heel -> toe when pressed ``down`` (0..1)."""
    a = np.arctan2(pedal.board[1], np.hypot(pedal.board[0], pedal.board[2]))
    b = np.arctan2(pedal.pressed_board[1], np.hypot(pedal.pressed_board[0], pedal.pressed_board[2]))
    horiz = np.array([pedal.board[0], 0.0, pedal.board[2]])
    horiz /= max(float(np.linalg.norm(horiz)), 1e-12)
    ang = a + (b - a) * down
    return np.asarray(np.cos(ang) * horiz + np.sin(ang) * np.array([0.0, 1.0, 0.0]))


def footboards(geo: Geometry, pose: BandPose) -> tuple[F64, tuple[float, float]]:
    """Box instances (2, 4, 4) of the kick's and the hi-hat's footboards, and how far
    each is pressed (kick, hi-hat)."""
    kit = geo.kit
    downs = (
        pressed(kit.kick_pedal, float(pose.drums.position("RightToe")[1])),
        pressed(kit.hihat_pedal, float(pose.drums.position("LeftToe")[1])),
    )
    centres, rots = [], []
    for pedal, down in zip((kit.kick_pedal, kit.hihat_pedal), downs, strict=True):
        d = board_direction(pedal, down)
        side = np.cross(np.array([0.0, 1.0, 0.0]), d)
        side /= max(float(np.linalg.norm(side)), 1e-12)
        up = np.cross(d, side)
        centres.append(pedal.heel + d * pedal.length / 2)
        rots.append(np.stack([side, up, d], axis=-1))
    sizes = [(*BOARD_SIZE, p.length) for p in (kit.kick_pedal, kit.hihat_pedal)]
    return box_transforms(np.array(centres), np.array(sizes), np.array(rots)), downs


def beater(geo: Geometry, down: float) -> tuple[F64, F64]:
    """The kick beater's axle and ball centre (3,) each, pressed ``down`` (0..1)."""
    kick = geo.kit.pieces.get("kick")
    if not isinstance(kick, Drum):
        return np.zeros(3), np.zeros(3)
    n = np.asarray(kick.normal, dtype=np.float64)  # out of the batter head, toward the drummer
    strike = kick.centre - np.array([0.0, 0.2 * kick.radius, 0.0]) + n * BEATER_BALL_M
    pivot = (
        strike
        - np.array([0.0, BEATER_SHAFT_M, 0.0])
        + n * (BEATER_PIVOT_IN_FRONT_M - BEATER_BALL_M)
    )
    shaft = strike - pivot
    axis = np.cross(np.array([0.0, 1.0, 0.0]), n)  # horizontal, along the head
    axis /= max(float(np.linalg.norm(axis)), 1e-12)
    ang = np.radians(BEATER_REST_DEG) * (1.0 - down)
    # turn the shaft toward the drummer (Rodrigues about ``axis``)
    c, s = np.cos(ang), np.sin(ang)
    turned = shaft * c + np.cross(axis, shaft) * s + axis * np.dot(axis, shaft) * (1 - c)
    if np.dot(turned - shaft, n) < 0:  # the other way round: always back toward the drummer
        turned = shaft * c - np.cross(axis, shaft) * s + axis * np.dot(axis, shaft) * (1 - c)
    return pivot, pivot + turned


__all__ = ["footboards", "beater", "pressed", "board_direction", "BEATER_BALL_M"]
