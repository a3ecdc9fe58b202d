"""Where a drummer's stroke lands: its impact pose turned about the stick's tip (issue 15).

The clips give each stroke's impact pose as a *row* (10,): the grip (3), the hand's
world rotation (4) and the elbow hint (3), exact on the instrument.
:mod:`virja.motion.drummer_hands` builds each hand's track through those rows; three
things change a row first, each a turn of the hand and stick about the stick's tip
(:meth:`Arm.reach`), so the tip, and with it contact and timing, stays exactly where
the clip put it:

- **reach** (:func:`reached`): a far move the plan leaves little time for is partly
  taken by the stick: the wrist sits toward the other piece (a busy hand from the snare
  to the crash in 114 ms, blues.mid at 7.27 s).
- **over** (:func:`over`): two strokes within ``drummer_clear.BEFORE_IMPACT_S`` whose
  sticks cross at their impacts (where no detour may bend either track): the louder
  hand lands raised over the other stick (GMD New Orleans funk 84 fill at 0.03 s).
- **under** (:func:`under`): the left waiting on a drum under the right stick crossed
  over it onto the hi-hat lands with its wrist lowered, its stick under the right's
  (GMD latin-chacarera 118 at 8.12 s).

Which strokes of the other hand count, and when, is the track builder's business; here
are pure functions of rows and an :class:`Arm`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.motion import drummer_clear
from virja.motion.skeleton import STICK_AXIS_LOCAL, STICK_BUTT_M, STICK_TIP_M

_UP = np.array([0.0, 1.0, 0.0])
_FLAT = np.array([1.0, 0.0, 1.0])  # seen from above
# a hand raised over (lowered under) the other stick at an impact in steps of this (m)
STEP_M = 0.005
# a turn about the tip never brings the wrist nearer the arm's full stretch than this
# (m), nor nearer than the clip's own pose: the body's turn moves the shoulder, and an
# arm out of reach misses the piece (a left hand on the ride: 3.8 mm off)
REACH_SLACK_M = 0.04
# under: right strokes whose stick passes this near the left's (m)
UNDER_NEAR_M = 0.08


def tip(row: np.ndarray) -> np.ndarray:
    """The stick's tip of a (grip, rot, ...) row."""
    return np.asarray(row[:3] + STICK_TIP_M * quat.rotate(row[3:7], STICK_AXIS_LOCAL))


def stick_ends(row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stick's butt and tip of a (grip, rot, ...) row."""
    axis = quat.rotate(row[3:7], STICK_AXIS_LOCAL)
    return row[:3] - STICK_BUTT_M * axis, row[:3] + STICK_TIP_M * axis


@dataclass(frozen=True)
class Arm:
    """One arm's fixed measures: the shoulder (world, m), the upper arm and forearm
    lengths (m) and the grip's offset in the hand's frame (m)."""

    shoulder: np.ndarray
    l1: float
    l2: float
    grip_off: np.ndarray

    def wrist(self, row: np.ndarray) -> np.ndarray:
        """The wrist of a (grip, rot, elbow) row."""
        return np.asarray(row[:3] - quat.rotate(row[3:7], self.grip_off))

    def reach(self, row: np.ndarray, toward: np.ndarray, dist: float) -> np.ndarray:
        """``row`` with the hand and stick turned about the stick's tip so that the wrist
        sits up to ``dist`` nearer ``toward`` (a wrist position; the part of the way
        square to the stick, which is all a turn about the tip can give): the tip stays
        exactly where it was."""
        grip, rot = row[:3], row[3:7]
        at = tip(row)
        r = self.wrist(row) - at
        lever = float(np.linalg.norm(r))
        way = toward - (at + r)
        r_hat = r / lever
        way = way - float(way @ r_hat) * r_hat
        norm = float(np.linalg.norm(way))
        if dist <= 1e-4 or norm < 1e-6:
            return row
        axis = np.cross(r_hat, way / norm)
        axis = axis / np.linalg.norm(axis)
        theta = math.asin(min(dist, norm, 0.9 * lever) / lever)
        full = self.l1 + self.l2 - REACH_SLACK_M
        limit = max(full, float(np.linalg.norm(at + r - self.shoulder)))
        for _ in range(6):
            q = quat.from_axis_angle(axis, theta)
            if float(np.linalg.norm(at + quat.rotate(q, r) - self.shoulder)) <= limit:
                break
            theta *= 0.5
        else:
            return row
        out = row.copy()
        out[:3] = at + quat.rotate(q, grip - at)
        out[3:7] = quat.multiply(q, rot)
        return out


def reached(
    arm: Arm,
    row: np.ndarray,
    here: np.ndarray,
    span: float,
    share: float,
    speed_m_s: float,
    max_m: float,
) -> np.ndarray:
    """``row`` reaching toward ``here`` (a row) when the wrist's way between them in
    ``span`` s is longer than ``speed_m_s`` allows: by ``share`` of the excess, at most
    ``max_m``.  Also where the hands cross (a left hand on the ride while the right
    plays the hi-hat): a stick turned about its tip there swept through the other
    stick (MMA Swing1 at 300 bpm) and was withheld until the tracks were kept apart as
    paths (:mod:`virja.motion.drummer_clear`); withheld, the crossed hand's wrist went
    the whole way (0.6 m in 164 ms: 16.7 cm a frame at 30 fps, MMA Swing1 at 240 bpm)."""
    a, b = arm.wrist(row), arm.wrist(here)
    excess = float(np.linalg.norm(a - b)) - speed_m_s * max(span, 0.0)
    if excess <= 0.0:
        return row
    return arm.reach(row, b, min(share * excess, max_m))


def _closest(row: np.ndarray, other: np.ndarray, flat: bool = False) -> tuple[float, float, float]:
    """(distance, this stick's height, the other's height) where the sticks of two rows
    come closest (seen from above when ``flat``: then the heights are 0)."""
    a0, a1 = (e[None] for e in stick_ends(row))
    b0, b1 = (e[None] for e in stick_ends(other))
    if flat:
        a0, a1, b0, b1 = a0 * _FLAT, a1 * _FLAT, b0 * _FLAT, b1 * _FLAT
    pa, pb = drummer_clear.segment_closest(a0, a1, b0, b1)
    return float(np.linalg.norm(pa - pb)), float(pa[0, 1]), float(pb[0, 1])


def over(
    arm: Arm,
    row: np.ndarray,
    lift: float,
    others: Sequence[tuple[np.ndarray, float]],
    is_right: bool,
    max_m: float,
) -> np.ndarray:
    """``row`` (a stroke's impact pose, its backswing ``lift``) raised over the other
    stick, turned about its tip, where one of ``others`` (the other hand's impact rows
    within ``drummer_clear.BEFORE_IMPACT_S``, each with its lift) crosses it under
    ``STICK_TRIGGER_M``: there neither track may be bent, so the two impact poses
    themselves must lie apart.  Of the two, the larger lift goes over (the higher
    backswing comes down from over the other stick; raising the soft right over the
    left instead left the left's backswing to come down through it), else the stick
    higher where they cross, else the right; its hand rises in ``STEP_M`` steps until
    ``STICK_CLEAR_M`` lies between them, at most ``max_m``."""
    for other, lift_o in others:
        d, ya, yb = _closest(row, other)
        if d >= drummer_clear.STICK_TRIGGER_M:
            continue
        # the same pair seen from the other hand's build: one of them goes over
        if abs(lift - lift_o) > 1e-9:
            if lift < lift_o:
                continue
        elif abs(ya - yb) > 1e-9:
            if ya < yb:
                continue
        elif not is_right:
            continue
        wrist = arm.wrist(row)
        for k in range(1, 1 + int(max_m / STEP_M + 1e-9)):
            up = arm.reach(row, wrist + _UP, k * STEP_M)
            if _closest(up, other)[0] >= drummer_clear.STICK_CLEAR_M:
                return up
    return row


def crosses_over(row: np.ndarray, others: Sequence[np.ndarray]) -> bool:
    """Whether the stick of ``row`` lies over the stick of one of ``others`` (rows),
    crossed seen from above (under ``STICK_CLEAR_M``)."""
    for other in others:
        if _closest(row, other, flat=True)[0] >= drummer_clear.STICK_CLEAR_M:
            continue
        _d, ya, yb = _closest(row, other)
        if ya > yb:
            return True
    return False


def _crossed_behind(row: np.ndarray, other: np.ndarray) -> bool:
    """Whether the stick of ``other`` crosses the stick of ``row`` seen from above
    (under ``STICK_CLEAR_M``) behind its middle (toward the hand, not where two tips
    meet on one piece)."""
    a0, a1 = (e[None] * _FLAT for e in stick_ends(row))
    b0, b1 = (e[None] * _FLAT for e in stick_ends(other))
    pa, pb = drummer_clear.segment_closest(a0, a1, b0, b1)
    return float(np.linalg.norm(pa - pb)) < drummer_clear.STICK_CLEAR_M and float(
        np.linalg.norm(pa - a0)
    ) < 0.5 * float(np.linalg.norm(a1 - a0))


def crossing(row: np.ndarray, others: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Those of ``others`` (rows) whose stick crosses the stick of ``row`` seen from above
    (under ``STICK_CLEAR_M``), behind its middle, and passes within ``UNDER_NEAR_M`` of
    it: the right stick crossed over onto the hi-hat lies over the left's hand (at 11 %
    of the left stick from its butt in GMD merengue 130 at 18.0 s), a right stroke on the
    tom the left plays meets it at the tips (100 %)."""
    return [
        other
        for other in others
        if _crossed_behind(row, other) and _closest(row, other)[0] < UNDER_NEAR_M
    ]


def under(
    arm: Arm, row: np.ndarray, others: Sequence[np.ndarray], max_m: float, extra_m: float = 0.0
) -> np.ndarray:
    """``row`` (the impact pose of a left-hand stroke) with the wrist lowered, turned
    about the tip, until its stick lies ``STICK_CLEAR_M`` under each of ``others`` (the
    right's impact rows while the left is low there) that crosses it (:func:`crossing`):
    the right arm crossed over onto the hi-hat, the left plays the drums beneath it.
    In ``STEP_M`` steps, at most ``max_m``; the unchanged ``row`` where that is not
    enough (GMD latin-chacarera 118 at 8.12 s: the left on the high tom, its butt at the
    height of the right stick, which rose into it with each hi-hat stroke while the left
    waited there).  Then, as far as ``max_m`` allows, ``extra_m`` lower still (the
    wrist's own rise in the stroke's backswing, which comes up under the right stick:
    GMD calypso 108 at 17.8 s)."""
    near = crossing(row, others)
    if not near:
        return row

    def beneath(r: np.ndarray, clear: float) -> bool:
        for other in near:
            d, ya, yb = _closest(r, other)
            if ya >= yb or d < clear:
                return False
        return True

    if beneath(row, drummer_clear.STICK_CLEAR_M + extra_m):
        return row
    wrist = arm.wrist(row)
    found = row
    for k in range(1, 1 + int(max_m / STEP_M + 1e-9)):
        down = arm.reach(row, wrist - _UP, k * STEP_M)
        if found is row and beneath(down, drummer_clear.STICK_CLEAR_M):
            found = down
        if found is not row and beneath(down, drummer_clear.STICK_CLEAR_M + extra_m):
            return down
    return found


__all__ = ["Arm", "crosses_over", "crossing", "over", "reached", "stick_ends", "tip", "under"]
