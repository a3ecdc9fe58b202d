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
  over two beats (on one foot at each beat, so a note on the beat shows the
  lean), the spine dipping deepest just after each beat, the chest turning toward the
  fretting hand as it moves down the neck; larger for louder notes.  The arms
  are solved again afterwards (:func:`virja.motion.ik.two_bone`) so both hands
  stay exactly where the clips put them: contact and timing do not change.
- **The bass leaning with him** (:mod:`virja.motion.bass_lean`): the instrument
  turns about its endpin with the chest's sway and dip, and both hands go
  with it (their targets and orientations are leaned before the arms are
  solved), so in the bass's own frame nothing of the contact changes.

Pure functions of the notes given and the time asked; numbers in
``motions/animation.toml`` ``[bassist]``.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.fingerboard import Fingerboard, fingerboard
from virja.geometry import Geometry
from virja.motion import bass_lean
from virja.motion.ik import frames
from virja.motion.skeleton import SKELETON
from virja.vocab import BASS_STRINGS, BassPluck, MotionKey

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
    sway_rad: float = 0.03  # hips: weight from foot to foot over two beats, on a foot at a beat
    dip_rad: float = 0.035  # spine: forward with each beat...
    dip_after_beat: float = 0.12  # ...deepest this share of a beat after it
    half_time_spb: float = 0.4  # beats shorter than this (over 150 bpm): the body in half time
    body_ramp_s: float = 0.4  # the body's motion grows over this before a note after a rest
    turn_rad_per_m: float = 0.25  # chest: toward the fretting hand, per metre down the neck
    shoulder_slack_m: float = 0.42  # the fretting shoulder reaches toward a wrist farther...
    shoulder_max_rad: float = 0.9  # ...than this, turning its collarbone at most this much
    thumb_position_fret: int = 12
    vibrato_m: float = 0.003  # left hand rolling along the string on a long note
    vibrato_hz: float = 5.0
    vibrato_after_s: float = 0.25  # it starts this long after the impact
    long_note_s: float = 0.45  # notes at least this long get vibrato
    lean_follow: float = 0.8  # the bass's contact point follows this much of the chest's move
    reach_share: float = 0.8  # the fretting wrist beside the board: at most this much of the
    arch_m: float = 0.045  # hand sideways; beyond, it rises this far in front of the strings
    arch_ramp_m: float = 0.01  # as it stays this far over the board's low edge
    arch_elbow_m: float = 0.55  # the arched hand's elbow pole raised up to this far to the front


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
CHEST = _SK.index("Chest")
_LTIP = _SK.index("LeftHandEnd")
_FINGER_BONES = 17  # the left hand's 10 (four fingers of two, the thumb's two), the right's 7

# the fretting wrist beside the fingerboard's low (E, B) edge (virja.fingerboard), this far out
WRIST_BESIDE_M = 0.005
WRIST_OVER_MAX_M = 0.010  # at most this far over it, where the hand cannot reach round
# a forearm this far in front of the strings or more passes over the board (arched over it,
# as in thumb position), not across or through it
CLEAR_OF_STRINGS_M = 0.02
# the fretting elbow's pole pushed toward the E side as the fingertip goes toward the G
# side (m of push per m the tip is past the board's centre line), up to POLE_PUSH_MAX_M
POLE_PUSH_PER_M = 12.0
POLE_PUSH_MAX_M = 0.6

NeckFrame = Fingerboard  # the board's frame and edges (the name the motion code used)


def neck_frame(geometry: Geometry, strings: tuple[str, ...] = BASS_STRINGS) -> Fingerboard:
    """The fingerboard as render.scene draws it for the tuning's ``strings``."""
    return fingerboard(geometry.bass, tuple(strings))


def forearm_over_board_m(neck: Fingerboard, elbow: np.ndarray, wrist: np.ndarray) -> np.ndarray:
    """How far (m, >= 0) the forearms (..., 3) elbow -> wrist reach over the fingerboard's
    low edge between the neck's back and ``CLEAR_OF_STRINGS_M`` in front of the strings
    (0: the forearm stays behind the neck, beside it, or arched clear over the strings);
    a forearm through the neck counts its whole overlap."""
    u = np.linspace(0.0, 1.0, 17)[:, None]
    e = np.asarray(elbow, dtype=np.float64)[..., None, :]
    w = np.asarray(wrist, dtype=np.float64)[..., None, :]
    c = neck.coords(e + u * (w - e))  # (..., 17, 3)
    by_board = (
        (c[..., 0] > 0.0)
        & (c[..., 0] < neck.length)
        & (c[..., 2] > neck.spec.back_m)
        & (c[..., 2] < CLEAR_OF_STRINGS_M)
    )
    over = np.where(by_board, neck.low_edge(c[..., 0]) - c[..., 1], 0.0)
    return np.asarray(np.clip(over, 0.0, None).max(axis=-1))


SIDE_OVER_M = 0.01  # a wrist beside the board: at most this far over its low edge...
ARCHED_M = 0.02  # ...and less than this in front of the fingertip; or arched over the board


def fretting_side(
    neck: Fingerboard, elbow: np.ndarray, wrist: np.ndarray, tip: np.ndarray
) -> np.ndarray:
    """Whether the fretting hand (elbow, wrist, fingertip (..., 3)) is on the correct side:
    its wrist toward the low side from the fingertip, and either beside the board (at most
    ``SIDE_OVER_M`` over its low edge, less than ``ARCHED_M`` in front of the fingertip,
    the elbow behind the strings) or arched over it (``ARCHED_M`` or more in front, as in
    thumb position) with the elbow out beyond the board's low edge."""
    e, w, t = neck.coords(elbow), neck.coords(wrist), neck.coords(tip)
    front = w[..., 2] - t[..., 2]
    beside = (w[..., 1] > neck.low_edge(w[..., 0]) - SIDE_OVER_M) & (front < ARCHED_M)
    beside &= e[..., 2] < 0.0
    arched = (front >= ARCHED_M) & (e[..., 1] > neck.low_edge(e[..., 0]))
    return np.asarray((w[..., 1] > t[..., 1]) & (beside | arched))


def _frames(direction: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    """(k, 3, 3) frames with columns (direction, hinge made perpendicular, their cross)."""
    return frames(direction, hinge, floor=0.0)


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
    hinge = quat.cross(u1, u2)
    straight = np.linalg.norm(hinge, axis=-1) < 1e-9  # a straight arm bends toward its pole
    hinge[straight] = quat.cross(u1[straight], v[straight])
    upper = quat.from_matrix(_frames(u1, hinge) @ _REST_T)
    lower = quat.from_matrix(_frames(u2, hinge) @ _REST_T)
    return upper, lower


def _position_of(motion: MotionKey, fret: int) -> int:
    """The left hand's position the planner chose (:attr:`BassPluck.position`), or the
    fret's own when it chose none."""
    pos = motion.position if isinstance(motion, BassPluck) else None
    return pos if pos is not None else max(fret, 1)


def _unit_rows(v: np.ndarray) -> np.ndarray:
    """:func:`_unit` of each row of ``v`` (m, 3)."""
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 1e-12, v / np.where(n > 1e-12, n, 1.0), v)


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
        self.neck = neck_frame(geometry)

    def use_strings(self, strings: tuple[str, ...]) -> None:
        """The tuning's strings: the fingerboard (and so where the fretting wrist goes
        beside it) is as wide as they need."""
        self.neck = neck_frame(self.geometry, strings)

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

    def fingers_many(self, times: np.ndarray, wpos: np.ndarray) -> np.ndarray:
        """:meth:`fingers` at many times at once: (m, k, 2, 3) for ``times`` (m,) and the
        joint positions ``wpos`` (m, n, 3); one numpy pass over all frames (equal to
        :meth:`fingers` frame by frame, tests/motion/test_bassist_fingers_batch.py)."""
        t = np.asarray(times, dtype=np.float64)
        wpos = np.asarray(wpos, dtype=np.float64)
        tab = self._note_table()
        starts = tab.start
        if t.size == 0:
            return np.zeros((0, _FINGER_BONES, 2, 3))
        # no notes yet, or notes added out of order: frame by frame
        if starts.size == 0 or np.any(np.diff(starts) < 0):
            return np.stack([self.fingers(float(x), w) for x, w in zip(t, wpos, strict=True)])
        return np.concatenate(
            [self._left_many(t, wpos, tab), self._right_many(t, wpos, tab)], axis=1
        )

    def _incoming_many(
        self, t: np.ndarray, tab: _NoteTable, stopped: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_incoming` at times ``t`` (m,): indices of (previous, next) notes (-1:
        none) and ``w``."""
        rows = tab.fretted if stopped else np.arange(tab.impact.size)
        i = np.searchsorted(tab.impact, t + 1.0, side="right")  # notes struck by t + 1 s
        lo = np.maximum(i - 48, 0)  # the window the per-frame version looks in
        k_end = np.searchsorted(rows, i, side="left")  # filtered notes before i
        k = np.minimum(np.searchsorted(tab.start[rows], t, side="right"), k_end) - 1
        row = np.where(k >= 0, rows[np.maximum(k, 0)] if rows.size else 0, -1)
        nxt = np.where((k >= 0) & (row >= lo), row, -1)
        prow = np.where(k >= 1, rows[np.maximum(k - 1, 0)] if rows.size else 0, -1)
        prev = np.where((nxt >= 0) & (prow >= lo), prow, -1)
        j = np.maximum(nxt, 0)
        span = tab.impact[j] - tab.start[j]  # (there is a note: fingers_many checks)
        safe = np.where(span > 1e-9, span, 1.0)
        u = np.where(span <= 1e-9, 1.0, np.clip((t - tab.start[j]) / safe, 0.0, 1.0))
        w = np.where(nxt >= 0, u * u * (3.0 - 2.0 * u), 1.0)
        return prev, nxt, w

    def _layouts(self, tab: _NoteTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_layout` of every note and of the rest position (the last row): tips
        (k + 1, 4, 3), thumbs (k + 1, 3), and the stopping finger (k + 1,)."""
        if tab.layouts is None:
            lay = [self._layout(n) for n in self._notes] + [self._layout(None)]
            tips = np.array([a for a, _ in lay]).reshape(-1, 4, 3)
            thumbs = np.array([b for _, b in lay]).reshape(-1, 3)
            stopping = np.argmin(np.linalg.norm(tips, axis=-1), axis=-1)
            object.__setattr__(tab, "layouts", (tips, thumbs, stopping))
        assert tab.layouts is not None
        return tab.layouts

    def _left_many(self, t: np.ndarray, wpos: np.ndarray, tab: _NoteTable) -> np.ndarray:
        s = self.settings
        front = self.geometry.bass.front
        tip = wpos[:, _SK.index("LeftHandEnd")]
        wrist = wpos[:, _SK.index("LeftHand")]
        prev, nxt, w = self._incoming_many(t, tab, stopped=True)
        tips, thumbs, stopping = self._layouts(tab)
        rest = len(tips) - 1
        a = np.where(prev >= 0, prev, np.where(nxt >= 0, nxt, rest))
        b = np.where(nxt >= 0, nxt, rest)
        offs = (1.0 - w)[:, None, None] * tips[a] + w[:, None, None] * tips[b]  # (m, 4, 3)
        thumb_tip = (1.0 - w)[:, None] * thumbs[a] + w[:, None] * thumbs[b]
        last = np.searchsorted(tab.impact, t, side="right") - 1
        j = np.maximum(nxt, 0)
        pressing = (nxt >= 0) & (last == nxt) & (t < tab.off[j]) & (tab.impact[j] <= t)
        press = pressing.astype(np.float64)[:, None]
        not_stopping = np.arange(4)[None, :] != stopping[b][:, None]  # (m, 4)
        rise = s.hover_m * not_stopping * press + s.lift_m * (1.0 - press)  # (m, 4)
        back = _unit_rows(wrist - tip)[:, None]
        ftip = tip[:, None] + offs + rise[..., None] * front
        knuckle = tip[:, None] + offs * 0.6 + s.finger_len_m * back
        mid = 0.5 * (knuckle + ftip) + 0.35 * s.finger_len_m * front
        m = len(t)
        out = np.empty((m, 10, 2, 3))
        out[:, 0:8:2, 0], out[:, 0:8:2, 1] = knuckle, mid
        out[:, 1:8:2, 0], out[:, 1:8:2, 1] = mid, ftip
        thumb_base = wrist + 0.3 * (tip - wrist)
        thumb_mid = 0.5 * (thumb_base + thumb_tip) - 0.01 * front
        out[:, 8, 0], out[:, 8, 1] = thumb_base, thumb_mid
        out[:, 9, 0], out[:, 9, 1] = thumb_mid, thumb_tip
        return out

    def _right_many(self, t: np.ndarray, wpos: np.ndarray, tab: _NoteTable) -> np.ndarray:
        s = self.settings
        b = self.geometry.bass
        tip = wpos[:, _SK.index("RightHandEnd")]
        wrist = wpos[:, _SK.index("RightHand")]
        prev, nxt, w = self._incoming_many(t, tab, stopped=False)
        finger = np.where(nxt >= 0, tab.right_finger[np.maximum(nxt, 0)], 0)
        first = np.where(prev >= 0, w, 1.0)  # the plucking finger's share
        plucking = np.where(np.arange(2)[None, :] == finger[:, None], first[:, None], 0.0)
        plucking = np.where(
            np.arange(2)[None, :] == finger[:, None], plucking, 1.0 - first[:, None]
        )
        along = b.string_dir("A")
        back = _unit_rows(wrist - tip)
        side = np.array([-0.02, 0.02])[None, :, None]  # index toward the nut, middle beside
        rest = side * along + s.hover_m * 2 * b.front  # (1, 2, 3)
        ftip = tip[:, None] + (1.0 - plucking)[..., None] * rest
        knuckle = tip[:, None] + 0.6 * side * along + s.finger_len_m * back[:, None]
        mid = 0.5 * (knuckle + ftip) + 0.25 * s.finger_len_m * b.front
        m = len(t)
        out = np.empty((m, 7, 2, 3))
        out[:, 0:4:2, 0], out[:, 0:4:2, 1] = knuckle, mid
        out[:, 1:4:2, 0], out[:, 1:4:2, 1] = mid, ftip
        palm = tip + 0.6 * s.finger_len_m * back
        for k, off in enumerate((0.035, 0.05)):
            out[:, 4 + k, 0] = palm + off * along
            out[:, 4 + k, 1] = palm + off * along - 0.02 * back + 0.01 * b.front
        out[:, 6, 0] = tip + s.finger_len_m * back - 0.02 * along
        out[:, 6, 1] = tip - 0.06 * along + 0.02 * b.front + 0.02 * self._lateral
        return out

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
        if tab.impact.size == 0:  # no notes yet: the player stands still
            return out
        # every frame, those before the first note too: the body stands still there (the
        # envelope is 0) but the fretting arm goes round the board as it will at the note
        rows = np.arange(len(t))
        last = np.maximum(i - 1, 0)
        loud = (0.6 + 0.4 * tab.velocity[last] / 127) * self._envelope(tab, t, i)
        # weight from one foot to the other over two beats, on a foot at each beat; the
        # spine dipping deepest just after each beat (``dip_after_beat`` of a beat)
        phase = np.asarray(beat_phase, dtype=np.float64)[rows]
        two = (np.asarray(beat_index)[rows] % 2 + phase) / 2.0
        sway = s.sway_rad * loud * np.cos(2 * np.pi * two)
        dip = s.dip_rad * loud * (0.5 + 0.5 * np.cos(2 * np.pi * (phase - s.dip_after_beat)))
        # the chest turns with the fretting hand: lower on the neck, further toward the bass
        # (where the fingertip is along the neck: it moves on continuously between notes)
        held = tab.has_fretted(i)
        out[rows] = self._moved(loc, root, sway, dip, held, self._vibrato_many(t, last))
        return out

    def _envelope(self, tab: _NoteTable, t: np.ndarray, i: np.ndarray) -> np.ndarray:
        """How much the body moves (m,) at times ``t`` whose notes struck so far are
        ``[:i]``: fully while playing; 2 s after a note it settles over a second; it
        comes back over ``body_ramp_s`` before the next note, and grows over that long
        after the first.  Continuous in time (a max of continuous windows)."""
        ramp = self.settings.body_ramp_s
        after = np.clip(3.0 - (t - tab.impact[np.maximum(i - 1, 0)]), 0.0, 1.0)
        nxt = np.append(tab.impact, math.inf)[i]
        before = np.clip(1.0 + (t - nxt) / ramp, 0.0, 1.0)
        first = np.clip((t - tab.impact[0]) / ramp, 0.0, 1.0)
        return np.asarray(np.maximum(after, before) * first)

    def lean(self, chest: np.ndarray, rest_chest: np.ndarray) -> np.ndarray:
        """The bass's lean (..., 4) for the chest at ``chest`` (..., 3) (see
        :mod:`virja.motion.bass_lean`; ``rest_chest`` where it stands still)."""
        return bass_lean.lean(chest, rest_chest, self.geometry.bass, self.settings.lean_follow)

    def _wrist_beside_board(
        self, wrist: np.ndarray, tip: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The fretting wrists (m, 3) moved round their fingertips (m, 3) (the hand turned
        about the tip, the tip kept) to lie beside the fingerboard's low edge; where the
        hand cannot reach round it (a high string on a wide board, high up the neck), as
        near it as ``reach_share`` of the hand reaches, the wrist rising in front of the
        strings (the hand arched over the board, as in thumb position) by up to
        ``arch_m`` as it stays over the board by up to ``arch_ramp_m``; the turns (m, 4)
        of the hands; and how far each hand is arched for its elbow (m,), 0..1 as the
        wrist stays up to three times ``arch_ramp_m`` over the edge (the elbow rises over
        a few frames).  A wrist already beside the board stays."""
        s = self.settings
        n = self.neck
        rel = wrist - tip
        length = np.linalg.norm(rel, axis=-1)
        c_tip = n.coords(tip)
        need = n.low_edge(c_tip[:, 0]) + WRIST_BESIDE_M
        move = (n.coords(wrist)[:, 1] < need) & (length >= 1e-9)
        turn = quat.identity((len(wrist),))
        arched = np.zeros(len(wrist))
        if not move.any():
            return wrist, turn, arched
        rel, length, tip = rel[move], length[move], tip[move]
        d_need = need[move] - c_tip[move, 1]
        d_lat = np.minimum(d_need, s.reach_share * length)
        short = d_need - d_lat  # how far the wrist stays over the board's edge
        # the rest of the hand's length in the plane (along, face), in the direction the
        # clip had it, its face part raised as the wrist stays over the board
        r = np.sqrt(np.maximum(length**2 - d_lat**2, 0.0))
        along = rel @ n.along
        face = rel @ n.face
        norm = np.hypot(along, face)
        ok = norm > 1e-9
        f0 = np.where(ok, face / np.where(ok, norm, 1.0), 1.0)
        a0 = np.where(ok, along / np.where(ok, norm, 1.0), 0.0)
        ramp = np.clip(short / s.arch_ramp_m, 0.0, 1.0)
        lift = -r + (np.minimum(s.arch_m, r) + r) * ramp  # -r (none) .. arch_m
        f = np.maximum(r * f0, lift)
        a = np.where(a0 >= 0.0, 1.0, -1.0) * np.sqrt(np.maximum(r**2 - f**2, 0.0))
        new = d_lat[:, None] * n.lateral + a[:, None] * n.along + f[:, None] * n.face
        out = wrist.copy()
        out[move] = tip + new
        turn[move] = quat.from_two_vectors(rel, new)
        arched[move] = np.clip(short / (3.0 * s.arch_ramp_m), 0.0, 1.0)
        return out, turn, arched

    def _posed(
        self,
        loc: np.ndarray,
        root: np.ndarray,
        rest_chest: np.ndarray,
        targets: np.ndarray,
        motion: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The torso moved by ``motion`` (sway, dip, turn (m,)), its FK, the bass leaning
        with the chest (m, 4) and the hands' targets (m, 2, 3) leaned with it."""
        out = _torso(loc, *motion)
        pos, rot = _SK.fk_matrices(out, root)
        q = self.lean(pos[:, CHEST], rest_chest)
        m = bass_lean.matrix(q, self.geometry.bass.endpin)
        leaned = np.einsum("mij,mkj->mki", m[:, :3, :3], targets) + m[:, None, :3, 3]
        return out, pos, rot, q, leaned

    def _reach_with_shoulder(
        self, out: np.ndarray, pos: np.ndarray, rot: np.ndarray, wrist: np.ndarray
    ) -> np.ndarray:
        """Turn the left collarbone of ``out`` (m, n, 4; in place) toward ``wrist`` (m, 3)
        by as much as the shoulder is farther than ``shoulder_slack_m`` from it (bounded);
        the frames (indices) where it turned."""
        s = self.settings
        clav, shoulder = pos[:, _SHOULDERS[0]], pos[:, _ARMS[0]]
        excess = np.linalg.norm(wrist - shoulder, axis=-1) - s.shoulder_slack_m
        bone = shoulder - clav
        axis = quat.cross(bone, wrist - clav)
        n = np.linalg.norm(axis, axis=-1)
        rows = np.nonzero((excess > 0.0) & (n >= 1e-12))[0]
        if rows.size == 0:
            return rows
        angle = np.minimum(excess[rows] / np.linalg.norm(bone[rows], axis=-1), s.shoulder_max_rad)
        world = quat.multiply(
            quat.from_axis_angle(axis[rows] / n[rows, None], angle),
            quat.from_matrix(rot[rows, _SHOULDERS[0]]),
        )
        parent = int(_SK.parents[_SHOULDERS[0]])
        out[rows, _SHOULDERS[0]] = quat.multiply(
            quat.conjugate(quat.from_matrix(rot[rows, parent])), world
        )
        return rows

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
        held: np.ndarray,
        vibrato: np.ndarray,
    ) -> np.ndarray:
        wpos, wrot = _SK.fk_matrices(loc, root)
        neck_tip = self.neck.coords(wpos[:, _LTIP])  # (m, 3) along, lateral, face
        down = np.where(held, np.clip(neck_tip[:, 0], 0.0, self.neck.length), 0.0)
        turn = self.settings.turn_rad_per_m * down
        targets = wpos[:, _HANDS].copy()
        hand_rot = quat.from_matrix(wrot[:, _HANDS])
        # the fretting wrist beside the board's E edge, so the forearm stays behind the neck
        targets[:, 0], turn_hand, arched = self._wrist_beside_board(
            wpos[:, _HANDS[0]], wpos[:, _LTIP]
        )
        hand_rot[:, 0] = quat.multiply(turn_hand, hand_rot[:, 0])
        targets[:, 0] += vibrato
        rest_chest = wpos[:, CHEST]
        out, moved_pos, moved_rot, q, leaned = self._posed(
            loc, root, rest_chest, targets, (sway, dip, turn)
        )
        # less of it where an arm near full stretch could no longer keep its hand in place:
        # the largest share k of the motion (shoulders and the leaned targets move about
        # linearly with it) that leaves both wrists within reach
        reach = _ARM_LEN[0] + _ARM_LEN[1] - 1e-3
        k = np.ones(len(loc))
        for i in range(2):
            s0, s1 = wpos[:, _ARMS[i]], moved_pos[:, _ARMS[i]]
            far = np.nonzero(np.linalg.norm(leaned[:, i] - s1, axis=-1) > reach)[0]
            if far.size == 0:
                continue
            lo, hi = np.zeros(far.size), np.ones(far.size)
            a, b = s0[far], s1[far] - s0[far]
            g, dg = targets[far, i], leaned[far, i] - targets[far, i]
            for _ in range(12):
                mid = 0.5 * (lo + hi)[:, None]
                out_of_reach = np.linalg.norm(g + mid * dg - (a + mid * b), axis=-1) > reach
                hi = np.where(out_of_reach, mid[:, 0], hi)
                lo = np.where(out_of_reach, lo, mid[:, 0])
            k[far] = np.minimum(k[far], lo)
        less = np.nonzero(k < 1.0)[0]
        if less.size:
            kl = k[less]
            motion = (kl * sway[less], kl * dip[less], kl * turn[less])
            o, p, r, ql, tl = self._posed(loc[less], root, rest_chest[less], targets[less], motion)
            out[less], moved_pos[less], moved_rot[less], q[less], leaned[less] = o, p, r, ql, tl
        # the fretting shoulder follows its hand: in the high positions the collarbone turns
        # toward the wrist, so the arm is not stretched straight and its elbow can stay out
        # behind the neck (the chest, and so the bass's lean, are unchanged)
        turned = self._reach_with_shoulder(out, moved_pos, moved_rot, leaned[:, 0])
        if turned.size:
            moved_pos[turned], moved_rot[turned] = _SK.fk_matrices(out[turned], root)
        poles = wpos[:, _FORES] + (moved_pos[:, _ARMS] - wpos[:, _ARMS])
        # the fretting elbow out to the E side as the fingertip reaches toward the G side
        # (the forearm comes round behind the neck, not across the board)
        push = np.minimum(np.maximum(-neck_tip[:, 1], 0.0) * POLE_PUSH_PER_M, POLE_PUSH_MAX_M)
        poles[:, 0] += push[:, None] * quat.rotate(q, self.neck.lateral)
        # and, with the hand arched over the board, raised toward the front so the forearm
        # comes round the board's low edge instead of through it
        lift = arched * self.settings.arch_elbow_m
        poles[:, 0] += lift[:, None] * quat.rotate(q, self.neck.face)
        out_more = np.maximum(arched * POLE_PUSH_MAX_M - push, 0.0)  # and well out to the side
        poles[:, 0] += out_more[:, None] * quat.rotate(q, self.neck.lateral)
        m = len(loc)
        upper, lower = _two_bone(
            moved_pos[:, _ARMS].reshape(-1, 3), leaned.reshape(-1, 3), poles.reshape(-1, 3)
        )
        upper, lower = upper.reshape(m, 2, 4), lower.reshape(m, 2, 4)
        shoulders = quat.from_matrix(moved_rot[:, _SHOULDERS])
        out[:, _ARMS] = quat.multiply(quat.conjugate(shoulders), upper)
        out[:, _FORES] = quat.multiply(quat.conjugate(upper), lower)
        # the hands keep their grip on the leaned bass: turned with it
        hands = quat.multiply(q[:, None], hand_rot)
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
    string_dir: np.ndarray  # (k, 3)
    fretted: np.ndarray  # indices of the stopped notes
    right_finger: np.ndarray  # (k,) 0 index, 1 middle
    # the left hand's finger layouts (Bassist._layouts), filled in when first asked for
    layouts: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

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
            string_dir=np.array([dirs[n.string] for n in notes]).reshape(-1, 3),
            fretted=np.nonzero(fret > 0)[0],
            right_finger=np.array([n.right_finger for n in notes], dtype=np.int64),
        )

    def has_fretted(self, i: np.ndarray) -> np.ndarray:
        """Whether a stopped note is held at times whose notes struck so far are ``[:i]``
        (m,): one among the last 32 (:meth:`Bassist.fretted`)."""
        k = np.searchsorted(self.fretted, i, side="left") - 1
        j = self.fretted[np.maximum(k, 0)] if self.fretted.size else np.zeros_like(i)
        return np.asarray((k >= 0) & (j >= i - 32))
