"""Motion instances on one limb and how they connect.

An :class:`Instance` plays a clip so that the clip's first frame falls on
``start`` and its impact on ``impact``: the preparation ``[0, clip.impact_s]``
is time-warped linearly onto ``[start, impact]``; after the impact the clip
plays at ``rate`` times its natural speed (the tempo shortens the rebound).

Connection (methods.md A): when instance B starts before A has ended, the
interval ``[max(B.start, A.impact), min(A.end, B.impact)]`` is their
connection (it never begins before A's impact, so A's contact is exact); in it the
pose is ``slerp(A, B, w)`` with ``w`` going linearly from 0 to 1, so A weighs
100 % -> 0 %.  After the connection A is dropped; B's impact is never
disturbed.  Outside connections a limb shows exactly one clip (or the base
layer), unchanged.  A "hold" clip keeps its last frame until replaced or
released; an instance with no predecessor and a nonzero ``fade_in`` fades in
from the base layer over ``[start, start + fade_in]`` the same way.

Velocity scales the gesture: the clip's deviation from the straight
slerp path ready -> impact pose -> ready is scaled by ``scale`` (soft = a
small stroke), so the first frame, the impact pose and the last frame stay
exact.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

import numpy as np

from virja import quat
from virja.motion.clip import Clip, align_signs, sample_frames


@dataclass
class Instance:
    """One clip placed on the timeline (times in session seconds)."""

    clip: Clip
    start: float
    impact: float
    rate: float = 1.0
    scale: float = 1.0
    velocity: int = 96
    hold_s: float = float("inf")
    fade_in: float = 0.0
    tag: object = None
    # filled in by the Timeline: end of the connection into this instance, and
    # the time a successor takes over completely (this instance stops there)
    ramp_start: float | None = field(default=None)
    ramp_end: float | None = field(default=None)
    cut: float | None = field(default=None)
    _cache: tuple[bytes, np.ndarray] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.impact < self.start:
            raise ValueError(f"impact {self.impact} before start {self.start}")
        if not self.rate > 0:
            raise ValueError(f"rate must be > 0, got {self.rate}")

    @property
    def natural_end(self) -> float:
        """When the clip (and, for a hold, its hold) is over, if nothing replaces it."""
        after = (self.clip.duration_s - self.clip.impact_s) / self.rate
        if self.clip.kind == "hold":
            return self.impact + max(after, self.hold_s)
        return self.impact + after

    @property
    def end(self) -> float:
        return self.natural_end if self.cut is None else min(self.cut, self.natural_end)

    def clip_time(self, t: float) -> float:
        """Clip-local time (s) shown at session time ``t`` (the time warp)."""
        c = self.clip
        if t < self.impact:
            span = self.impact - self.start
            if span <= 1e-9:
                return c.impact_s
            return max(0.0, (t - self.start) / span) * c.impact_s
        return min(c.impact_s + (t - self.impact) * self.rate, c.duration_s)

    def local(self, t: float, joint_index: np.ndarray) -> np.ndarray:
        """Local rotations (k, 4) of joints ``joint_index`` at session time ``t``."""
        return sample_frames(
            self._frames(joint_index), self.clip.fps, self.clip_time(t), _ALL[: len(joint_index)]
        )

    def _frames(self, joint_index: np.ndarray) -> np.ndarray:
        """The clip's frames of ``joint_index``, velocity-scaled, computed once per instance."""
        key = joint_index.tobytes()
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1]
        frames = scaled_frames(self.clip, joint_index, self.scale)
        self._cache = (key, frames)
        return frames

    def weight(self, t: float) -> float:
        """Weight (0..1) of this instance over what lies below it at ``t``."""
        if self.ramp_end is not None:
            r0 = self.start if self.ramp_start is None else self.ramp_start
            if t < r0:
                return 0.0
            span = self.ramp_end - r0
            return 1.0 if span <= 1e-9 else float(min((t - r0) / span, 1.0))
        if self.fade_in > 0:
            return float(min(max((t - self.start) / self.fade_in, 0.0), 1.0))
        return 1.0


_ALL = np.arange(256)


def scaled_frames(clip: Clip, joint_index: np.ndarray, scale: float) -> np.ndarray:
    """Frames (n, k, 4) of ``joint_index`` with the gesture scaled by ``scale``.

    Each frame's deviation from the straight path ready -> impact pose ->
    ready is scaled (slerp from the identity, or a power above 1), so the
    first frame, the impact frame and the last frame are unchanged.
    """
    frames = clip.rotations[:, joint_index]
    if abs(scale - 1.0) < 1e-9 or clip.kind != "stroke":
        return frames
    n = clip.n_frames
    k_imp = int(round(clip.impact_s * clip.fps))
    u = np.empty(n)
    u[k_imp:] = np.arange(n - k_imp) / max(n - 1 - k_imp, 1)
    u[: k_imp + 1] = np.arange(k_imp + 1) / max(k_imp, 1)  # the impact frame ends the first leg
    a = np.where(np.arange(n)[:, None] <= k_imp, 0, 1)[:, :, None]  # which leg of the path
    first, imp, last = frames[0], frames[k_imp], frames[-1]
    start = np.where(a == 0, first, imp)
    stop = np.where(a == 0, imp, last)
    base = quat.slerp(start, stop, u[:, None])
    dev = quat.multiply(quat.conjugate(base), frames)
    dev = (
        quat.slerp(quat.identity(dev.shape[:-1]), dev, scale) if scale <= 1.0 else _pow(dev, scale)
    )
    return align_signs(quat.multiply(base, dev))


def _pow(q: np.ndarray, s: float) -> np.ndarray:
    axis, ang = quat.to_axis_angle(q)
    return quat.from_axis_angle(axis, ang * s)


class Timeline:
    """The instances of one limb (driving joints ``joint_index``), ordered by start time."""

    def __init__(self, joint_index: np.ndarray) -> None:
        self.joint_index = np.asarray(joint_index, dtype=np.int64)
        self._items: list[Instance] = []
        self._starts: list[float] = []

    def __len__(self) -> int:
        return len(self._items)

    @property
    def instances(self) -> list[Instance]:
        return list(self._items)

    def add(self, inst: Instance) -> None:
        i = bisect.bisect_right(self._starts, inst.start)
        self._items.insert(i, inst)
        self._starts.insert(i, inst.start)
        self._relink(max(i - 1, 0), min(i + 2, len(self._items)))

    def _relink(self, lo: int, hi: int) -> None:
        for k in range(lo, hi):
            b = self._items[k]
            b.ramp_start = b.ramp_end = None
            if k > 0:
                a = self._items[k - 1]
                a.cut = None
                if a.natural_end > b.start:
                    # the connection never starts before A's impact, so both impacts stay exact
                    r0 = max(b.start, min(a.impact, b.impact))
                    stop = min(a.natural_end, b.impact)
                    if stop > r0:
                        b.ramp_start, b.ramp_end = r0, stop
                        a.cut = stop
                    else:  # no room for a connection: A stops where B takes over
                        a.cut = max(r0, b.start)
                        b.ramp_start = b.ramp_end = a.cut

    def active(self, t: float) -> list[Instance]:
        """Instances that contribute at ``t`` (start <= t < end), in start order.

        Ends never decrease along the timeline (a predecessor is cut at its
        successor's impact at the latest), so the backward scan stops at the
        first instance that has ended, or at one that covers everything below.
        """
        out: list[Instance] = []
        for k in range(bisect.bisect_right(self._starts, t) - 1, -1, -1):
            inst = self._items[k]
            if inst.end <= t:
                break
            out.append(inst)
            if inst.weight(t) >= 1.0:
                break
        out.reverse()
        return out

    def blend(self, t: float, below: np.ndarray) -> np.ndarray:
        """Local rotations (k, 4) of this limb's joints: ``below`` with the active instances on top."""
        acc = below
        for inst in self.active(t):
            w = inst.weight(t)
            q = inst.local(t, self.joint_index)
            acc = q if w >= 1.0 else quat.slerp(acc, q, w)
        return acc

    def forget_before(self, t: float) -> int:
        """Drop instances that ended before ``t`` (keeps the latest one); returns how many."""
        keep_from = 0
        for k, inst in enumerate(self._items[:-1]):
            if inst.end < t:
                keep_from = k + 1
            else:
                break
        if keep_from:
            del self._items[:keep_from]
            del self._starts[:keep_from]
        return keep_from


def clip_times(inst: Instance, t: np.ndarray) -> np.ndarray:
    """:meth:`Instance.clip_time` over an array of session times."""
    c = inst.clip
    span = inst.impact - inst.start
    if span <= 1e-9:
        pre = np.full(t.shape, c.impact_s)
    else:
        pre = np.maximum(0.0, (t - inst.start) / span) * c.impact_s
    post = np.minimum(c.impact_s + (t - inst.impact) * inst.rate, c.duration_s)
    return np.where(t < inst.impact, pre, post)


def weights(inst: Instance, t: np.ndarray) -> np.ndarray:
    """:meth:`Instance.weight` over an array of session times."""
    if inst.ramp_end is not None:
        r0 = inst.start if inst.ramp_start is None else inst.ramp_start
        span = inst.ramp_end - r0
        w = np.ones(t.shape) if span <= 1e-9 else np.minimum((t - r0) / span, 1.0)
        return np.where(t < r0, 0.0, w)
    if inst.fade_in > 0:
        return np.clip((t - inst.start) / inst.fade_in, 0.0, 1.0)
    return np.ones(t.shape)


def sample_frames_many(frames: np.ndarray, fps: float, times: np.ndarray) -> np.ndarray:
    """:func:`virja.motion.clip.sample_frames` of all joints over an array of clip times:
    (m, k, 4) from ``frames`` (n, k, 4)."""
    n = frames.shape[0]
    f = np.clip(times * fps, 0.0, n - 1.0)
    i0 = f.astype(np.int64)
    frac = f - i0
    exact = (frac < 1e-9) | (i0 >= n - 1)
    i1 = np.minimum(i0 + 1, n - 1)
    q = (1.0 - frac)[:, None, None] * frames[i0] + frac[:, None, None] * frames[i1]
    q = q / np.sqrt(np.einsum("mij,mij->mi", q, q))[..., None]
    return np.where(exact[:, None, None], frames[i0], q)


def blend_many(tl: Timeline, times: np.ndarray, below: np.ndarray) -> np.ndarray:
    """:meth:`Timeline.blend` at many times at once: (m, k, 4) from ``below`` (m, k, 4).

    ``times`` must be sorted ascending.  Each instance is applied, in start
    order, to the times it covers (start <= t < end); as ends never decrease
    along a timeline this is the set :meth:`Timeline.active` returns, and an
    instance at full weight replaces what lies below, as in :meth:`Timeline.blend`.
    """
    acc = below.copy()
    if not times.size:
        return acc
    # only the instances that can cover one of the times: those started by the last,
    # back to the first that has ended by the first (the scan :meth:`Timeline.active`
    # makes), not the whole timeline: a render loop asks a few frames at a time
    first, last = float(times[0]), float(times[-1])
    hi_k = bisect.bisect_right(tl._starts, last)
    lo_k = hi_k
    while lo_k > 0 and tl._items[lo_k - 1].end > first:
        lo_k -= 1
    for inst in tl._items[lo_k:hi_k]:
        lo = int(np.searchsorted(times, inst.start, side="left"))
        hi = int(np.searchsorted(times, inst.end, side="left"))
        if hi <= lo:
            continue
        t = times[lo:hi]
        w = weights(inst, t)
        q = sample_frames_many(inst._frames(tl.joint_index), inst.clip.fps, clip_times(inst, t))
        full = (w >= 1.0)[:, None, None]
        mixed = quat.slerp(acc[lo:hi], q, w[:, None])
        acc[lo:hi] = np.where(full, q, mixed)
    return acc
