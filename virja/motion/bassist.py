"""The bassist's fingers and living body, on top of the clips of :mod:`virja.motion.band`.

The clips put the fretting fingertip (``LeftHandEnd``) on the stopped string
and the plucking fingertip (``RightHandEnd``) on the pluck point at every
impact; this module adds what the clips do not carry:

- **Fingers** (:meth:`Bassist.fingers`): the left hand's four fingers, each
  with two joints, laid over the fingerboard one semitone apart by the hand
  position the planner chose (``_pos`` in the motion name; 1-2-4 fingering in
  the lower positions, one finger a fret in thumb position); the finger that
  stops the note ends exactly at ``LeftHandEnd``, the others hover; the thumb
  sits behind the neck, opposite the second finger.  All fingers lift off the
  string at the note-off or for an open string (which then rings on).  The
  right hand plucks with index and middle finger alternating, the other one
  resting beside it.
- **Living body** (:meth:`Bassist.body`): weight shifting from foot to foot
  over two beats, the spine dipping on each beat, the chest turning toward the
  fretting hand as it moves down the neck; larger for louder notes.  The arms
  are solved again afterwards (:func:`virja.motion.ik.two_bone`) so both hands
  stay exactly where the clips put them: contact and timing do not change.

Pure functions of the notes given and the time asked; numbers in
``motions/animation.toml`` ``[bassist]``.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from virja.geometry import Geometry
from virja.motion import ik, quat
from virja.motion.skeleton import SKELETON

_SK = SKELETON
_ARM_LEN = (
    float(np.linalg.norm(_SK.offsets[_SK.index("LeftForeArm")])),
    float(np.linalg.norm(_SK.offsets[_SK.index("LeftHand")])),
)
_ARM_REST_DIR = np.array([0.0, -1.0, 0.0])
_ARM_REST_HINGE = np.array([-1.0, 0.0, 0.0])
# semitones from the first finger: 1-2-4 fingering (ring beside the little finger)
_LOW_OFFSETS = (0.0, 1.0, 1.6, 2.0)
_THUMB_OFFSETS = (0.0, 1.0, 2.0, 3.0)  # thumb position: one finger a fret
_FINGER_OF_STEP_LOW = {0: 0, 1: 1, 2: 3}  # frets above the position -> finger (0 = index)
LEFT_BONES = 10  # :meth:`Bassist.fingers` gives the left hand's bones first (4 fingers, thumb)


@dataclass(frozen=True)
class BassistSettings:
    """Constants (``[bassist]`` of motions/animation.toml)."""

    finger_len_m: float = 0.05  # knuckle to fingertip
    hover_m: float = 0.006  # fingers not stopping the string, above it
    lift_m: float = 0.014  # all fingers after the note-off or for an open string
    thumb_behind_m: float = 0.045  # thumb tip behind the strings
    sway_rad: float = 0.03  # hips: weight from foot to foot over two beats
    dip_rad: float = 0.035  # spine: forward on each beat
    turn_rad_per_m: float = 0.25  # chest: toward the fretting hand, per metre down the neck
    thumb_position_fret: int = 12
    vibrato_m: float = 0.003  # left hand rolling along the string on a long note
    vibrato_hz: float = 5.0
    vibrato_after_s: float = 0.25  # it starts this long after the impact
    long_note_s: float = 0.45  # notes at least this long get vibrato

    @classmethod
    def from_table(cls, table: dict[str, Any]) -> BassistSettings:
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(table) - known)
        if unknown:
            raise ValueError(f"animation.toml [bassist]: unknown key(s) {', '.join(unknown)}")
        return cls(**{k: type(getattr(cls(), k))(v) for k, v in table.items()})


@dataclass
class _Note:
    impact: float
    note: int
    string: str
    fret: int
    position: int
    velocity: int
    right_finger: int  # 0 index, 1 middle
    off: float = math.inf


def _position_of(motion: str, fret: int) -> int:
    _, sep, tail = motion.rpartition("_pos")
    if sep and tail.isdigit():
        return int(tail)
    return max(fret, 1)


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-12 else v


class Bassist:
    """Fingers and body of the bassist for the notes given (see the module docstring)."""

    def __init__(self, geometry: Geometry, settings: BassistSettings | None = None) -> None:
        self.geometry = geometry
        self.settings = settings or BassistSettings()
        self._notes: list[_Note] = []
        self._times: list[float] = []
        b = geometry.bass
        lateral = np.cross(b.axis, b.front)
        self._lateral = lateral / np.linalg.norm(lateral)  # toward the low strings

    # -- input ------------------------------------------------------------------

    def add(self, impact: float, note: int, string: str, fret: int, motion: str, velocity: int) -> None:
        """A planned bass note (its impact, string, fret, motion name, loudness)."""
        i = bisect.bisect_right(self._times, impact)
        finger = (self._notes[i - 1].right_finger + 1) % 2 if i > 0 else 0
        self._times.insert(i, impact)
        self._notes.insert(
            i, _Note(impact, note, string, fret, _position_of(motion, fret), velocity, finger)
        )

    def note_off(self, note: int, time_s: float) -> None:
        """The note-off of ``note`` (or of the note it was moved from by octaves) at ``time_s``."""
        i = bisect.bisect_right(self._times, time_s)
        for n in reversed(self._notes[max(0, i - 16) : i]):
            if n.off == math.inf and (n.note - note) % 12 == 0:
                n.off = time_s
                return

    def forget_before(self, time_s: float) -> None:
        k = max(bisect.bisect_left(self._times, time_s) - 1, 0)
        del self._notes[:k]
        del self._times[:k]

    def current(self, t: float) -> _Note | None:
        """The latest note struck at or before ``t``."""
        i = bisect.bisect_right(self._times, t)
        return self._notes[i - 1] if i > 0 else None

    def fretted(self, t: float) -> _Note | None:
        """The latest stopped note struck at or before ``t`` (where the left hand is)."""
        i = bisect.bisect_right(self._times, t)
        for n in reversed(self._notes[max(0, i - 32) : i]):
            if n.fret > 0:
                return n
        return None

    # -- fingers ----------------------------------------------------------------

    def fingers(self, t: float, wpos: np.ndarray) -> np.ndarray:
        """(k, 2, 3) finger bones (from, to) of both hands at ``t``, world metres.

        ``wpos``: the bassist's joint positions (n, 3) from the clips.
        """
        segs: list[tuple[np.ndarray, np.ndarray]] = []
        segs += self._left(t, wpos)
        segs += self._right(t, wpos)
        return np.array([[a, b] for a, b in segs]).reshape(-1, 2, 3)

    def _left(self, t: float, wpos: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        s = self.settings
        b = self.geometry.bass
        tip = wpos[_SK.index("LeftHandEnd")]
        wrist = wpos[_SK.index("LeftHand")]
        held = self.fretted(t)
        last = self.current(t)
        string = held.string if held is not None else "D"
        fret = held.fret if held is not None else 5
        pos = held.position if held is not None else 5
        pressing = (
            held is not None
            and last is held
            and t < held.off
            and held.impact <= t
        )
        thumb_pos = pos >= s.thumb_position_fret
        offsets = _THUMB_OFFSETS if thumb_pos else _LOW_OFFSETS
        step = fret - pos
        k = min(max(step, 0), 3) if thumb_pos else _FINGER_OF_STEP_LOW.get(step, 0)
        along = b.string_dir(string)  # toward the bridge: higher frets
        fret_gap = b.fret_distance(min(fret + 1, b.max_fret)) - b.fret_distance(fret)
        fret_gap = max(fret_gap, 0.02)
        front = b.front
        # the knuckles lie behind the pressing fingertip, toward the wrist and off the board
        back = _unit(wrist - tip)
        out: list[tuple[np.ndarray, np.ndarray]] = []
        for i, off in enumerate(offsets):
            shift = (off - offsets[k]) * fret_gap * along
            if i == k:
                ftip = tip + (0.0 if pressing else s.lift_m) * front
            else:
                ftip = tip + shift + (s.hover_m if pressing else s.lift_m) * front
            knuckle = tip + shift * 0.6 + s.finger_len_m * back
            mid = 0.5 * (knuckle + ftip) + 0.35 * s.finger_len_m * front  # arched over the string
            out += [(knuckle, mid), (mid, ftip)]
        # the thumb: behind the neck, opposite the second finger
        middle_fret = min(pos + 1, b.max_fret)
        centre = 0.5 * (b.string_point("A", middle_fret) + b.string_point("D", middle_fret))
        thumb_tip = centre - s.thumb_behind_m * front
        thumb_base = wrist + 0.3 * (tip - wrist)
        thumb_mid = 0.5 * (thumb_base + thumb_tip) - 0.01 * front
        out += [(thumb_base, thumb_mid), (thumb_mid, thumb_tip)]
        return out

    def _right(self, t: float, wpos: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        s = self.settings
        b = self.geometry.bass
        tip = wpos[_SK.index("RightHandEnd")]
        wrist = wpos[_SK.index("RightHand")]
        last = self.current(t)
        finger = last.right_finger if last is not None else 0
        string = last.string if last is not None else "A"
        along = b.string_dir(string)
        back = _unit(wrist - tip)
        out: list[tuple[np.ndarray, np.ndarray]] = []
        # index nearer the fingerboard (toward the nut), middle beside it toward the bridge
        for i in (0, 1):
            if i == finger:
                ftip = tip
            else:
                ftip = tip + (0.02 if i == 1 else -0.02) * along + s.hover_m * 2 * b.front
            knuckle = tip + (0.012 if i == 1 else -0.012) * along + s.finger_len_m * back
            mid = 0.5 * (knuckle + ftip) + 0.25 * s.finger_len_m * b.front
            out += [(knuckle, mid), (mid, ftip)]
        # ring and little curled into the palm, the thumb resting on the fingerboard's edge
        palm = tip + 0.6 * s.finger_len_m * back
        for off in (0.035, 0.05):
            out.append((palm + off * along, palm + off * along - 0.02 * back + 0.01 * b.front))
        thumb_tip = tip - 0.06 * along + 0.02 * b.front + 0.02 * self._lateral
        out.append((tip + s.finger_len_m * back - 0.02 * along, thumb_tip))
        return out

    def _vibrato(self, t: float) -> np.ndarray:
        """Offset (3,) of the fretting hand along its string: vibrato on a long stopped note."""
        s = self.settings
        i = bisect.bisect_right(self._times, t)
        if i == 0:
            return np.zeros(3)
        n = self._notes[i - 1]
        nxt = self._notes[i].impact if i < len(self._notes) else math.inf
        end = min(n.off, nxt)
        held = t - n.impact
        if n.fret <= 0 or held < s.vibrato_after_s or end - n.impact < s.long_note_s or t >= end:
            return np.zeros(3)
        # fade in over 0.2 s and out over the last 0.1 s before the note ends
        ramp = min(1.0, (held - s.vibrato_after_s) / 0.2, max(0.0, (end - t) / 0.1))
        amp = s.vibrato_m * ramp * math.sin(2 * math.pi * s.vibrato_hz * (held - s.vibrato_after_s))
        return amp * self.geometry.bass.string_dir(n.string)

    # -- body -------------------------------------------------------------------

    def body(
        self, loc: np.ndarray, root: np.ndarray, t: float, beat_phase: float, beat_index: int
    ) -> np.ndarray:
        """The bassist's local rotations (n, 4) with the living body added and the arms
        solved again so the hands stay where ``loc`` put them."""
        s = self.settings
        wpos, wrot = _SK.fk(loc, root)
        held = self.fretted(t)
        last = self.current(t)
        loud = 0.6 + 0.4 * (last.velocity / 127 if last is not None else 0.5)
        # weight from one foot to the other over two beats; a dip of the spine on each beat
        two = (beat_index % 2 + beat_phase) / 2.0
        sway = s.sway_rad * loud * math.sin(2 * math.pi * two)
        dip = s.dip_rad * loud * math.sin(math.pi * beat_phase) ** 2
        # the chest turns with the fretting hand: lower on the neck, further toward the bass
        down = 0.0
        if held is not None:
            down = self.geometry.bass.fret_distance(held.fret)
        turn = s.turn_rad_per_m * down
        # less of it where an arm at full stretch could no longer keep its hand in place
        for k in (1.0, 0.5, 0.0):
            out, reached = self._moved(loc, root, wpos, wrot, k * sway, k * dip, k * turn, t)
            if reached:
                break
        return out

    def _moved(
        self,
        loc: np.ndarray,
        root: np.ndarray,
        wpos: np.ndarray,
        wrot: np.ndarray,
        sway: float,
        dip: float,
        turn: float,
        t: float,
    ) -> tuple[np.ndarray, bool]:
        out = loc.copy()
        hips, spine, chest = _SK.index("Hips"), _SK.index("Spine"), _SK.index("Chest")
        q_sway = quat.from_axis_angle([0.0, 0.0, 1.0], sway)
        out[hips] = quat.multiply(out[hips], q_sway)
        inv = quat.conjugate(q_sway)
        for leg in ("LeftUpLeg", "RightUpLeg"):  # the legs keep standing where they stood
            j = _SK.index(leg)
            out[j] = quat.multiply(inv, out[j])
        out[spine] = quat.multiply(out[spine], quat.from_axis_angle([1.0, 0.0, 0.0], dip))
        out[chest] = quat.multiply(out[chest], quat.from_axis_angle([0.0, 1.0, 0.0], turn))
        moved_pos, moved_rot = _SK.fk(out, root)
        wobble = self._vibrato(t)
        reached = True
        for side in ("Left", "Right"):
            arm, fore, hand = (_SK.index(f"{side}{j}") for j in ("Arm", "ForeArm", "Hand"))
            shoulder = _SK.index(f"{side}Shoulder")
            target = wpos[hand] + (wobble if side == "Left" else 0.0)
            sol = ik.two_bone(
                moved_pos[arm],
                target,
                wpos[fore] + (moved_pos[arm] - wpos[arm]),
                *_ARM_LEN,
                _ARM_REST_DIR,
                _ARM_REST_HINGE,
            )
            reached = reached and sol.reached
            out[arm] = ik.local_from_world(moved_rot[shoulder], sol.upper)
            out[fore] = ik.local_from_world(sol.upper, sol.lower)
            out[hand] = ik.local_from_world(sol.lower, wrot[hand])
        return out, reached
