"""The drummer's living body (issue 15, deliverable 5): a turning torso that breathes.

The hand and foot clips are authored in world space with a still torso.  This
layer moves the torso over them and then re-solves the arms so the hands
stay where the clips put them:

- **turn**: the spine and chest turn (yaw) toward the pieces the two hands
  play: a step function of time (at each stroke's impact the hand's piece
  changes; no sooner than half the window after the stroke is known, so live the
  turn never changes under a frame drawn) averaged over both hands, scaled by
  ``gain`` and clamped, then smoothed by a centred moving average (so the turn
  starts before the stroke and never jumps).
- **breathing**: the chest pitches slowly (``breath_deg`` at ``breath_period_s``).
- **beat**: the spine leans forward on each beat (sin^2 of the beat phase),
  ``beat_deg`` at 120 bpm, smaller when faster (times ``spb / 0.5``, clamped),
  and the torso turns ``sway_deg`` to one side and back on each beat (scaled the
  same way, clamped to ``sway_floor``-``sway_ceiling``): the way the turn goes
  over the beat's first half, else one way on one beat, the other on the next.
- **feathered kick**: on each beat with no kick near it the right ankle presses
  the kick's board a little (``feather_deg``, a cos^2 bump), as jazz drummers
  feather the bass drum: the idle foot is never frozen.
- **arms**: while a hand is playing (within ``engage_s`` of one of its
  impacts) each arm is re-solved as a two-bone chain from its moved shoulder
  to the wrist of the authored pose, elbow toward the authored elbow, and the
  hand keeps its authored world rotation: the grip and the stick are where
  the clip put them, so contact and timing at impact are unchanged.  Further
  from its strokes a resting hand blends (over ``release_s``) to riding with
  the body's sway about the spine (not its turn toward the pieces, which would
  carry it into the other stick): it sways instead of hanging frozen in space.

Before his first stroke (of any limb) the drummer sits still (the body wakes
over the ``engage_s`` before it).  The hips and legs are not moved (the feet stay on the pedals; only the right
ankle feathers).  Constants:
motions/drummer_body.toml.  Everything is vectorised over times.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from virja import quat
from virja.geometry import GEOMETRY, Geometry
from virja.motion.ik import frames
from virja.motion.skeleton import SKELETON
from virja.vocab import HANDS

_SK = SKELETON
_HIPS = _SK.index("Hips")
_SPINE = _SK.index("Spine")
_CHEST = _SK.index("Chest")
_NECK = _SK.index("Neck")
_RFOOT = _SK.index("RightFoot")
_ARMS = {
    "left_hand": tuple(_SK.index(f"Left{j}") for j in ("Shoulder", "Arm", "ForeArm", "Hand")),
    "right_hand": tuple(_SK.index(f"Right{j}") for j in ("Shoulder", "Arm", "ForeArm", "Hand")),
}
_ARM_JOINTS = [j for hand in HANDS for j in _ARMS[hand]]
_UP = np.array([0.0, 1.0, 0.0])
_SIDE = np.array([1.0, 0.0, 0.0])


@dataclass(frozen=True)
class BodySettings:
    """Constants from motions/drummer_body.toml (reasons given there)."""

    gain: float = 0.45
    max_turn_deg: float = 12.0
    smooth_s: float = 0.5
    chest_share: float = 0.5
    head_share: float = 0.5
    breath_deg: float = 0.8
    breath_period_s: float = 3.6
    beat_deg: float = 1.5
    sway_deg: float = 2.0
    sway_floor: float = 0.8
    sway_ceiling: float = 2.0
    sway_follow_deg: float = 0.05
    reference_spb: float = 0.5
    engage_s: float = 1.0
    release_s: float = 0.5
    feather_deg: float = 3.0
    feather_width_s: float = 0.12
    feather_clear_s: float = 0.3

    @classmethod
    def still(cls) -> BodySettings:
        """No body layer at all: the limbs exactly as the clips put them (for tests of the clips)."""
        return cls(gain=0.0, breath_deg=0.0, beat_deg=0.0, sway_deg=0.0, feather_deg=0.0)

    @property
    def is_still(self) -> bool:
        return (
            self.gain == self.breath_deg == self.beat_deg == self.sway_deg == self.feather_deg == 0
        )

    @classmethod
    def load(cls, path: Path | None = None) -> BodySettings:
        from virja.motion.settings_files import body_settings
        from virja.resources import motions_file

        found = motions_file("drummer_body.toml", path)
        return cls() if found is None else body_settings(found)


class DrummerBody:
    """The strokes of the two hands, and the body layer computed from them."""

    def __init__(
        self,
        root: np.ndarray,
        geometry: Geometry = GEOMETRY,
        settings: BodySettings | None = None,
    ) -> None:
        self.settings = settings or BodySettings.load()
        # azimuth (rad, about +y, 0 = facing +z) of each piece seen from the chest
        chest = np.asarray(root, dtype=np.float64) + _SK.offsets[_SPINE] + _SK.offsets[_CHEST]
        self.azimuth: dict[str, float] = {}
        for name, piece in geometry.kit.pieces.items():
            d = np.asarray(piece.centre) - chest
            self.azimuth[name] = float(np.arctan2(d[0], d[2]))
        self._times: dict[str, list[float]] = {h: [] for h in HANDS}
        self._az: dict[str, list[float]] = {h: [] for h in HANDS}
        # when the turn takes each stroke's piece in (add_stroke), in the impacts' order
        self._turn_at: dict[str, list[float]] = {h: [] for h in HANDS}
        self._kicks: list[float] = []  # the right foot's strokes (no feathering near them)
        self._first = math.inf  # the first stroke of any limb: the body wakes for it
        self._side: dict[float, float] = {}  # beat start -> the side it sways to (_sides)

    def add_stroke(
        self, limb: str, impact: float, piece: str | None, known: float | None = None
    ) -> None:
        """Record a hand's stroke or a kick (the hi-hat pedal and unknown pieces only
        wake the body: GMD rock 118, three pedal chicks and nothing else, sat still).

        ``known``: when the stroke became known (its motion's start, or the latest frame
        shown if later); the turn takes the hand's new piece in at the impact, or half
        its window after ``known`` where that is later, so the turn never changes under
        a frame drawn before (:meth:`turn`)."""
        self._first = min(self._first, impact)
        if limb == "right_foot":
            bisect.insort(self._kicks, impact)
            return
        if limb not in self._times or piece not in self.azimuth:
            return
        i = bisect.bisect_right(self._times[limb], impact)
        self._times[limb].insert(i, impact)
        self._az[limb].insert(i, self.azimuth[piece])
        half = self.settings.smooth_s / 2
        self._turn_at[limb].insert(i, impact if known is None else max(impact, known + half))

    def forget_before(self, time_s: float) -> None:
        horizon = time_s - 10.0
        for h in HANDS:
            k = max(bisect.bisect_left(self._times[h], horizon) - 1, 0)
            del self._times[h][:k]
            del self._az[h][:k]
            del self._turn_at[h][:k]
        del self._kicks[: max(bisect.bisect_left(self._kicks, horizon) - 1, 0)]
        for b in [b for b in self._side if b < horizon]:
            del self._side[b]

    # ------------------------------------------------------------------ curves

    def _hand_azimuth(self, hand: str, t: np.ndarray) -> np.ndarray:
        """Azimuth of the hand's piece for the turn: the latest stroke's taken in by
        ``t`` (``_turn_at``); none (NaN) before the first (live, the first stroke's piece
        taken in before it was known turned the torso at once)."""
        at = np.asarray(self._turn_at[hand], dtype=np.float64)
        az = np.asarray(self._az[hand], dtype=np.float64)
        if at.size == 0:
            return np.full(t.shape, np.nan)
        # the latest stroke i with at[i] <= t is the last i whose suffix minimum is <= t
        # (a stroke taken in later than the next one's is never shown)
        first = np.minimum.accumulate(at[::-1])[::-1]
        i = np.searchsorted(first, t, side="right") - 1
        return np.asarray(np.where(i >= 0, az[np.maximum(i, 0)], np.nan))

    def _target(self, t: np.ndarray) -> np.ndarray:
        s = self.settings
        both = np.stack([self._hand_azimuth(h, t) for h in HANDS])
        n = np.sum(~np.isnan(both), axis=0)
        mean = np.where(n > 0, np.nansum(both, axis=0) / np.maximum(n, 1), 0.0)
        lim = np.radians(s.max_turn_deg)
        return np.asarray(np.clip(s.gain * mean, -lim, lim))

    def turn(self, t: np.ndarray) -> np.ndarray:
        """The torso's yaw (rad) at times ``t``: the target's exact moving average over
        ``smooth_s`` (the target is a step function, so the turn is piecewise linear)."""
        t = np.asarray(t, dtype=np.float64)
        half = self.settings.smooth_s / 2
        # sorted, each once (np.unique's first call imports numpy.ma: 16 ms in a render's
        # first chunk; docs/performance.md, "Pose and scene, eighth round")
        steps = np.sort(
            np.concatenate([np.asarray(self._turn_at[h], dtype=np.float64) for h in HANDS])
        )
        steps = steps[np.concatenate([[True], steps[1:] != steps[:-1]])] if steps.size else steps
        if steps.size == 0 or t.size == 0:
            return np.asarray(self._target(t))
        lo = min(float(t.min()) - half, float(steps[0])) - 1.0
        hi = max(float(t.max()) + half, float(steps[-1])) + 1.0
        knots = np.concatenate([[lo], steps, [hi]])
        values = self._target((knots[:-1] + knots[1:]) / 2)  # the target on each interval
        integral = np.concatenate([[0.0], np.cumsum(values * np.diff(knots))])
        area = np.interp(t + half, knots, integral) - np.interp(t - half, knots, integral)
        return np.asarray(area / (2 * half))

    def engagement(self, hand: str, t: np.ndarray) -> np.ndarray:
        """1 while ``hand`` plays (within ``engage_s`` of an impact), fading to 0 at rest."""
        s = self.settings
        ts = np.asarray(self._times[hand])
        if ts.size == 0:
            return np.zeros(t.shape)
        i = np.searchsorted(ts, t)
        prev = ts[np.clip(i - 1, 0, ts.size - 1)]
        nxt = ts[np.clip(i, 0, ts.size - 1)]
        gap = np.minimum(np.abs(t - prev), np.abs(nxt - t))
        return np.asarray(np.clip((s.engage_s + s.release_s - gap) / s.release_s, 0.0, 1.0))

    def _beat_phase(
        self, t: np.ndarray, beat_times: np.ndarray, beat_spb: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Phase in the current beat (0..1), seconds per beat, +-1 alternating by beat,
        and the beat's start."""
        s = self.settings
        i = np.searchsorted(beat_times, t, side="right") - 1
        if beat_times.size:
            k = np.maximum(i, 0)
            spb = beat_spb[k]
            start = beat_times[k]
            phase = np.where(i >= 0, np.minimum((t - start) / spb, 1.0), 0.0)
        else:
            spb = np.full(t.shape, s.reference_spb)
            start = np.floor(t / spb) * spb
            phase = np.mod(t / spb, 1.0)
        # alternate by the beat's place on its tempo's grid; the sin^2 shapes below are
        # 0 at every beat, so a tempo change that repeats a sign never makes a jump
        sign = np.where(np.mod(np.round(start / spb), 2) == 0, 1.0, -1.0)
        return phase, spb, sign, start

    def _sides(
        self, t: np.ndarray, start: np.ndarray, spb: np.ndarray, parity: np.ndarray
    ) -> np.ndarray:
        """The side (+-1) the torso sways to on the beat of each of ``t`` (beginning at
        ``start``, ``spb`` long): the way the turn goes over the beat's first half, where
        the sway rises (more than ``sway_follow_deg``); else ``parity`` (one way on one
        beat, the other on the next).  A sway going against the turn cancelled it (GMD
        drummer2 rock 130: the left between snare and hi-hat every two beats turned the
        chest 2.8 degrees, the sway 3.7, together 2.8).

        Each beat's side is kept from the first time a pose inside it is asked for
        (``_side``): live, a stroke learnt during the beat never flips the sway (a jump
        of twice its amplitude); given the whole input, every stroke is known then."""
        if t.size == 0:
            return np.array(parity, dtype=np.float64)
        new = np.concatenate([[True], start[1:] != start[:-1]])  # each beat's first sample
        first = np.flatnonzero(new)
        keys = start[first].tolist()
        sides = [self._side.get(k, 0.0) for k in keys]
        todo = [n for n, k in enumerate(keys) if k not in self._side]
        if todo:
            idx = first[todo]
            yaw = self.turn(np.concatenate([start[idx], start[idx] + 0.5 * spb[idx]]))
            d = yaw[len(idx) :] - yaw[: len(idx)]
            follow = np.abs(d) > np.radians(self.settings.sway_follow_deg)
            chosen = np.where(follow, np.sign(d), parity[idx]).tolist()
            ends = np.concatenate([first[1:], [t.size]])
            for n, c in zip(todo, chosen, strict=True):
                sides[n] = c
                # kept once a pose inside the beat is asked for (before it the sway
                # there is 0, and the strokes that decide it may not be known yet)
                if np.any(t[first[n] : ends[n]] >= keys[n]):
                    self._side[keys[n]] = c
        return np.asarray(np.array(sides, dtype=np.float64)[np.cumsum(new) - 1])

    def _beat(
        self, t: np.ndarray, beat_times: np.ndarray, beat_spb: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Phase in the current beat (0..1), seconds per beat, and the side it sways to
        (:meth:`_sides`)."""
        phase, spb, parity, start = self._beat_phase(t, beat_times, beat_spb)
        return phase, spb, self._sides(t, start, spb, parity)

    def drawn(self, time_s: float, beat_times: Sequence[float], beat_spb: Sequence[float]) -> None:
        """A frame of ``time_s`` was shown: the side its beat sways to is kept from now
        (:meth:`_sides`), as when a pose inside it is asked for.  ``beat_times`` sorted."""
        if self.settings.is_still:
            return
        i = max(bisect.bisect_right(beat_times, time_s) - 1, 0)
        if beat_times and beat_times[i] <= time_s and beat_times[i] in self._side:
            return  # kept already (the window posed this frame): nothing to build per frame
        t = np.array([float(time_s)])
        beats = np.asarray(beat_times[i : i + 1], dtype=np.float64)
        _phase, spb, parity, start = self._beat_phase(t, beats, np.asarray(beat_spb[i : i + 1]))
        if float(start[0]) not in self._side:
            self._sides(t, start, spb, parity)

    def _lean(self, t: np.ndarray, beat_times: np.ndarray, beat_spb: np.ndarray) -> np.ndarray:
        """Forward lean (rad) on each beat."""
        return self._lean_of(*self._beat_phase(t, beat_times, beat_spb)[:3])

    def _lean_of(self, phase: np.ndarray, spb: np.ndarray, _sign: np.ndarray) -> np.ndarray:
        s = self.settings
        amp = np.radians(s.beat_deg) * np.clip(spb / s.reference_spb, 0.3, 1.5)
        return np.asarray(amp * np.sin(np.pi * phase) ** 2)

    def _sway(self, t: np.ndarray, beat_times: np.ndarray, beat_spb: np.ndarray) -> np.ndarray:
        """Side-to-side turn (rad) with the beat: toward where the turn goes (:meth:`_sides`),
        else one way on one beat, the other on the next."""
        return self._sway_of(*self._beat(t, beat_times, beat_spb))

    def _sway_of(self, phase: np.ndarray, spb: np.ndarray, sign: np.ndarray) -> np.ndarray:
        s = self.settings
        amp = np.radians(s.sway_deg) * np.clip(spb / s.reference_spb, s.sway_floor, s.sway_ceiling)
        return np.asarray(sign * amp * np.sin(np.pi * phase) ** 2)

    # ------------------------------------------------------------------ apply

    def feather(self, t: np.ndarray, beat_times: np.ndarray) -> np.ndarray:
        """The right ankle's press (rad, toe down) at ``t``: a feathered kick, a cos^2 bump
        ``feather_width_s`` either side of each beat with no kick within ``feather_clear_s``
        (the board moves, the beater barely leaves its rest; nothing sounds)."""
        s = self.settings
        if beat_times.size == 0 or s.feather_deg == 0.0:
            return np.zeros(t.shape)
        kicks = np.asarray(self._kicks, dtype=np.float64)
        if kicks.size:
            k = np.clip(np.searchsorted(kicks, beat_times), 1, kicks.size) - 1
            near = np.minimum(
                np.abs(kicks[k] - beat_times),
                np.abs(kicks[np.minimum(k + 1, kicks.size - 1)] - beat_times),
            )
            free = near > s.feather_clear_s
        else:
            free = np.ones(beat_times.size, dtype=bool)
        i = np.clip(np.searchsorted(beat_times, t), 1, beat_times.size) - 1
        j = np.minimum(i + 1, beat_times.size - 1)
        out = np.zeros(t.shape)
        for b in (i, j):  # the beats either side: bumps are narrower than a beat
            dt = np.abs(t - beat_times[b]) / s.feather_width_s
            bump = np.where(dt < 1.0, np.cos(0.5 * np.pi * np.minimum(dt, 1.0)) ** 2, 0.0)
            out = np.maximum(out, np.where(free[b], bump, 0.0))
        return np.radians(s.feather_deg) * out

    def apply(
        self,
        times: np.ndarray,
        local: np.ndarray,
        root: np.ndarray,
        beat_times: np.ndarray,
        beat_spb: np.ndarray,
    ) -> np.ndarray:
        """The drummer's local rotations (m, n, 4) at ``times`` (m,) with the body layer on."""
        s = self.settings
        t = np.asarray(times, dtype=np.float64)
        out = np.array(local, dtype=np.float64, copy=True)
        if s.is_still:
            return out
        # before his first stroke the drummer sits still; the body wakes over the second before it
        if self._first == math.inf:
            return out
        awake = np.clip(t - (self._first - s.engage_s), 0.0, s.engage_s) / s.engage_s
        beat = self._beat(t, beat_times, beat_spb)  # (phase, spb, side)
        sway = awake * self._sway_of(*beat)  # a resting hand rides with it
        yaw = awake * self.turn(t) + sway
        breath = awake * np.radians(s.breath_deg) * np.sin(2 * np.pi * t / s.breath_period_s)
        lean = awake * self._lean_of(*beat)
        hips = out[:, _HIPS]
        spine_turn = quat.from_axis_angle(_UP, yaw * (1.0 - s.chest_share))
        chest_turn = quat.from_axis_angle(_UP, yaw * s.chest_share)
        # world-vertical turns expressed in the parent's frame (the hips do not move)
        spine_w = quat.multiply(quat.from_axis_angle(_SIDE, lean), spine_turn)
        out[:, _SPINE] = quat.multiply(
            quat.multiply(quat.conjugate(hips), quat.multiply(spine_w, hips)), out[:, _SPINE]
        )
        chest_local = quat.multiply(chest_turn, quat.from_axis_angle(_SIDE, breath))
        out[:, _CHEST] = quat.multiply(chest_local, out[:, _CHEST])
        out[:, _NECK] = quat.multiply(quat.from_axis_angle(_UP, yaw * s.head_share), out[:, _NECK])
        press = awake * self.feather(t, beat_times)
        out[:, _RFOOT] = quat.multiply(out[:, _RFOOT], quat.from_axis_angle(_SIDE, press))
        # forward kinematics with world rotations as matrices, before and after the body
        # layer in one pass; only the arms' converted
        m = len(t)
        p, mat = _SK.fk_matrices(np.concatenate([np.asarray(local, dtype=np.float64), out]), root)
        r = np.zeros(mat.shape[:-2] + (4,))
        r[:, _ARM_JOINTS] = quat.from_matrix(mat[:, _ARM_JOINTS])
        p0, r0, p1, r1 = p[:m], r[:m], p[m:], r[m:]
        # a resting hand rides with the beat's sway about the spine, not with the turn
        # toward the pieces: carried by the whole turn (up to 12 deg + the sway) a hand
        # gone to rest drifted 12 cm from where its track put it, into the other stick
        # hovering over the snare (MMA jazzcombo 60 at 12.5 s, the right resting while
        # the left waits on the snare)
        for hand in HANDS:
            c = self.engagement(hand, t)
            rows = np.flatnonzero((awake > 0.0) | (c > 0.0))
            if rows.size == 0:
                continue
            sh, arm, fore, wrist = _ARMS[hand]
            ride = (1.0 - c) * sway
            if rows.size == len(t):  # every frame (no copies)
                pm, rm, sh_p, sh_r = p0, r0, p1[:, arm], r1[:, sh]
            else:
                pm, rm, sh_p, sh_r = p0[rows], r0[rows], p1[rows, arm], r1[rows, sh]
                ride = ride[rows]
            turned = np.flatnonzero(ride)  # resting: the authored arm carried by the sway
            if turned.size:
                pm, rm = pm.copy(), rm.copy()
                q = quat.from_axis_angle(_UP, ride[turned])
                centre = pm[turned, _SPINE]
                for j in (arm, fore, wrist):
                    pm[turned, j] = centre + quat.rotate(q, pm[turned, j] - centre)
                    rm[turned, j] = quat.multiply(q, rm[turned, j])
            solved = _resolve_arm(pm, rm, sh_p, sh_r, arm, fore, wrist)
            for j, got in zip((arm, fore, wrist), solved, strict=True):
                out[rows, j] = got
        return out


def _frames(d: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Right-handed orthonormal frames (..., 3, 3), columns [d, h orthogonalised, d x h]."""
    return frames(d, h)


_BONE_M = [float(np.linalg.norm(o)) for o in _SK.offsets]  # each joint's bone length (m)


def _resolve_arm(
    p0: np.ndarray,
    r0: np.ndarray,
    shoulder: np.ndarray,
    shoulder_rot: np.ndarray,
    arm: int,
    fore: int,
    wrist: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Local rotations of (arm, forearm, hand) putting the wrist and hand as in the
    authored pose (``p0``, ``r0``) from the moved ``shoulder`` (m, 3)."""
    l1, l2 = _BONE_M[fore], _BONE_M[wrist]
    s0, e0, w = p0[:, arm], p0[:, fore], p0[:, wrist]
    to = w - shoulder
    dist = np.linalg.norm(to, axis=-1)
    d = np.clip(dist, abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6)
    u = to / dist[:, None]
    v = (e0 + shoulder - s0) - shoulder  # the authored elbow, carried with the shoulder
    v = v - np.sum(v * u, axis=-1, keepdims=True) * u
    v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)
    cos_a = np.clip((l1**2 + d**2 - l2**2) / (2 * l1 * d), -1.0, 1.0)
    a = np.arccos(cos_a)[:, None]
    e1 = shoulder + l1 * (np.cos(a) * u + np.sin(a) * v)
    w1 = shoulder + d[:, None] * u
    up_old, lo_old = e0 - s0, w - e0
    up_new, lo_new = e1 - shoulder, w1 - e1
    m_up = _frames(up_new, lo_new) @ np.swapaxes(_frames(up_old, lo_old), -1, -2)
    m_lo = _frames(lo_new, -up_new) @ np.swapaxes(_frames(lo_old, -up_old), -1, -2)
    world_up = quat.multiply(quat.from_matrix(m_up), r0[:, arm])
    world_lo = quat.multiply(quat.from_matrix(m_lo), r0[:, fore])
    return (
        quat.multiply(quat.conjugate(shoulder_rot), world_up),
        quat.multiply(quat.conjugate(world_up), world_lo),
        quat.multiply(quat.conjugate(world_lo), r0[:, wrist]),
    )


__all__ = ["BodySettings", "DrummerBody"]
