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
    return float(_pressed_many(pedal, np.array([toe_y], dtype=np.float64))[0])


def _pressed_many(pedal: Pedal, toe_y: F64) -> F64:
    """:func:`pressed` for toe heights (m,)."""
    up_y, down_y = float(pedal.toe_point(False)[1]), float(pedal.toe_point(True)[1])
    return np.asarray(np.clip((up_y - toe_y) / max(up_y - down_y, 1e-6), 0.0, 1.0))


def board_direction(pedal: Pedal, down: float) -> F64:
    """The footboard's unit direction heel -> toe when pressed ``down`` (0..1)."""
    return _board_directions(pedal, np.array([down], dtype=np.float64))[0]


def footboards(geo: Geometry, pose: BandPose) -> tuple[F64, tuple[float, float]]:
    """Box instances (2, 4, 4) of the kick's and the hi-hat's footboards, and how far
    each is pressed (kick, hi-hat)."""
    boards, downs = footboards_many(
        geo,
        np.array([pose.drums.position("RightToe")[1]], dtype=np.float64),
        np.array([pose.drums.position("LeftToe")[1]], dtype=np.float64),
    )
    return boards[0], (float(downs[0, 0]), float(downs[0, 1]))


def footboards_many(
    geo: Geometry, right_toe_y: F64, left_toe_y: F64
) -> tuple[F64, NDArray[np.float64]]:
    """:func:`footboards` over frames (the render loops' chunks): the drummer's right
    and left toe heights (m,) -> boxes (m, 2, 4, 4) and presses (m, 2) (kick, hi-hat)."""
    kit = geo.kit
    pedals = (kit.kick_pedal, kit.hihat_pedal)
    m = len(right_toe_y)
    downs = np.empty((m, 2))
    centres = np.empty((m, 2, 3))
    rots = np.empty((m, 2, 3, 3))
    for j, (pedal, toe) in enumerate(zip(pedals, (right_toe_y, left_toe_y), strict=True)):
        down = _pressed_many(pedal, np.asarray(toe, dtype=np.float64))
        d = _board_directions(pedal, down)
        side = np.cross(np.array([0.0, 1.0, 0.0]), d)
        side /= np.maximum(np.linalg.norm(side, axis=-1, keepdims=True), 1e-12)
        up = np.cross(d, side)
        downs[:, j] = down
        centres[:, j] = pedal.heel + d * pedal.length / 2
        rots[:, j] = np.stack([side, up, d], axis=-1)
    sizes = np.tile([(*BOARD_SIZE, p.length) for p in pedals], (m, 1))
    boxes = box_transforms(centres.reshape(-1, 3), sizes, rots.reshape(-1, 3, 3))
    return boxes.reshape(m, 2, 4, 4), downs


def _board_directions(pedal: Pedal, down: F64) -> F64:
    """:func:`board_direction` for presses ``down`` (m,): (m, 3)."""
    a = np.arctan2(pedal.board[1], np.hypot(pedal.board[0], pedal.board[2]))
    b = np.arctan2(pedal.pressed_board[1], np.hypot(pedal.pressed_board[0], pedal.pressed_board[2]))
    horiz = np.array([pedal.board[0], 0.0, pedal.board[2]])
    horiz /= max(float(np.linalg.norm(horiz)), 1e-12)
    ang = (a + (b - a) * down)[:, None]
    return np.asarray(np.cos(ang) * horiz + np.sin(ang) * np.array([0.0, 1.0, 0.0]))


def beater(geo: Geometry, down: float) -> tuple[F64, F64]:
    """The kick beater's axle and ball centre (3,) each, pressed ``down`` (0..1)."""
    axle, ball = beater_many(geo, np.array([down], dtype=np.float64))
    return axle[0], ball[0]


def beater_many(geo: Geometry, down: F64) -> tuple[F64, F64]:
    """:func:`beater` over frames: presses ``down`` (m,) -> axles and ball centres (m, 3)."""
    down = np.asarray(down, dtype=np.float64).reshape(-1)
    kick = geo.kit.pieces.get("kick")
    if not isinstance(kick, Drum):
        return np.zeros((down.size, 3)), np.zeros((down.size, 3))
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
    c, s = np.cos(ang)[:, None], np.sin(ang)[:, None]
    turned = shaft * c + np.cross(axis, shaft) * s + axis * np.dot(axis, shaft) * (1 - c)
    other = shaft * c - np.cross(axis, shaft) * s + axis * np.dot(axis, shaft) * (1 - c)
    # the other way round where needed: always back toward the drummer
    turned = np.where(((turned - shaft) @ n < 0)[:, None], other, turned)
    return np.broadcast_to(pivot, turned.shape).copy(), pivot + turned


__all__ = [
    "footboards",
    "footboards_many",
    "beater",
    "beater_many",
    "pressed",
    "board_direction",
    "BEATER_BALL_M",
]
