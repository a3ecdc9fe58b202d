"""The drummer's hands from where they are (issue 15, deliverable 3).

The authored hand clips all start and end in one ready pose over the snare;
squeezed into a short lead they sent the wrist 30-50 cm back to the snare and
out again between two ride strokes.  Here a hand's motion is built from its
strokes instead, and the clips give only their impact poses (the grip, the
hand's rotation and the elbow at the impact frame, exact on the instrument):

- **keys**: for each stroke a *backswing* key (the next piece's impact pose
  with the stick raised) ``down`` seconds before the impact and the impact key
  itself; after the impact the stick rebounds to a *hover* over the piece just
  struck and waits there; the hand leaves for the next piece ``move_early``
  times ``distance / move_speed`` before the impact, slower than it must (or at
  once when the time is short); after ``rest_after_s`` without a stroke it goes to the
  relaxed ready pose and comes back in time for the next.  A move the plan
  leaves less time than that goes at even speed between short ramps
  (``_SQUEEZED``), and the stick takes part of it: at the impacts on either side
  the hand and stick are turned about the tip so the wrist sits toward the other
  piece (``reach_*``, :func:`virja.motion.drummer_landing.reached`, also where the
  hands cross);
  a hand over a cymbal (or on the spot of a drum) that the other hand strikes
  next gets out of its way low and sideways (:meth:`DrummerHands._yield`).
- **lift**: velocity sets the stick tip's height above the surface (not a
  scale of joint rotations), ``lift_soft_m`` .. ``lift_loud_m`` by velocity
  (to the power ``lift_curve``; a side-stick at most ``side_stick_m``, a rim
  shot at least ``rim_min_m``) and
  at most ``lift_per_s`` times the time since the previous stroke; the stick
  turns up about the wrist (the wrist itself rises ``wrist_share`` of it), so a
  soft stroke is a low one and nothing dives under a head or a cymbal.
- **profiles**: into an impact the stick accelerates (u^2), out of it it
  decelerates, every other segment eases in and out (smoothstep); the pose
  is interpolated between keys (grip and elbow lerp, hand rotation slerp).
- **crossed at once**: where the two hands strike within ``BEFORE_IMPACT_S`` of each
  other (no detour bends a track there), the louder stroke's hand lands raised over
  the other stick (:func:`virja.motion.drummer_landing.over`), and a squeezed move up
  to a stroke that ends crossed over the other stick gets its height first
  (``_SQUEEZED_OVER``).  A left hand playing a drum under the right stick crossed
  over it onto the hi-hat lands lowered under that stick, lower still by its wrist's
  rise in the backswing, wherever the right strikes while the left is low there
  (:func:`virja.motion.drummer_landing.under`; which strokes count: :meth:`_build`).
- **apart**: the two hands' tracks are sampled together and bent around each
  other and the kit where a stick would go through the other or a tip under a
  piece (:mod:`virja.motion.drummer_clear`, :meth:`DrummerHands._clear`).
- **arm**: each frame the arm is solved by two-bone IK from the fixed shoulder
  to the wrist, the elbow toward the interpolated authored elbow, the hand at
  its world rotation.  At the impact key the pose is the clip's own, so contact
  stays exact.

Everything is vectorised over times; constants in motions/drummer_hands.toml.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from virja.geometry import GEOMETRY, DrumKit
from virja.motion import drummer_clear, drummer_landing, quat
from virja.motion.clip import Clip
from virja.motion.ik import frames
from virja.motion.skeleton import SKELETON, STICK_AXIS_LOCAL, STICK_BUTT_M, STICK_TIP_M
from virja.vocab import CYMBAL_PIECES

_SK = SKELETON
HANDS = ("left_hand", "right_hand")
_SIDE = {"left_hand": "Left", "right_hand": "Right"}
_UP = np.array([0.0, 1.0, 0.0])
_SMOOTH, _ACCEL, _DECEL = 0, 1, 2
_MOVE = 3  # eased like _SMOOTH; the grip's height leads or lags (_height_share)
_RISE_LEAD, _DROP_LAG = 1.5, 2.0  # exponents, see _height_share
# a move off the hi-hat (the low cymbal beside the snare) keeps its height later still: a
# soft side-stick hand leaving the open hi-hat for the snare dipped its tip under the top
# cymbal's edge (MMA Swing1 at 300 bpm, 12 such runs in 12 s); off the high crash and
# ride the longer lag made the drop's end too fast (jumps of 15-17 cm a frame at 30 fps)
_MOVE_OFF_HIHAT, _HIHAT_LAG = 5, 2.5
# a hand hovering over a cymbal that the other hand strikes next (the right hand back on
# the hi-hat, to the crash the left just played) gets out of its way to the ready pose
# as soon as that stroke is known, if it has at least _YIELD_MIN_S before it: sticks
# passed through each other as the hands swapped over a cymbal (GMD rock-prog 190)
_YIELDING = frozenset(CYMBAL_PIECES)
_YIELD_MIN_S = 0.05
_YIELD_AFTER_S = 0.04  # after its own impact: the stick leaves the cymbal at once
# ... low and sideways, not back to the ready pose: the way back crossed the incoming
# stick when the other hand came in 85 ms later (GMD rock-prog 190 at 11.68 s); the grip
# moves this far (m) away from the other stick's strike point, the tip this low over the
# piece, in at most _YIELD_MOVE_S.  On a drum only when the two tips land this near
# (m): hands alternate on the snare each on its own spot, but the right came down on
# the high tom where the left had just struck (rock-prog 190 at 10.43 s)
_YIELD_ASIDE_M, _YIELD_LOW_M, _YIELD_MOVE_S = 0.12, 0.03, 0.15
_YIELD_NEAR_M = 0.12
_YIELD_SHARE = 0.6  # out of the way within this share of the time to the other's impact
# a move the plan squeezes (no time to hover first): constant speed between two short
# ramps of this share each, so the peak speed is 1 / (1 - _RAMP) of the average (1.25;
# smoothstep's is 1.5): the shortest move at bounded speed, not a jump in mid-way
_SQUEEZED, _RAMP = 4, 0.2
# ... but where the plan leaves so little time that those ramps would bring the peak
# near 15 cm a 30 fps frame (average grip speed over 3.4 m/s: 1.25 x 3.4 = 4.25 m/s,
# 14.2 cm a frame, the rest left for the lift and the body's turn), the ramps are
# halved (peak 1.11 x the average): GMD latin 118 at 21.2 s, the left hand tom_low ->
# snare, 35.6 cm of grip in 100 ms along the stick, which the reach cannot shorten
# (a turn about the tip moves the wrist square to the stick): 15.7 -> 14.4 cm a frame
_SQUEEZED_FAST, _RAMP_FAST, _FAST_M_S = 6, 0.1, 3.4
_SQUEEZED_LEAD = 1.1  # its rise leads a little (_height_share), clear of a cymbal's edge
# ... a squeezed move up to a stroke that ends crossed over the other hand's stick (the
# other strikes within drummer_clear.BEFORE_IMPACT_S, its stick under this one where
# they cross seen from above) gets its height first, as the mirror of a move off the
# hi-hat keeping it late (_HIHAT_LAG), then goes across: the right rising from the
# snare straight to the hi-hat swept through the left stick coming down from it to the
# snare (GMD latin 84 at 0.86 s: both strokes 5 ms apart, no detour fits so near them)
_SQUEEZED_OVER, _OVER_LEAD = 7, _HIHAT_LAG
# ... where that keeps the grip's peak speed within a squeezed move's at _FAST_M_S
# (1.25 x 3.4 = 4.25 m/s): the right rising 41 cm from the snare to the crash in 203 ms
# over the left's snare stroke (GMD soul-motown 148 at 6.3 s) jumped 16.6 cm a frame
_OVER_PEAK_M_S = _FAST_M_S / (1.0 - _RAMP)
_SQUEEZED_LAG = 1.0
# a hand re-aims its impact toward the next piece (HandSettings.reach_*) only when that
# stroke is known at least this long before the impact
_REACH_MIN_S = 0.04
# a stroke whose piece lies this far from where the hand is moves the hand toward it
# (DrummerHands.departs); nearer, only the stick's backswing shows it (the hand stays)
_DEPART_M = 0.02
# the left under the right stick crossed over it (DrummerHands._under): right strokes
# from this long before the left's impact (or its last impact, if later) to its next
_UNDER_BEFORE_S = 0.25
# ... and those after its impact when its next backswing lifts the tip at most this (m),
# the hand lowered further by that backswing's wrist rise (wrist_share of it; at most
# reach_max_m in all): a middle stroke (drum method books' full stroke is 30 cm) rises
# under the right stick (GMD funk 112 fill at 2.43 s, rock-prog 125 at 21.0 s, funk
# purdie shuffle 130 fill at 1.16 s); a full one (velocity 121: 28 cm, the wrist 8 cm)
# from over it (:meth:`_over`, New Orleans funk 84 fill)
_UNDER_LIFT_M = 0.2


@dataclass(frozen=True)
class HandSettings:
    """Constants from motions/drummer_hands.toml (reasons given there)."""

    enabled: bool = True
    lift_soft_m: float = 0.03
    lift_loud_m: float = 0.30
    lift_curve: float = 1.5
    lift_per_s: float = 1.6
    side_stick_m: float = 0.03
    rim_min_m: float = 0.2
    hover_m: float = 0.05
    wrist_share: float = 0.3
    down_share: float = 0.3
    down_min_s: float = 0.02
    down_max_s: float = 0.09
    rebound_share: float = 0.3
    rebound_max_s: float = 0.12
    move_speed_m_s: float = 2.0
    move_early: float = 2.0
    rest_after_s: float = 2.0
    rest_move_s: float = 0.5
    reach_speed_m_s: float = 2.5
    reach_max_m: float = 0.12

    @classmethod
    def clips(cls) -> HandSettings:
        """The hands as the clips move them (the time-warped authored strokes)."""
        return cls(enabled=False)

    @classmethod
    def load(cls, path: Path | None = None) -> HandSettings:
        from virja.motion.settings_files import hand_settings
        from virja.resources import motions_file

        found = motions_file("drummer_hands.toml", path)
        return cls() if found is None else hand_settings(found)


@dataclass(frozen=True)
class _Pose:
    """A hand pose in the still body's frame: grip (3,), hand rotation (4,), elbow
    relative to the shoulder (3,)."""

    grip: np.ndarray
    rot: np.ndarray
    elbow: np.ndarray
    piece: str | None = None  # the piece struck in this pose


@dataclass
class _Keys:
    """Two key tracks of one hand: where the hand is (``t``, ``grip``, ``rot``,
    ``elbow``) and how high the stick is raised (``lift_t``, ``lift``); each
    ``*profile`` is the shape of the segment ending at that key."""

    t: np.ndarray  # (K,)
    grip: np.ndarray  # (K, 3)
    rot: np.ndarray  # (K, 4)
    elbow: np.ndarray  # (K, 3)
    profile: np.ndarray  # (K,)
    lift_t: np.ndarray  # (L,)
    lift: np.ndarray  # (L,)
    lift_profile: np.ndarray  # (L,)
    # where each segment would have ended had a later note not cut it short (_cut)
    end_t: np.ndarray  # (K,)
    end_rows: np.ndarray  # (K, 10): grip, rot, elbow
    lift_end_t: np.ndarray  # (L,)
    lift_end: np.ndarray  # (L,)


@dataclass
class _Base:
    """A hand's track frozen up to ``t`` (a frame drawn then): its keys up to there
    (cut at ``t``, :func:`_cut`) and the last stroke landed by then (impact time,
    lift, impact pose row) or None.  Strokes later than ``t`` are built on from it
    (:meth:`DrummerHands._build`), so a change of plan never changes a frame drawn."""

    t: float
    pt: list[float]
    pv: list[np.ndarray]
    pp: list[Any]
    lt: list[float]
    lv: list[float]
    lp: list[Any]
    last: tuple[float, float, np.ndarray, str | None] | None


def _same_until(a: _Keys, b: _Keys, t: float) -> bool:
    """Whether two key tracks give the same poses at every time up to ``t``: the same
    keys up to ``t`` and the same segment across it."""
    tracks = (
        ("t", "grip", "rot", "elbow", "profile", "end_t", "end_rows"),
        ("lift_t", "lift", "lift_profile", "lift_end_t", "lift_end"),
    )
    for names in tracks:
        ta, tb = getattr(a, names[0]), getattr(b, names[0])
        n = int(np.searchsorted(ta, t, side="right"))
        if n != int(np.searchsorted(tb, t, side="right")):
            return False
        for name in names:
            x, y = getattr(a, name)[: n + 1], getattr(b, name)[: n + 1]
            if x.shape != y.shape or not np.array_equal(x, y):
                return False
    return True


def _shaped(
    keys_t: np.ndarray, profile: np.ndarray, t: np.ndarray, end_t: np.ndarray | None = None
) -> tuple[np.ndarray, ...]:
    """(i0, i1, u): the segment of each time and the shaped fraction along it.

    ``end_t``: where each segment would have ended had it not been cut short (a key
    put where a later note changed the course): the part before the cut keeps its
    original curve, so what was drawn before stays exactly as it was."""
    n = keys_t.size
    if end_t is None:
        end_t = keys_t
    i1 = np.clip(np.searchsorted(keys_t, t, side="right"), 1, max(n - 1, 1))
    i0 = i1 - 1
    if n == 1:
        return np.zeros_like(i0), np.zeros_like(i0), np.zeros(t.shape)
    span = end_t[i1] - keys_t[i0]
    ok = span > 1e-12
    u = np.where(ok, np.clip((t - keys_t[i0]) / np.where(ok, span, 1.0), 0.0, 1.0), 1.0)
    u = np.where(t < keys_t[0], 0.0, u)
    prof = profile[i1]
    u = np.where(
        prof == _ACCEL,
        u * u,
        np.where(
            prof == _DECEL,
            1.0 - (1.0 - u) ** 2,
            np.where(
                (prof == _SQUEEZED) | (prof == _SQUEEZED_OVER),
                _ramped(u),
                np.where(prof == _SQUEEZED_FAST, _ramped(u, _RAMP_FAST), u * u * (3 - 2 * u)),
            ),
        ),
    )
    return i0, i1, u


def _ramped(u: np.ndarray, ramp: float = _RAMP) -> np.ndarray:
    """The fraction along a :data:`_SQUEEZED` move: ramps of ``ramp`` at either end at
    constant acceleration, constant speed ``1 / (1 - ramp)`` between (continuous
    speed, no step in position)."""
    v = 1.0 / (1.0 - ramp)
    return np.where(
        u < ramp,
        0.5 * v * u * u / ramp,
        np.where(u > 1.0 - ramp, 1.0 - 0.5 * v * (1.0 - u) ** 2 / ramp, v * (u - 0.5 * ramp)),
    )


def _squeezed(way_m: float, span_s: float) -> int:
    """The profile of a move of ``way_m`` (grip) squeezed into ``span_s``:
    :data:`_SQUEEZED_FAST` over ``_FAST_M_S`` on average, else :data:`_SQUEEZED`."""
    return _SQUEEZED_FAST if way_m > _FAST_M_S * max(span_s, 1e-9) else _SQUEEZED


def _over_peak_m_s(a: np.ndarray, b: np.ndarray, span_s: float) -> float:
    """The grip's peak speed (m/s) on a :data:`_SQUEEZED_OVER` move from ``a`` up to ``b``
    (grip positions) in ``span_s``."""
    u = _ramped(np.linspace(0.0, 1.0, 201))
    h = _height_share(u, np.full(u.shape, b[1] - a[1]), np.full(u.shape, _SQUEEZED_OVER))
    path = a + u[:, None] * (b - a)
    path[:, 1] = a[1] + h * (b[1] - a[1])
    step = np.linalg.norm(np.diff(path, axis=0), axis=1)
    return float(step.max() * 200 / max(span_s, 1e-9))


def _shape(u: float, profile: int) -> float:
    if profile == _ACCEL:
        return u * u
    if profile == _DECEL:
        return 1.0 - (1.0 - u) ** 2
    if profile in (_SQUEEZED, _SQUEEZED_OVER):
        return float(_ramped(np.asarray(u)))
    if profile == _SQUEEZED_FAST:
        return float(_ramped(np.asarray(u), _RAMP_FAST))
    return u * u * (3 - 2 * u)


def _height_share(u: np.ndarray, rise: np.ndarray, profile: np.ndarray) -> np.ndarray:
    """How far along its move the grip's height is at shaped fraction ``u``: a hand going
    down stays up until late (off a cymbal over its edge, not under it); on a move
    given its full time (:data:`_MOVE`) a hand going up also rises first, on a
    squeezed one (:data:`_SQUEEZED`, already at its bounded speed) a little first, one
    that ends crossed over the other stick (:data:`_SQUEEZED_OVER`) first; all start
    and end at rest."""
    moving = (profile == _MOVE) | (profile == _MOVE_OFF_HIHAT)
    over = profile == _SQUEEZED_OVER
    squeezed = (profile == _SQUEEZED) | (profile == _SQUEEZED_FAST) | over
    lead = np.where(
        moving,
        1.0 - (1.0 - u) ** _RISE_LEAD,
        np.where(
            over,
            1.0 - (1.0 - u) ** _OVER_LEAD,
            np.where(squeezed, 1.0 - (1.0 - u) ** _SQUEEZED_LEAD, u),
        ),
    )
    lag = np.where(
        profile == _MOVE_OFF_HIHAT,
        u**_HIHAT_LAG,
        np.where(squeezed, u**_SQUEEZED_LAG, u**_DROP_LAG),
    )
    return np.where(rise > 0, lead, lag)


def _pose_at(a: np.ndarray, b: np.ndarray, u: float, shape: int) -> np.ndarray:
    """(grip, rot, elbow) rows ``a`` -> ``b`` at shaped fraction ``u`` of a ``shape`` segment."""
    out = a + u * (b - a)
    dy = np.asarray(b[1] - a[1])
    out[1] = a[1] + float(_height_share(np.asarray(u), dy, np.asarray(shape))) * dy
    out[3:7] = quat.slerp(a[3:7], b[3:7], u)
    return out


def _lift_at(a: float, b: float, u: float, shape: int) -> float:
    return a + u * (b - a)


def _add(
    times: list[float], values: list[Any], profiles: list[Any], t: float, v: Any, p: Any
) -> None:
    times.append(t)
    values.append(v)
    profiles.append(p)


def _segment(profile: Any, t: float, value: Any) -> tuple[int, float, Any]:
    """(shape, end time, end value) of the segment ending at a key: its own unless the
    key cut a segment short (then the tuple stored by :func:`_cut`)."""
    return profile if isinstance(profile, tuple) else (profile, t, value)


def _cut(times: list[float], values: list[Any], profiles: list[Any], cut: float, at: Any) -> Any:
    """The track's value at ``cut``; keys after ``cut`` are dropped and, unless one lies
    exactly there, a key holding that value is put at ``cut`` that remembers the cut
    segment's own end, so the track up to ``cut`` is unchanged."""
    k = bisect.bisect_right(times, cut)
    prof: Any = _SMOOTH
    if k == 0:
        value = values[0]
    elif k == len(times):
        value = values[-1]
    else:
        shape, end_t, end_v = _segment(profiles[k], times[k], values[k])
        span = end_t - times[k - 1]
        u = 1.0 if span <= 1e-12 else _shape((cut - times[k - 1]) / span, shape)
        value = at(values[k - 1], end_v, u, shape)
        prof = (shape, end_t, end_v)
    del times[k:], values[k:], profiles[k:]
    if not times or times[-1] < cut:
        _add(times, values, profiles, cut, value, prof)
    return value


class DrummerHands:
    """The strokes of the drummer's two hands and the arm poses made from them."""

    def __init__(
        self,
        root: np.ndarray,
        idle_local: np.ndarray,
        settings: HandSettings | None = None,
        kit: DrumKit = GEOMETRY.kit,
    ) -> None:
        self.settings = settings or HandSettings.load()
        self._kit = kit
        self._root = np.asarray(root, dtype=np.float64)
        self._idle = np.asarray(idle_local, dtype=np.float64)
        p, r = _SK.fk(self._idle, self._root)
        self._shoulder = {h: p[_SK.index(f"{_SIDE[h]}Arm")] for h in HANDS}
        self._shoulder_rot = {h: r[_SK.index(f"{_SIDE[h]}Shoulder")] for h in HANDS}
        self._joints = {
            h: np.array(
                [_SK.index(f"{_SIDE[h]}{j}") for j in ("Shoulder", "Arm", "ForeArm", "Hand")]
            )
            for h in HANDS
        }
        self._l1 = {
            h: float(np.linalg.norm(_SK.offsets[_SK.index(f"{_SIDE[h]}ForeArm")])) for h in HANDS
        }
        self._l2 = {
            h: float(np.linalg.norm(_SK.offsets[_SK.index(f"{_SIDE[h]}Hand")])) for h in HANDS
        }
        self._grip_off = {h: _SK.offsets[_SK.index(f"{_SIDE[h]}HandEnd")] for h in HANDS}
        self._arm = {
            h: drummer_landing.Arm(self._shoulder[h], self._l1[h], self._l2[h], self._grip_off[h])
            for h in HANDS
        }
        self._times: dict[str, list[float]] = {h: [] for h in HANDS}
        # per stroke: (start, impact pose, velocity, articulation)
        self._strokes: dict[str, list[tuple[float, _Pose, int, str | None]]] = {
            h: [] for h in HANDS
        }
        self._rest: dict[str, _Pose | None] = dict.fromkeys(HANDS)
        self._ref: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None] = (
            dict.fromkeys(HANDS)
        )
        self._poses: dict[tuple[str, int], _Pose] = {}
        self._keys: dict[str, _Keys | None] = dict.fromkeys(HANDS)
        # per stroke, beside _strokes: the key it was added under (remove_stroke) or None
        self._ids: dict[str, list[object]] = {h: [] for h in HANDS}
        # the track frozen up to a frame drawn (_Base), and the last build's key lists
        # and strokes landed (what a freeze cuts)
        self._base: dict[str, _Base | None] = dict.fromkeys(HANDS)
        self._lists: dict[str, tuple[Any, ...] | None] = dict.fromkeys(HANDS)
        # the two tracks kept apart (virja.motion.drummer_clear): each hand's detours,
        # the key tracks they were found on, and the last frame drawn (never changed)
        self._detours: dict[str, list[drummer_clear.Detour]] = {h: [] for h in HANDS}
        self._lifts: dict[str, list[drummer_clear.Detour]] = {h: [] for h in HANDS}
        self._detour_src: tuple[_Keys | None, ...] | None = None
        self._drawn = -math.inf
        # per stroke added under a key, from the last build: when the hand's track first
        # moves for it (:meth:`departs`)
        self._departs: dict[str, dict[object, float]] = {h: {} for h in HANDS}

    @property
    def enabled(self) -> bool:
        return self.settings.enabled

    def has_strokes(self, hand: str) -> bool:
        return bool(self._times.get(hand)) or self._base.get(hand) is not None

    # ------------------------------------------------------------------ input

    def _clip_pose(self, clip: Clip, frame: int) -> _Pose:
        key = (clip.name, frame)
        got = self._poses.get(key)
        if got is not None:
            return got
        hand = clip.limb or ""
        side = _SIDE[hand]
        loc = self._idle.copy()
        ji = [_SK.index(j) for j in clip.joints]
        loc[ji] = clip.rotations[frame, ji]
        p, r = _SK.fk(loc, self._root)
        pose = _Pose(
            p[_SK.index(f"{side}HandEnd")].copy(),
            r[_SK.index(f"{side}Hand")].copy(),
            p[_SK.index(f"{side}ForeArm")] - self._shoulder[hand],
            clip.piece,
        )
        self._poses[key] = pose
        if self._ref[hand] is None:  # the arm's reference frames for the IK (the ready pose)
            a, f, w = (_SK.index(f"{side}{j}") for j in ("Arm", "ForeArm", "Hand"))
            self._ref[hand] = (p[f] - p[a], p[w] - p[f], r[a].copy(), r[f].copy())
        return pose

    def add_stroke(
        self,
        hand: str,
        start: float,
        impact: float,
        clip: Clip,
        velocity: int,
        articulation: str | None = None,
        *,
        key: object = None,
        drawn: float = -math.inf,
    ) -> None:
        """Record a stroke of ``hand`` landing at ``impact`` as ``clip``'s impact frame.

        ``start`` is the earliest time the hand may change course for it: when the note
        became known and nothing later was drawn yet (:meth:`BandAnimator.add_planned`
        gives that), so what was drawn before stays true; the hand also waits for its
        previous impact.  ``articulation`` from the kit map: a side-stick lifts
        little, a rim shot fully.  ``key``: a stroke that may be taken back
        (:meth:`remove_stroke`); ``drawn``: the last frame shown, which the new stroke
        must not change (strokes are built on from there if it would, :meth:`_change`).
        """
        if hand not in self._times:
            return
        if self._rest[hand] is None:
            self._rest[hand] = self._clip_pose(clip, 0)
        pose = self._clip_pose(clip, int(round(clip.impact_s * clip.fps)))

        def insert() -> None:
            i = bisect.bisect_right(self._times[hand], impact)
            self._times[hand].insert(i, impact)
            self._strokes[hand].insert(i, (min(start, impact), pose, int(velocity), articulation))
            self._ids[hand].insert(i, key)

        self._change(hand, drawn, insert)

    def remove_stroke(self, hand: str, key: object, drawn: float = -math.inf) -> bool:
        """Take back the stroke added under ``key`` (a provisional hand the plan revised):
        the frames up to ``drawn`` stay as they were, from there the hand goes on from
        where it is.  False when ``hand`` has no such stroke."""
        ids = self._ids.get(hand)
        if ids is None or key not in ids:
            return False
        i = ids.index(key)

        def delete() -> None:
            del self._times[hand][i], self._strokes[hand][i], self._ids[hand][i]

        self._change(hand, drawn, delete)
        return True

    def keep_stroke(self, hand: str, key: object) -> None:
        """The stroke added under ``key`` is no longer provisional: it stays as it is."""
        ids = self._ids.get(hand)
        if ids is not None and key in ids:
            ids[ids.index(key)] = None

    def _change(self, hand: str, drawn: float, apply: Callable[[], None]) -> None:
        """``apply`` a change of ``hand``'s strokes without changing either hand's track
        at or before ``drawn`` (the other hand may get out of a stroke's way,
        :meth:`_yield`): if a rebuilt track differs there, the old one is frozen up to
        ``drawn`` (:class:`_Base`) and the strokes after it built on from it."""
        live = drawn > -math.inf
        if live:  # the frames drawn so far were drawn with the detours of the tracks then
            self._clear()
        self._drawn = max(self._drawn, drawn)
        olds = {h: (self.keys(h) if live else None, self._lists[h]) for h in HANDS}
        apply()
        for h in HANDS:
            self._keys[h] = None
        for h in HANDS:
            old, old_lists = olds[h]
            if old is None or old_lists is None:
                continue
            new = self.keys(h)
            if new is not None and _same_until(old, new, drawn):
                continue
            self._freeze(h, drawn, old_lists)
            self._keys[h] = None

    def _freeze(self, hand: str, t: float, lists: tuple[Any, ...]) -> None:
        """Freeze ``hand``'s track (the build that gave ``lists``) up to ``t``."""
        pt, pv, pp, lt, lv, lp, landed = (list(x) for x in lists)
        _cut(pt, pv, pp, t, _pose_at)
        _cut(lt, lv, lp, t, _lift_at)
        done = [x for x in landed if x[0] <= t]
        self._base[hand] = _Base(t, pt, pv, pp, lt, lv, lp, done[-1] if done else None)

    def forget_before(self, time_s: float) -> None:
        horizon = time_s - 10.0
        for h in HANDS:
            k = max(bisect.bisect_left(self._times[h], horizon) - 1, 0)
            if k:
                del self._times[h][:k]
                del self._strokes[h][:k]
                del self._ids[h][:k]
                self._keys[h] = None
            self._detours[h] = [d for d in self._detours[h] if d.t3 >= horizon]
            self._lifts[h] = [d for d in self._lifts[h] if d.t3 >= horizon]
            base = self._base[h]
            if base is not None:  # keys long past: the last before the horizon is enough
                k = max(bisect.bisect_right(base.pt, horizon) - 1, 0)
                j = max(bisect.bisect_right(base.lt, horizon) - 1, 0)
                if k or j:
                    del base.pt[:k], base.pv[:k], base.pp[:k]
                    del base.lt[:j], base.lv[:j], base.lp[:j]
                    self._keys[h] = None

    # ------------------------------------------------------------------ keys

    def _lift_for(self, velocity: int, gap: float, articulation: str | None) -> float:
        s = self.settings
        v = (min(max(velocity, 0), 127) / 127) ** s.lift_curve
        by_vel = s.lift_soft_m + (s.lift_loud_m - s.lift_soft_m) * v
        if articulation == "side_stick":  # the butt clicks on the rim: a short tilt
            by_vel = min(by_vel, s.side_stick_m)
        elif articulation == "rim":  # a rim shot is an accent: a full stroke
            by_vel = max(by_vel, s.rim_min_m)
        return float(min(by_vel, s.lift_per_s * gap))

    def _yield(
        self, hand: str, t: float, piece: str | None, next_t: float, row: np.ndarray
    ) -> tuple[float, float, tuple[np.ndarray, np.ndarray]] | None:
        """(when ``hand`` starts to get out of the way, the other hand's impact, the other
        stick's tip and grip there) when the other hand strikes the piece ``hand`` struck at
        ``t`` (in pose ``row``) before ``hand`` strikes again at ``next_t``: any cymbal,
        a drum when the two tips land within ``_YIELD_NEAR_M``; from when that stroke
        is known, after the rebound."""
        if piece is None:
            return None
        other = HANDS[1 - HANDS.index(hand)]
        times = self._times[other]
        for j in range(bisect.bisect_right(times, t), len(times)):
            t_o = times[j]
            if t_o >= next_t:
                return None
            start_o, pose_o, _v, _a = self._strokes[other][j]
            if pose_o.piece != piece:
                continue
            tip_o = drummer_landing.tip(np.concatenate([pose_o.grip, pose_o.rot]))
            if (
                piece not in _YIELDING
                and np.linalg.norm(tip_o - drummer_landing.tip(row)) > _YIELD_NEAR_M
            ):
                return None  # alternating on a drum, each on its own spot
            cut = max(start_o, t + _YIELD_AFTER_S)
            if cut >= t + 0.5 * self.settings.rest_after_s:
                return None  # going to rest anyway
            # no time to get out of the way: stay rather than cross the incoming stick
            out = (cut, t_o, (tip_o, pose_o.grip))
            return out if t_o - cut >= _YIELD_MIN_S else None
        return None

    def _others(
        self, hand: str, lo: float, hi: float, *, up_to: bool = True
    ) -> list[tuple[np.ndarray, int, str | None]]:
        """The other hand's strokes with impacts from ``lo`` to ``hi`` (``hi`` itself
        only ``up_to``): (impact row of grip and rotation, velocity, articulation)."""
        other = HANDS[1 - HANDS.index(hand)]
        times = self._times[other]
        end = (bisect.bisect_right if up_to else bisect.bisect_left)(times, hi)
        return [
            (np.concatenate([pose.grip, pose.rot]), vel, art)
            for _s, pose, vel, art in self._strokes[other][bisect.bisect_left(times, lo) : end]
        ]

    def _over(self, hand: str, t: float, row: np.ndarray) -> np.ndarray:
        """``row`` (the impact pose of ``hand``'s stroke at ``t``) raised over the other
        stick where the other hand strikes within ``drummer_clear.BEFORE_IMPACT_S`` with
        the sticks crossed (:func:`drummer_landing.over`)."""
        near = drummer_clear.BEFORE_IMPACT_S
        _start, _pose, vel, art = self._strokes[hand][bisect.bisect_left(self._times[hand], t)]
        others = [
            (r, self._lift_for(v, math.inf, a))
            for r, v, a in self._others(hand, t - near, t + near)
        ]
        lift = self._lift_for(vel, math.inf, art)
        arm = self._arm[hand]
        return drummer_landing.over(
            arm, row, lift, others, hand == HANDS[1], self.settings.reach_max_m
        )

    def _waits(self, gap: float) -> bool:
        """Whether a hand whose next stroke comes ``gap`` s after its last hovers in
        between (as :meth:`_build` times the rebound, the rise and the downstroke), or
        rebounds straight into the next backswing."""
        s = self.settings
        down = min(max(s.down_share * gap, s.down_min_s), s.down_max_s, 0.5 * gap)
        rise = min(2 * down + 0.05, 0.5 * gap)
        return gap - down - rise > min(s.rebound_max_s, s.rebound_share * gap) + 1e-4

    def _under(
        self, hand: str, span: tuple[float, float], row: np.ndarray, lift: float
    ) -> np.ndarray:
        """``row`` (the impact pose of a left-hand stroke) lowered under the right stick
        crossed over it (:func:`drummer_landing.under`) where the right strikes within
        ``span`` (:meth:`_build` says which: while the left is low there)."""
        if hand != HANDS[0]:
            return row
        others = [r for r, _v, _a in self._others(hand, span[0], span[1], up_to=False)]
        s = self.settings
        extra = s.wrist_share * lift  # the wrist's own rise in the backswing
        return drummer_landing.under(self._arm[hand], row, others, s.reach_max_m, extra)

    def _low(self, hand: str, span: tuple[float, float], row: np.ndarray) -> bool:
        """Whether the right stick crosses over ``row`` (a left-hand impact pose) at a
        right stroke within ``span`` (:func:`drummer_landing.crossing`)."""
        if hand != HANDS[0]:
            return False
        others = [r for r, _v, _a in self._others(hand, span[0], span[1], up_to=False)]
        return bool(drummer_landing.crossing(row, others))

    def _crosses_over(self, hand: str, t: float, row: np.ndarray) -> bool:
        """Whether ``hand``'s stick at its impact at ``t`` (pose ``row``) lies over the
        other hand's stick, crossed seen from above (under ``STICK_CLEAR_M``), at an
        impact of the other within ``drummer_clear.BEFORE_IMPACT_S``."""
        near = drummer_clear.BEFORE_IMPACT_S
        others = [r for r, _v, _a in self._others(hand, t - near, t + near)]
        return drummer_landing.crosses_over(row, others)

    def _reached(
        self, hand: str, row: np.ndarray, here: np.ndarray, span: float, share: float
    ) -> np.ndarray:
        """``row`` reaching toward ``here`` (:func:`drummer_landing.reached`)."""
        s = self.settings
        return drummer_landing.reached(
            self._arm[hand], row, here, span, share, s.reach_speed_m_s, s.reach_max_m
        )

    def _build(self, hand: str) -> _Keys:
        """The key tracks of ``hand``: after each stroke its tail (rebound, hover, rest
        if nothing follows), cut where the next stroke becomes known (its start, never
        before the last impact) and continued from the state there to the next impact."""
        s = self.settings
        rest = self._rest[hand]
        assert rest is not None
        pt: list[float] = []  # pose keys: times, (grip, rot, elbow) rows, profiles
        pv: list[np.ndarray] = []
        pp: list[Any] = []
        lt: list[float] = []  # lift keys
        lv: list[float] = []
        lp: list[Any] = []
        prev_t: float | None = None
        prev_lift = 0.0
        # (impact, lift, pose row, piece)
        landed: list[tuple[float, float, np.ndarray, str | None]] = []
        base = self._base[hand]
        floor = -math.inf
        prev_piece: str | None = None
        times = self._times[hand]
        home = np.concatenate([rest.grip, rest.rot, rest.elbow])

        def get_out_of_the_way(t: float, piece: str | None, nxt: float, row: np.ndarray) -> None:
            """After the stroke at ``t`` on ``piece`` (pose ``row``), low and sideways,
            square to the other stick at its impact, to this hand's side of it, if the other hand strikes there before
            ``nxt`` (:meth:`_yield`)."""
            yielding = self._yield(hand, t, piece, nxt, row)
            # the time left from where the track is frozen (live) counts, as in _yield: a
            # hand frozen 23 ms before the other's impact stepped 12 cm aside in 12 ms
            # (as live, GMD merengue 162 at 6.8 s: 12.5 m/s, after a revised stroke)
            if yielding is None or yielding[1] - max(yielding[0], floor) < _YIELD_MIN_S:
                return
            at, t_o, (tip_o, grip_o) = max(yielding[0], floor), yielding[1], yielding[2]
            here = _cut(pt, pv, pp, at, _pose_at)  # never before what is frozen
            _cut(lt, lv, lp, at, _lift_at)
            # square to the incoming stick, to the side of it where this hand's wrist is
            way = grip_o - tip_o
            side = np.cross(way, _UP)
            side[1] = 0.0
            if float(np.linalg.norm(side)) < 1e-6:
                side = self._shoulder[hand] - self._shoulder[HANDS[1 - HANDS.index(hand)]]
                side[1] = 0.0
            side = side / float(np.linalg.norm(side))
            if float(side @ (self._arm[hand].wrist(here) - tip_o)) < 0.0:
                side = -side
            # aside of the stroke's own spot (where the hand waits after it), not of where
            # it is: a track frozen live after the hand got out of the way is built on
            # from there and met this again (as live, the hand stepped a second 12 cm
            # aside in 5 ms: 14.4 m/s, MMA jazzcombo at 240 bpm at 3.0 s)
            aside = here.copy()
            aside[:3] = row[:3] + _YIELD_ASIDE_M * side
            clear = at + min(_YIELD_MOVE_S, _YIELD_SHARE * (t_o - at))
            _add(pt, pv, pp, clear, aside, _SQUEEZED)
            _add(lt, lv, lp, clear, min(s.hover_m, _YIELD_LOW_M), _SMOOTH)

        if base is not None:  # frozen up to a frame drawn: build on from there
            floor = base.t
            pt, pv, pp = list(base.pt), list(base.pv), list(base.pp)
            lt, lv, lp = list(base.lt), list(base.lv), list(base.lp)
            self._settle(hand, base, pt, pv, pp, lt, lv, lp)
            if base.last is not None:
                landed.append(base.last)
                prev_t, prev_lift, prev_piece = base.last[0], base.last[1], base.last[3]
                nxt = next((u for u in times if u > floor), math.inf)
                get_out_of_the_way(prev_t, prev_piece, nxt, base.last[2])
        strokes = self._strokes[hand]
        ids = self._ids[hand]
        departs: dict[object, float] = {}
        aimed: dict[int, float] = {}  # a stroke toward which the one before was aimed, from
        for i, (t, (start, pose, vel, art)) in enumerate(zip(times, strokes, strict=True)):
            if t <= floor or (prev_t is not None and t - prev_t < 1e-6):
                continue  # two notes struck at once by one hand: one stroke
            row = np.concatenate([pose.grip, pose.rot, pose.elbow])
            nxt_t = next((u for u in times[i + 1 :] if u - t >= 1e-6), math.inf)
            since = t - _UNDER_BEFORE_S if prev_t is None else max(prev_t, t - _UNDER_BEFORE_S)
            until = min(nxt_t, t + 0.5 * s.rest_after_s)  # then it rests
            # the left goes under the right stick crossed over it where the right strikes
            # while the left is low there: from its last impact (or _UNDER_BEFORE_S before
            # this one) to its next where it waits (hovers before the next backswing) or
            # that backswing is low (at most _UNDER_LIFT_M); else up to its impact (the
            # rebound goes on into a high backswing: GMD merengue 130 at 18.0 s, the left
            # coming up from the snare to the high tom 100 ms after the right struck the
            # hi-hat; a loud stroke right after the right's rises from over its stick,
            # :meth:`_over`, New Orleans funk 84 fill)
            end = until
            lift_in = self._lift_for(vel, math.inf if prev_t is None else t - prev_t, art)
            # a left whose backswing into this stroke comes up under the right stick
            # crossed over it (a right stroke since its last) lifts at most a middle
            # stroke: lowered under it at the impact, a full one's tip half still rose
            # through it (GMD hip-hop 140 fill at 2.45 s: 29 cm of tip, 108 ms before
            # the left's high tom and inside the right's guard, where no detour of the
            # left alone kept the sticks apart)
            low = self._low(hand, (since, t), row)
            if low:
                lift_in = min(lift_in, _UNDER_LIFT_M)
            lift_on = 0.0  # the next backswing's, where the right strokes after it count
            if nxt_t < math.inf and not self._waits(nxt_t - t):
                n = next(k for k in range(i + 1, len(times)) if times[k] - t >= 1e-6)
                _s, _p, vel_n, art_n = strokes[n]
                lift_on = self._lift_for(vel_n, nxt_t - t, art_n)
                if lift_on > _UNDER_LIFT_M:
                    end, lift_on = t, 0.0
            target = self._under(hand, (since, end), row, max(lift_in, lift_on))
            if target is row:
                target = self._over(hand, t, row)
            if base is not None:
                start = max(start, floor)
            if prev_t is None and base is None:
                cut, gap = start, math.inf
                here = np.concatenate([rest.grip, rest.rot, rest.elbow])
                pt, pv, pp = [cut], [here], [_SMOOTH]
                lt, lv, lp = [cut], [0.0], [_SMOOTH]
                lift_here = 0.0
            else:
                cut = start if prev_t is None else max(start, prev_t)
                gap = math.inf if prev_t is None else t - prev_t
                here = _cut(pt, pv, pp, cut, _pose_at)
                lift_here = float(_cut(lt, lv, lp, cut, _lift_at))
            room = t - cut
            # the backswing fits the time the hand has: since its last stroke, or since
            # it learnt of this one when that is later (a hand the plan gives a note at
            # the motion's start, live, has the lead from where it is, not the gap)
            lift = self._lift_for(vel, min(gap, room), art)
            if low:
                lift = min(lift, _UNDER_LIFT_M)
            # a far move with little time: the stick takes part of it (_reached); at this
            # impact the wrist still sits toward where it comes from ...
            target = self._reached(hand, target, here, room, 1.0)
            # ... and already toward the next piece, when that stroke is known in time
            # and its move will be short of time too: from the start when it is known
            # before this move begins, else re-aimed from when it is known
            j = next((k for k in range(i + 1, len(times)) if times[k] - t >= 1e-6), None)
            reached = target
            if j is not None and strokes[j][0] < t - _REACH_MIN_S:
                nxt_pose = strokes[j][1]
                nxt_row = np.concatenate([nxt_pose.grip, nxt_pose.rot, nxt_pose.elbow])
                reached = self._reached(hand, target, nxt_row, times[j] - t, 0.5)
                if reached is not target and ids[j] is not None:
                    aimed[j] = max(strokes[j][0], cut)
            down = min(max(s.down_share * gap, s.down_min_s), s.down_max_s, 0.5 * gap)
            down = min(down, 0.5 * room) if room > 0 else 0.0
            rise = min(2 * down + 0.05, 0.5 * gap)
            way = max(np.linalg.norm(target[:3] - here[:3]), np.linalg.norm(reached[:3] - here[:3]))
            travel = float(way) / s.move_speed_m_s
            if prev_t is None and base is None:
                travel = max(travel, s.rest_move_s)
            leave = t - travel  # hover where the hand is; leave only when the move must start
            if leave > cut + 1e-4:  # ... or a little before: a slower move, when there is time
                leave = max(t - s.move_early * travel, cut + 1e-4)
            if j is not None and strokes[j][0] <= max(leave, cut):
                target = reached  # known before the hand leaves: the whole way to it
            if leave > cut + 1e-4:
                _add(pt, pv, pp, leave, here, _SMOOTH)
                # time enough: over the cymbals' edges
                off_hihat = prev_piece == "hihat"
                _add(pt, pv, pp, t, target, _MOVE_OFF_HIHAT if off_hihat else _MOVE)
            else:  # squeezed by the plan: the straight, shortest way at even speed
                shape = _squeezed(float(way), t - cut)
                if (
                    shape == _SQUEEZED
                    and target[1] > here[1]
                    and _over_peak_m_s(here[:3], target[:3], t - cut) <= _OVER_PEAK_M_S
                    and self._crosses_over(hand, t, target)
                ):
                    shape = _SQUEEZED_OVER
                _add(pt, pv, pp, t, target, shape)
            if reached is not target:  # known on the way: re-aimed from then
                assert j is not None
                _cut(pt, pv, pp, strokes[j][0], _pose_at)
                _add(pt, pv, pp, t, reached, _SQUEEZED)
                target = reached
            rebound = -math.inf  # when the last stroke's rebound is over
            if prev_t is not None:
                rebound = prev_t + min(s.rebound_max_s, s.rebound_share * gap)
            if cut < rebound - 1e-4:  # known before the last stroke's rebound is over
                if t - down - rise > rebound + 1e-4:
                    # time to spare: the rebound goes on to a hover, then the rise
                    _add(lt, lv, lp, rebound, min(s.hover_m, lift, prev_lift), _DECEL)
                    _add(lt, lv, lp, t - down - rise, lv[-1], _SMOOTH)
                    _add(lt, lv, lp, t - down, lift, _SMOOTH)
                else:  # the stick rebounds straight into the backswing
                    _add(lt, lv, lp, t - down, lift, _DECEL)
            else:
                if t - down - rise > cut + 1e-4:
                    _add(lt, lv, lp, t - down - rise, lift_here, _SMOOTH)
                _add(lt, lv, lp, t - down, lift, _SMOOTH)
            _add(lt, lv, lp, t, 0.0, _ACCEL)
            if ids[i] is not None:  # when the hand first moves toward it (departs)
                moves = (leave if leave > cut + 1e-4 else cut) if way >= _DEPART_M else math.inf
                first = min(moves, aimed.get(i, math.inf))
                if first < math.inf:
                    departs[ids[i]] = first
            # the tail, as if no stroke followed: rebound to a hover, rest after a while
            hover = min(s.hover_m, lift, prev_lift if prev_t is not None else lift)
            away = t + 0.5 * s.rest_after_s
            _add(lt, lv, lp, t + s.rebound_max_s, hover, _DECEL)
            _add(lt, lv, lp, away, hover, _SMOOTH)
            _add(lt, lv, lp, away + s.rest_move_s, 0.0, _SMOOTH)
            _add(pt, pv, pp, away, target, _SMOOTH)
            home = np.concatenate([rest.grip, rest.rot, rest.elbow])
            _add(pt, pv, pp, away + s.rest_move_s, home, _MOVE)
            nxt = next((u for u in times[i + 1 :] if u - t >= 1e-6), math.inf)
            get_out_of_the_way(t, pose.piece, nxt, target)
            prev_t, prev_lift, prev_piece = t, lift, pose.piece
            landed.append((t, lift, target, pose.piece))
        self._lists[hand] = (pt, pv, pp, lt, lv, lp, landed)
        self._departs[hand] = departs
        rows = np.array(pv)
        seg = [_segment(*k) for k in zip(pp, pt, pv, strict=True)]
        lseg = [_segment(*k) for k in zip(lp, lt, lv, strict=True)]
        return _Keys(
            np.array(pt),
            rows[:, :3],
            rows[:, 3:7],
            rows[:, 7:],
            np.array([g[0] for g in seg], dtype=np.int64),
            np.array(lt),
            np.array(lv),
            np.array([g[0] for g in lseg], dtype=np.int64),
            np.array([g[1] for g in seg]),
            np.array([g[2] for g in seg]),
            np.array([g[1] for g in lseg]),
            np.array([g[2] for g in lseg], dtype=np.float64),
        )

    def _settle(
        self,
        hand: str,
        base: _Base,
        pt: list[float],
        pv: list[np.ndarray],
        pp: list[Any],
        lt: list[float],
        lv: list[float],
        lp: list[Any],
    ) -> None:
        """After a frozen track (a stroke taken back), the hand goes from where it is
        back over the piece it last played, at a hover (or to the ready pose when it
        played nothing yet), and rests after a while as after any stroke."""
        s = self.settings
        rest = self._rest[hand]
        assert rest is not None
        home = np.concatenate([rest.grip, rest.rot, rest.elbow])
        here = pv[-1]
        target = home if base.last is None else base.last[2]
        travel = float(np.linalg.norm(target[:3] - here[:3])) / s.move_speed_m_s
        back = base.t + max(travel, s.down_max_s)
        _add(pt, pv, pp, back, target, _MOVE)
        if base.last is None:
            _add(lt, lv, lp, back, 0.0, _SMOOTH)
            return
        hover = min(s.hover_m, base.last[1])
        _add(lt, lv, lp, back, hover, _SMOOTH)
        away = max(base.last[0] + 0.5 * s.rest_after_s, back + 1e-3)
        _add(lt, lv, lp, away, hover, _SMOOTH)
        _add(lt, lv, lp, away + s.rest_move_s, 0.0, _SMOOTH)
        _add(pt, pv, pp, away, target, _SMOOTH)
        _add(pt, pv, pp, away + s.rest_move_s, home, _MOVE)

    def departs(self, hand: str, key: object) -> float | None:
        """When ``hand`` first moves toward the piece of the stroke added under ``key``:
        its move there begins (a piece at least _DEPART_M from where the hand is), or the
        stroke before it is aimed toward it (the stick's reach).  None when ``hand`` has no
        such stroke, or it moves only the stick (a stroke where the hand is: a backswing,
        which a plan giving the note to the other hand only lowers again).  A frame drawn
        at or after it has shown the hand on its way to that stroke."""
        if key not in self._ids.get(hand, ()):
            return None
        self.keys(hand)
        return self._departs[hand].get(key)

    def keys(self, hand: str) -> _Keys | None:
        if not self._times[hand] and self._base[hand] is None:
            return None
        k = self._keys[hand]
        if k is None:
            k = self._keys[hand] = self._build(hand)
        return k

    # ------------------------------------------------------------------ output

    def targets(self, hand: str, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Wrist position (m, 3), hand world rotation (m, 4) and elbow hint (m, 3) at ``times``:
        the hand's own track, bent around the other stick and the kit (:meth:`_clear`)."""
        self._clear()
        t = np.asarray(times, dtype=np.float64)
        wrist, rot, elbow = self._track(hand, t)
        return wrist + drummer_clear.offsets(self._detours[hand], t), rot, elbow

    def _stick(self, hand: str, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The wrist and the stick's butt and tip, each (m, 3), on the hand's track with
        its detours."""
        wrist, rot, _elbow = self._track(hand, times)
        wrist = wrist + drummer_clear.offsets(self._detours[hand], times)
        grip = wrist + quat.rotate(rot, self._grip_off[hand])
        axis = quat.rotate(rot, STICK_AXIS_LOCAL)
        return wrist, grip - STICK_BUTT_M * axis, grip + STICK_TIP_M * axis

    def _clear(self) -> None:
        """Find the detours that keep the two sticks apart and off the kit, once per
        change of either track: those begun by the last frame drawn stay (cut short
        before an impact of their hand now after it), later ones are found anew."""
        src = tuple(self.keys(h) if self.has_strokes(h) else None for h in HANDS)
        old = self._detour_src
        if old is not None and all(a is b for a, b in zip(src, old, strict=True)):
            return
        self._detour_src = src
        floor = self._drawn
        for h in HANDS:
            for kept in (self._detours, self._lifts):
                kept[h] = [_cut_detour(d, self._times[h], floor) for d in kept[h] if d.t0 <= floor]
        known = [k for k in src if k is not None]
        if not known:
            return
        impacts = [list(self._times[h]) for h in HANDS]
        last = max((ts[-1] for ts in impacts if ts), default=-math.inf)
        first = min(float(k.t[0]) for k in known)
        span = (max(first, floor), last + 0.5)
        if not all(math.isfinite(x) for x in span) or span[1] <= span[0]:
            return
        fns = [
            (lambda ts, h=h: self._stick(h, ts)) if k is not None else None
            for h, k in zip(HANDS, src, strict=True)
        ]
        sampled = drummer_clear.Sampled(fns, self._kit, span)
        for _ in range(3):  # a detour may bring a stick near something else: again
            moves, lifts = drummer_clear.detours_in(sampled, impacts, floor)
            if not any(moves) and not any(lifts):
                break
            for i, (h, found, up) in enumerate(zip(HANDS, moves, lifts, strict=True)):
                self._detours[h] = sorted(self._detours[h] + found, key=lambda d: d.t0)
                self._lifts[h] = sorted(self._lifts[h] + up, key=lambda d: d.t0)
                fn = fns[i]
                if fn is not None:  # sampled again only where the new detours reach
                    sampled.redo(i, fn, found + up)

    def _track(self, hand: str, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`targets` on the hand's own key track (no detours)."""
        k = self.keys(hand)
        assert k is not None
        i0, i1, u = _shaped(k.t, k.profile, t, k.end_t)
        end = k.end_rows[i1]
        grip = k.grip[i0] + u[:, None] * (end[:, :3] - k.grip[i0])
        dy = end[:, 1] - k.grip[i0, 1]
        grip[:, 1] = k.grip[i0, 1] + _height_share(u, dy, k.profile[i1]) * dy
        elbow = k.elbow[i0] + u[:, None] * (end[:, 7:] - k.elbow[i0])
        rot = quat.slerp(k.rot[i0], end[:, 3:7], u)
        j0, j1, w = _shaped(k.lift_t, k.lift_profile, t, k.lift_end_t)
        lift = k.lift[j0] + w * (k.lift_end[j1] - k.lift[j0])
        off = self._grip_off[hand]
        wrist = grip - quat.rotate(rot, off)
        # the stick turns up about the wrist, the wrist rises a share of the lift
        s = self.settings
        d = quat.rotate(rot, STICK_AXIS_LOCAL)
        axis = quat.cross(d, _UP)
        norm = np.linalg.norm(axis, axis=-1, keepdims=True)
        axis = axis / np.maximum(norm, 1e-9)
        lever = STICK_TIP_M + float(np.linalg.norm(off))
        sin_a = -d[:, 1]  # the stick's slope below the horizontal
        rise = (1.0 - s.wrist_share) * lift
        if self._lifts[hand]:  # the tip over a piece it would go through (_clear)
            rise = rise + drummer_clear.offsets(self._lifts[hand], t)[:, 1]
        theta = np.arcsin(np.clip(rise / lever - sin_a, -1.0, math.sin(math.radians(60.0))))
        theta = theta + np.arcsin(np.clip(sin_a, -1.0, 1.0))
        rot = quat.multiply(quat.from_axis_angle(axis, theta), rot)
        wrist = wrist + (s.wrist_share * lift)[:, None] * _UP
        return wrist, rot, elbow

    def local(self, hand: str, times: np.ndarray) -> np.ndarray:
        """Local rotations (m, 4, 4) of the hand's Shoulder, Arm, ForeArm, Hand at ``times``."""
        wrist, rot, elbow = self.targets(hand, times)
        ref = self._ref[hand]
        assert ref is not None
        up_ref, lo_ref, r_arm, r_fore = ref
        shoulder = self._shoulder[hand]
        l1, l2 = self._l1[hand], self._l2[hand]
        to = wrist - shoulder
        dist = np.linalg.norm(to, axis=-1)
        d = np.clip(dist, abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6)
        u = to / np.maximum(dist, 1e-9)[:, None]
        v = elbow - np.sum(elbow * u, axis=-1, keepdims=True) * u
        v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)
        cos_a = np.clip((l1**2 + d**2 - l2**2) / (2 * l1 * d), -1.0, 1.0)
        a = np.arccos(cos_a)[:, None]
        up_new = l1 * (np.cos(a) * u + np.sin(a) * v)
        lo_new = d[:, None] * u - up_new
        m_up = _frames(up_new, lo_new) @ np.swapaxes(_frames(up_ref, lo_ref), -1, -2)
        m_lo = _frames(lo_new, -up_new) @ np.swapaxes(_frames(lo_ref, -up_ref), -1, -2)
        world_up = quat.multiply(quat.from_matrix(m_up), r_arm)
        world_lo = quat.multiply(quat.from_matrix(m_lo), r_fore)
        out = np.empty((len(wrist), 4, 4))
        out[:, 0] = self._idle[self._joints[hand][0]]
        out[:, 1] = quat.multiply(quat.conjugate(self._shoulder_rot[hand]), world_up)
        out[:, 2] = quat.multiply(quat.conjugate(world_up), world_lo)
        out[:, 3] = quat.multiply(quat.conjugate(world_lo), rot)
        return out

    def joint_index(self, hand: str) -> np.ndarray:
        return self._joints[hand]


def _cut_detour(
    d: drummer_clear.Detour, impacts: list[float], drawn: float
) -> drummer_clear.Detour:
    """A detour begun by ``drawn``, back to zero before its hand's first impact after
    ``drawn`` (a stroke added since): unchanged at and before ``drawn``, and never held
    longer than it was (a detour already over, or on its way back, at ``drawn`` is not
    held again: as live on MMA JazzWaltz at 240 bpm one cut short at 0.27 s and over by
    0.34 s was held again up to the frame of 0.37 s and then dropped in a millisecond,
    7 cm: 9.7 m/s)."""
    if d.t3 <= drawn:
        return d  # over before the last frame drawn
    k = bisect.bisect_right(impacts, max(drawn, d.t0))
    if k == len(impacts) or impacts[k] >= d.t3 + drummer_clear.BEFORE_IMPACT_S - 1e-9:
        return d
    imp = impacts[k]
    if d.t2 <= drawn:  # on its way back at the last frame drawn: it ends sooner
        t2 = d.t2
    else:
        t2 = max(drawn, d.t1, min(d.t2, imp - 2 * drummer_clear.BEFORE_IMPACT_S))
    t3 = min(max(t2 + 1e-3, drawn + 1e-3, imp - drummer_clear.BEFORE_IMPACT_S), imp, d.t3)
    return drummer_clear.Detour(d.t0, d.t1, t2, max(t3, t2 + 1e-4), d.vec)


def _frames(d: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Right-handed orthonormal frames (..., 3, 3), columns [d, h orthogonalised, d x h]."""
    return frames(d, h)


__all__ = ["DrummerHands", "HandSettings", "HANDS"]
