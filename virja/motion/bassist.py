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

import numpy as np

from virja import quat
from virja.geometry import Geometry
from virja.motion.skeleton import SKELETON
from virja.vocab import BassPluck, MotionKey

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


@dataclass
class _Note:
    impact: float
    start: float  # when the hands start moving toward it
    note: int
    string: str
    fret: int
    position: int
    velocity: int
    right_finger: int  # 0 index, 1 middle
    off: float = math.inf


_ARMS = [_SK.index("LeftArm"), _SK.index("RightArm")]
_FORES = [_SK.index("LeftForeArm"), _SK.index("RightForeArm")]
_HANDS = [_SK.index("LeftHand"), _SK.index("RightHand")]
_SHOULDERS = [_SK.index("LeftShoulder"), _SK.index("RightShoulder")]


def _frames(direction: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    """(k, 3, 3) frames with columns (direction, hinge made perpendicular, their cross)."""
    d = direction / np.linalg.norm(direction, axis=-1, keepdims=True)
    h = hinge - np.sum(hinge * d, axis=-1, keepdims=True) * d
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    return np.stack([d, h, np.cross(d, h)], axis=-1)


_REST_T = _frames(_ARM_REST_DIR[None], _ARM_REST_HINGE[None])[0].T


def _two_bone(
    roots: np.ndarray, targets: np.ndarray, poles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (k, 4) of upper and lower arm putting each wrist on its target,
    bending toward its pole: :func:`virja.motion.ik.two_bone` for several arms at once
    (targets out of reach are clamped)."""
    a_len, b_len = _ARM_LEN
    to = targets - roots
    dist = np.linalg.norm(to, axis=-1)
    d = np.clip(dist, abs(a_len - b_len) + 1e-6, a_len + b_len - 1e-6)
    u = to / dist[:, None]
    v = poles - roots
    v = v - np.sum(v * u, axis=-1, keepdims=True) * u
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    cos_a = (a_len**2 + d**2 - b_len**2) / (2 * a_len * d)
    ang = np.arccos(np.clip(cos_a, -1.0, 1.0))[:, None]
    elbow = roots + a_len * (np.cos(ang) * u + np.sin(ang) * v)
    end = roots + d[:, None] * u
    u1 = (elbow - roots) / np.linalg.norm(elbow - roots, axis=-1, keepdims=True)
    u2 = (end - elbow) / np.linalg.norm(end - elbow, axis=-1, keepdims=True)
    hinge = np.cross(u1, u2)
    straight = np.linalg.norm(hinge, axis=-1) < 1e-9  # a straight arm bends toward its pole
    hinge[straight] = np.cross(u1[straight], v[straight])
    upper = quat.from_matrix(_frames(u1, hinge) @ _REST_T)
    lower = quat.from_matrix(_frames(u2, hinge) @ _REST_T)
    return upper, lower


def _position_of(motion: MotionKey, fret: int) -> int:
    """The left hand's position the planner chose (:attr:`BassPluck.position`), or the
    fret's own when it chose none."""
    pos = motion.position if isinstance(motion, BassPluck) else None
    return pos if pos is not None else max(fret, 1)


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
        self._edits = 0  # note-offs and forgetting: the note table is rebuilt after them
        self._table: _NoteTable | None = None
        self._table_key = (0, 0)
        b = geometry.bass
        lateral = np.cross(b.axis, b.front)
        self._lateral = lateral / np.linalg.norm(lateral)  # toward the low strings

    # -- input ------------------------------------------------------------------

    def add(
        self,
        impact: float,
        note: int,
        string: str,
        fret: int,
        motion: MotionKey,
        velocity: int,
        start: float | None = None,
    ) -> None:
        """A planned bass note (its impact, string, fret, motion, loudness, start)."""
        i = bisect.bisect_right(self._times, impact)
        finger = (self._notes[i - 1].right_finger + 1) % 2 if i > 0 else 0
        begin = min(impact, start if start is not None else impact - 0.1)
        if i > 0:  # a hand starts toward a note only once it has struck the one before
            begin = max(begin, self._notes[i - 1].impact)
        self._times.insert(i, impact)
        self._notes.insert(
            i,
            _Note(impact, begin, note, string, fret, _position_of(motion, fret), velocity, finger),
        )

    def note_off(self, note: int, time_s: float) -> None:
        """The note-off of ``note`` (or of the note it was moved from by octaves) at ``time_s``."""
        i = bisect.bisect_right(self._times, time_s)
        for n in reversed(self._notes[max(0, i - 16) : i]):
            if n.off == math.inf and (n.note - note) % 12 == 0:
                n.off = time_s
                self._edits += 1
                return

    def forget_before(self, time_s: float) -> None:
        k = max(bisect.bisect_left(self._times, time_s) - 1, 0)
        if k:
            self._edits += 1
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

    def _incoming(self, t: float, stopped: bool) -> tuple[_Note | None, _Note | None, float]:
        """(previous, next, w): the hand goes from ``previous``'s note to ``next``'s, ``w``
        0..1 of the way (1 once ``next`` is struck); only stopped notes if ``stopped``."""
        nxt: _Note | None = None
        prev: _Note | None = None
        i = bisect.bisect_right(self._times, t + 1.0)  # approaches last well under 1 s
        for n in reversed(self._notes[max(0, i - 48) : i]):
            if stopped and n.fret <= 0:
                continue
            if nxt is None:
                if n.start <= t:
                    nxt = n
                continue
            prev = n
            break
        if nxt is None:
            return None, None, 1.0
        span = nxt.impact - nxt.start
        u = 1.0 if span <= 1e-9 else min(max((t - nxt.start) / span, 0.0), 1.0)
        return prev, nxt, u * u * (3.0 - 2.0 * u)

    def _layout(self, n: _Note | None) -> tuple[np.ndarray, np.ndarray]:
        """Fingertip offsets (4, 3) from the stopping fingertip, and the thumb tip (3,),
        for the hand position of stopped note ``n`` (the rest position for None)."""
        s = self.settings
        b = self.geometry.bass
        string, fret, pos = (n.string, n.fret, n.position) if n is not None else ("D", 5, 5)
        thumb_pos = pos >= s.thumb_position_fret
        offsets = _THUMB_OFFSETS if thumb_pos else _LOW_OFFSETS
        step = fret - pos
        k = min(max(step, 0), 3) if thumb_pos else _FINGER_OF_STEP_LOW.get(step, 0)
        along = b.string_dir(string)  # toward the bridge: higher frets
        gap = max(b.fret_distance(min(fret + 1, b.max_fret)) - b.fret_distance(fret), 0.02)
        tips = np.array([(off - offsets[k]) * gap * along for off in offsets])
        middle_fret = min(pos + 1, b.max_fret)
        centre = 0.5 * (b.string_point("A", middle_fret) + b.string_point("D", middle_fret))
        return tips, centre - s.thumb_behind_m * b.front

    def _left(self, t: float, wpos: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        s = self.settings
        front = self.geometry.bass.front
        tip = wpos[_SK.index("LeftHandEnd")]
        wrist = wpos[_SK.index("LeftHand")]
        prev, nxt, w = self._incoming(t, stopped=True)
        tips_a, thumb_a = self._layout(prev if prev is not None else nxt)
        tips_b, thumb_b = self._layout(nxt)
        offs = (1.0 - w) * tips_a + w * tips_b
        thumb_tip = (1.0 - w) * thumb_a + w * thumb_b
        last = self.current(t)
        pressing = nxt is not None and last is nxt and t < nxt.off and nxt.impact <= t
        # the stopping finger: the one with no offset; the others hover, all lift when free
        stopping = int(np.argmin(np.linalg.norm(tips_b, axis=1)))
        press = 1.0 if pressing else 0.0
        back = _unit(wrist - tip)
        out: list[tuple[np.ndarray, np.ndarray]] = []
        for i in range(4):
            rise = (s.hover_m if i != stopping else 0.0) * press + s.lift_m * (1.0 - press)
            # near the impact the stopping finger comes down with the hand (clip) itself
            ftip = tip + offs[i] + rise * front
            knuckle = tip + offs[i] * 0.6 + s.finger_len_m * back
            mid = 0.5 * (knuckle + ftip) + 0.35 * s.finger_len_m * front  # arched over the string
            out += [(knuckle, mid), (mid, ftip)]
        # the thumb: behind the neck, opposite the second finger
        thumb_base = wrist + 0.3 * (tip - wrist)
        thumb_mid = 0.5 * (thumb_base + thumb_tip) - 0.01 * front
        out += [(thumb_base, thumb_mid), (thumb_mid, thumb_tip)]
        return out

    def _right(self, t: float, wpos: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        s = self.settings
        b = self.geometry.bass
        tip = wpos[_SK.index("RightHandEnd")]
        wrist = wpos[_SK.index("RightHand")]
        prev, nxt, w = self._incoming(t, stopped=False)
        finger = nxt.right_finger if nxt is not None else 0
        # the finger that plucked last rests; the one about to pluck comes to the string
        plucking = np.zeros(2)
        plucking[finger] = w if prev is not None else 1.0
        plucking[1 - finger] = 1.0 - plucking[finger]
        along = b.string_dir("A")
        back = _unit(wrist - tip)
        out: list[tuple[np.ndarray, np.ndarray]] = []
        # index nearer the fingerboard (toward the nut), middle beside it toward the bridge
        for i in (0, 1):
            side = 0.02 if i == 1 else -0.02
            rest = side * along + s.hover_m * 2 * b.front
            ftip = tip + (1.0 - plucking[i]) * rest
            knuckle = tip + 0.6 * side * along + s.finger_len_m * back
            mid = 0.5 * (knuckle + ftip) + 0.25 * s.finger_len_m * b.front
            out += [(knuckle, mid), (mid, ftip)]
        # ring and little curled into the palm, the thumb resting on the fingerboard's edge
        palm = tip + 0.6 * s.finger_len_m * back
        for off in (0.035, 0.05):
            out.append((palm + off * along, palm + off * along - 0.02 * back + 0.01 * b.front))
        thumb_tip = tip - 0.06 * along + 0.02 * b.front + 0.02 * self._lateral
        out.append((tip + s.finger_len_m * back - 0.02 * along, thumb_tip))
        return out

    # -- body -------------------------------------------------------------------

    def _note_table(self) -> _NoteTable:
        """The notes as arrays (rebuilt when a note or note-off arrives or is forgotten)."""
        key = (len(self._notes), self._edits)
        if self._table is None or self._table_key != key:
            self._table = _NoteTable.of(self._notes, self.geometry)
            self._table_key = key
        return self._table

    def body(
        self, loc: np.ndarray, root: np.ndarray, t: float, beat_phase: float, beat_index: int
    ) -> np.ndarray:
        """The bassist's local rotations (n, 4) with the living body added and the arms
        solved again so the hands stay where ``loc`` put them (:meth:`body_many` of one)."""
        return self.body_many(
            np.asarray(loc)[None],
            root,
            np.array([t], dtype=np.float64),
            np.array([beat_phase], dtype=np.float64),
            np.array([beat_index]),
        )[0]

    def body_many(
        self,
        loc: np.ndarray,
        root: np.ndarray,
        times: np.ndarray,
        beat_phase: np.ndarray,
        beat_index: np.ndarray,
    ) -> np.ndarray:
        """:meth:`body` at many times at once: ``loc`` (m, n, 4) at ``times`` (m,), with
        the beat's phase and number at each; one numpy pass over all frames."""
        s = self.settings
        loc = np.asarray(loc, dtype=np.float64)
        t = np.asarray(times, dtype=np.float64)
        out = loc.copy()
        tab = self._note_table()
        i = np.searchsorted(tab.impact, t, side="right")
        rows = np.nonzero(i > 0)[0]  # before the first note the player stands still
        if rows.size == 0:
            return out
        t, i, loc = t[rows], i[rows], loc[rows]
        last = i - 1
        # playing: full size; 2 s after the last note the body settles over a second
        settle = np.clip(3.0 - (t - tab.impact[last]), 0.0, 1.0)
        loud = (0.6 + 0.4 * tab.velocity[last] / 127) * settle
        # weight from one foot to the other over two beats; a dip of the spine on each beat
        phase = np.asarray(beat_phase, dtype=np.float64)[rows]
        two = (np.asarray(beat_index)[rows] % 2 + phase) / 2.0
        sway = s.sway_rad * loud * np.sin(2 * np.pi * two)
        dip = s.dip_rad * loud * np.sin(np.pi * phase) ** 2
        # the chest turns with the fretting hand: lower on the neck, further toward the bass
        turn = s.turn_rad_per_m * tab.fretted_down(i)
        out[rows] = self._moved(loc, root, sway, dip, turn, self._vibrato_many(t, last))
        return out

    def _vibrato_many(self, t: np.ndarray, last: np.ndarray) -> np.ndarray:
        """:meth:`_vibrato` at times ``t`` (m,) whose latest note is ``last`` (m,): (m, 3)."""
        s = self.settings
        tab = self._note_table()
        nxt = np.append(tab.start, math.inf)[last + 1]
        end = np.minimum(tab.off[last], nxt)
        impact = tab.impact[last]
        held = t - impact
        on = (
            (tab.fret[last] > 0)
            & (held >= s.vibrato_after_s)
            & (end - impact >= s.long_note_s)
            & (t < end)
        )
        # fade in over 0.2 s and out over the last 0.1 s before the note ends
        ramp = np.minimum(
            np.minimum(1.0, (held - s.vibrato_after_s) / 0.2), np.maximum(0.0, (end - t) / 0.1)
        )
        amp = s.vibrato_m * ramp * np.sin(2 * np.pi * s.vibrato_hz * (held - s.vibrato_after_s))
        return np.where(on, amp, 0.0)[:, None] * tab.string_dir[last]

    def _moved(
        self,
        loc: np.ndarray,
        root: np.ndarray,
        sway: np.ndarray,
        dip: np.ndarray,
        turn: np.ndarray,
        vibrato: np.ndarray,
    ) -> np.ndarray:
        wpos, wrot = _SK.fk_matrices(loc, root)
        targets = wpos[:, _HANDS].copy()
        targets[:, 0] += vibrato
        out = _torso(loc, sway, dip, turn)
        moved_pos, moved_rot = _SK.fk_matrices(out, root)
        # less of it where an arm near full stretch could no longer keep its hand in place:
        # the largest share k of the motion (shoulders move about linearly with it) that
        # leaves both wrists within reach
        reach = _ARM_LEN[0] + _ARM_LEN[1] - 1e-3
        k = np.ones(len(loc))
        for i in range(2):
            s0, s1 = wpos[:, _ARMS[i]], moved_pos[:, _ARMS[i]]
            far = np.nonzero(np.linalg.norm(targets[:, i] - s1, axis=-1) > reach)[0]
            if far.size == 0:
                continue
            lo, hi = np.zeros(far.size), np.ones(far.size)
            a, b, goal = s0[far], s1[far] - s0[far], targets[far, i]
            for _ in range(12):
                mid = 0.5 * (lo + hi)
                out_of_reach = np.linalg.norm(goal - (a + mid[:, None] * b), axis=-1) > reach
                hi = np.where(out_of_reach, mid, hi)
                lo = np.where(out_of_reach, lo, mid)
            k[far] = np.minimum(k[far], lo)
        less = np.nonzero(k < 1.0)[0]
        if less.size:
            kl = k[less]
            out[less] = _torso(loc[less], kl * sway[less], kl * dip[less], kl * turn[less])
            moved_pos[less], moved_rot[less] = _SK.fk_matrices(out[less], root)
        poles = wpos[:, _FORES] + (moved_pos[:, _ARMS] - wpos[:, _ARMS])
        m = len(loc)
        upper, lower = _two_bone(
            moved_pos[:, _ARMS].reshape(-1, 3), targets.reshape(-1, 3), poles.reshape(-1, 3)
        )
        upper, lower = upper.reshape(m, 2, 4), lower.reshape(m, 2, 4)
        shoulders = quat.from_matrix(moved_rot[:, _SHOULDERS])
        hands = quat.from_matrix(wrot[:, _HANDS])
        out[:, _ARMS] = quat.multiply(quat.conjugate(shoulders), upper)
        out[:, _FORES] = quat.multiply(quat.conjugate(upper), lower)
        out[:, _HANDS] = quat.multiply(quat.conjugate(lower), hands)
        return out


_HIPS, _SPINE, _CHEST = _SK.index("Hips"), _SK.index("Spine"), _SK.index("Chest")
_LEGS = [_SK.index("LeftUpLeg"), _SK.index("RightUpLeg")]


def _torso(loc: np.ndarray, sway: np.ndarray, dip: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """``loc`` (m, n, 4) with the hips swayed, the spine dipped and the chest turned."""
    out = loc.copy()
    q_sway = quat.from_axis_angle([0.0, 0.0, 1.0], sway)
    out[:, _HIPS] = quat.multiply(out[:, _HIPS], q_sway)
    legs = quat.conjugate(q_sway)[:, None]
    out[:, _LEGS] = quat.multiply(legs, out[:, _LEGS])  # the legs stay put
    out[:, _SPINE] = quat.multiply(out[:, _SPINE], quat.from_axis_angle([1.0, 0.0, 0.0], dip))
    out[:, _CHEST] = quat.multiply(out[:, _CHEST], quat.from_axis_angle([0.0, 1.0, 0.0], turn))
    return out


@dataclass(frozen=True)
class _NoteTable:
    """The bassist's notes as arrays, for :meth:`Bassist.body_many`."""

    impact: np.ndarray
    start: np.ndarray
    off: np.ndarray
    velocity: np.ndarray
    fret: np.ndarray
    down: np.ndarray  # fret distance from the nut (0 for an open string)
    string_dir: np.ndarray  # (k, 3)
    fretted: np.ndarray  # indices of the stopped notes

    @classmethod
    def of(cls, notes: list[_Note], geometry: Geometry) -> _NoteTable:
        b = geometry.bass
        dirs = {s: b.string_dir(s) for s in {n.string for n in notes}}
        fret = np.array([n.fret for n in notes], dtype=np.int64)
        return cls(
            impact=np.array([n.impact for n in notes], dtype=np.float64),
            start=np.array([n.start for n in notes], dtype=np.float64),
            off=np.array([n.off for n in notes], dtype=np.float64),
            velocity=np.array([n.velocity for n in notes], dtype=np.float64),
            fret=fret,
            down=np.array([b.fret_distance(n.fret) if n.fret > 0 else 0.0 for n in notes]),
            string_dir=np.array([dirs[n.string] for n in notes]).reshape(-1, 3),
            fretted=np.nonzero(fret > 0)[0],
        )

    def fretted_down(self, i: np.ndarray) -> np.ndarray:
        """How far down the neck the hand is at times whose notes struck so far are
        ``[:i]`` (m,): the latest stopped note among the last 32 (:meth:`Bassist.fretted`)."""
        k = np.searchsorted(self.fretted, i, side="left") - 1
        j = self.fretted[np.maximum(k, 0)] if self.fretted.size else np.zeros_like(i)
        found = (k >= 0) & (j >= i - 32)
        return np.where(found, self.down[j] if self.fretted.size else 0.0, 0.0)
