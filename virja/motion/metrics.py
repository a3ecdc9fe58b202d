"""Quality of the animation, measured: impact timing, contact, continuity.

- **Contact error** (m): at each planned impact, the distance from the
  contact point to the instrument in :mod:`virja.geometry`: stick tip to the
  struck head or cymbal surface, toe to the pressed pedal, fretting fingertip
  to the stopped string point, plucking fingertip to the pluck point.
- **Timing error** (s): when the contact point is actually closest to its
  target (strokes: closest approach within +-60 ms of the impact, 1 ms
  steps, and no nearer a neighbouring impact of the same limb than to its
  own: a double 46 ms before on the same head touches it as closely and is
  that note's contact, not this one's) minus the planned impact.
- **Continuity** (rad/s per frame): the largest change of any limb joint's
  angular velocity between consecutive frames, split into frames inside a
  connection interval (two instances blending) and frames within one clip.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from virja import quat
from virja.geometry import Geometry
from virja.motion import bass_lean
from virja.motion.band import FIGURES, BandAnimator, PlannedNoteLike, sticks
from virja.motion.skeleton import LIMB_JOINTS, SKELETON
from virja.vocab import HANDS, PERFORMER_LIMBS, DrumStroke

_SK = SKELETON
CONTACT_TOLERANCE_M = 0.01


@dataclass(frozen=True)
class NoteCheck:
    """One planned note's measurements (``fret_contact_m`` None for open strings and drums)."""

    motion: str
    impact: float
    contact_m: float
    timing_s: float
    fret_contact_m: float | None = None


@dataclass
class MotionReport:
    """Summary of :func:`measure` (lengths in metres, times in seconds)."""

    notes: list[NoteCheck] = field(default_factory=list)
    continuity_connection: float = 0.0
    continuity_within: float = 0.0
    frames: int = 0

    @property
    def max_contact_m(self) -> float:
        vals = [n.contact_m for n in self.notes] + [
            n.fret_contact_m for n in self.notes if n.fret_contact_m is not None
        ]
        return max(vals, default=0.0)

    @property
    def mean_contact_m(self) -> float:
        return float(np.mean([n.contact_m for n in self.notes])) if self.notes else 0.0

    @property
    def max_timing_s(self) -> float:
        return max((abs(n.timing_s) for n in self.notes), default=0.0)

    @property
    def mean_timing_s(self) -> float:
        return float(np.mean([abs(n.timing_s) for n in self.notes])) if self.notes else 0.0

    @property
    def contacts_over_tolerance(self) -> int:
        return sum(
            1
            for n in self.notes
            if n.contact_m > CONTACT_TOLERANCE_M or (n.fret_contact_m or 0.0) > CONTACT_TOLERANCE_M
        )


def contact_distance(
    animator: BandAnimator, p: PlannedNoteLike, t: float
) -> tuple[float, float | None]:
    """(contact distance, fretting distance or None) of note ``p`` at time ``t`` (m)."""
    contact, fret = contact_distances(animator, p, np.array([t]))
    return float(contact[0]), None if fret is None else float(fret[0])


def contact_distances(
    animator: BandAnimator, p: PlannedNoteLike, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`contact_distance` at many times (sorted ascending), the poses batched:
    (contact distances (m,), fretting distances (m,) or None)."""
    geo: Geometry = animator.geometry
    loc = animator.local_rotations_many(np.asarray(times, dtype=np.float64))
    wpos, wrot = _SK.fk(loc, animator._roots)  # (m, 2, n, 3), (m, 2, n, 4)
    if p.performer == "drums":
        clip = p.motion.clip if isinstance(p.motion, DrumStroke) else p.motion.name
        piece = p.piece or animator.library[clip].piece or ""
        if p.limb in HANDS:
            tips = sticks(wpos[:, 0], wrot[:, 0])[:, 0 if p.limb == "left_hand" else 1, 1]
            return np.array([geo.kit.surface_distance(piece, tip) for tip in tips]), None
        pedal = geo.kit.kick_pedal if piece == "kick" else geo.kit.hihat_pedal
        toe = wpos[:, 0, _SK.index("RightToe" if p.limb == "right_foot" else "LeftToe")]
        return np.linalg.norm(toe - pedal.toe_point(True), axis=-1), None
    assert p.string is not None
    # the bass leans with its player (BandPose.bass_transform): the targets lean with it
    leans = animator.bass_transform(wpos[:, 1])  # (m, 4, 4)
    pluck_at = np.stack([bass_lean.apply(m, geo.bass.pluck_point(p.string)) for m in leans])
    pluck = np.linalg.norm(wpos[:, 1, _SK.index("RightHandEnd")] - pluck_at, axis=-1)
    fret = None
    if p.fret:
        stop = np.stack(
            [bass_lean.apply(m, geo.bass.string_point(p.string, p.fret)) for m in leans]
        )
        fret = np.linalg.norm(wpos[:, 1, _SK.index("LeftHandEnd")] - stop, axis=-1)
    return pluck, fret


TIMING_WINDOW_MS = 60


def _timing(
    animator: BandAnimator,
    p: PlannedNoteLike,
    prev_impact: float | None = None,
    next_impact: float | None = None,
) -> float:
    """When the tip is really closest to its target, minus the planned impact (s):
    searched over +-60 ms in 1 ms steps, but only on this note's side of the midpoints
    to the same limb's previous and next impacts (``prev_impact``, ``next_impact``).
    Without that bound, a stroke 46 ms before on the same head (a double, a drag, a
    swung skip note at 300 bpm) touches it as closely as this one does, and the
    search finds that stroke's contact: a timing error of -46 ms for a note that lands
    exactly."""
    steps = np.arange(-TIMING_WINDOW_MS, TIMING_WINDOW_MS + 1)
    offsets = steps * 1e-3
    own = np.ones(steps.size, dtype=bool)
    if prev_impact is not None:
        own &= offsets > 0.5 * (prev_impact - p.impact)
    if next_impact is not None:
        own &= offsets < 0.5 * (next_impact - p.impact)
    own[TIMING_WINDOW_MS] = True  # the impact itself is always the note's own
    ts = p.impact + offsets[own]
    d = contact_distances(animator, p, ts)[0]
    return float(ts[int(np.argmin(d))] - p.impact)


def _neighbour_impacts(
    planned: Sequence[PlannedNoteLike],
) -> list[tuple[float | None, float | None]]:
    """For each note of ``planned``, the impacts of the same performer's same limb just
    before and just after it (None where there is none); an impact at the same instant
    is no neighbour (nothing separates the two contacts)."""
    by_limb: dict[tuple[str, str], list[float]] = {}
    for p in planned:
        by_limb.setdefault((p.performer, p.limb), []).append(p.impact)
    for times in by_limb.values():
        times.sort()
    out: list[tuple[float | None, float | None]] = []
    for p in planned:
        times = by_limb[(p.performer, p.limb)]
        lo = bisect.bisect_left(times, p.impact)
        hi = bisect.bisect_right(times, p.impact)
        out.append((times[lo - 1] if lo else None, times[hi] if hi < len(times) else None))
    return out


def in_connection(
    animator: BandAnimator, t: float, figure: str | None = None, limb: str | None = None
) -> bool:
    """Whether a limb (or the given figure/limb) is blending two instances (or fading from rest) at ``t``."""
    for (fig, lb), tl in animator.timelines.items():
        if (figure is not None and fig != figure) or (limb is not None and lb != limb):
            continue
        for inst in tl.active(t):
            if 0.0 < inst.weight(t) < 1.0:
                return True
    return False


def continuity(
    animator: BandAnimator, t0: float, t1: float, fps: float = 120.0
) -> tuple[float, float, int]:
    """(largest angular-velocity jump in connections, within clips, frames) over [t0, t1]."""
    times = t0 + np.arange(int((t1 - t0) * fps) + 1) / fps
    if len(times) < 3:
        return 0.0, 0.0, len(times)
    loc = animator.local_rotations_many(times)  # (k, 2, n, 4)
    limb_idx = sorted(
        {_SK.index(j) for f in FIGURES for limb in PERFORMER_LIMBS[f] for j in LIMB_JOINTS[limb]}
    )
    q = loc[:, :, limb_idx]
    rel = quat.multiply(quat.conjugate(q[:-1]), q[1:])
    axis, ang = quat.to_axis_angle(rel)
    omega = axis * ang[..., None] * fps  # (k-1, 2, j, 3) rad/s
    jump = np.linalg.norm(omega[1:] - omega[:-1], axis=-1).max(axis=(1, 2))  # (k-2,)
    conn = np.array([in_connection(animator, float(t)) for t in times[1:-1]])
    c = float(jump[conn].max()) if conn.any() else 0.0
    w = float(jump[~conn].max()) if (~conn).any() else 0.0
    return c, w, len(times)


def measure(
    animator: BandAnimator,
    planned: Sequence[PlannedNoteLike],
    *,
    fps: float = 120.0,
    timing: bool = True,
) -> MotionReport:
    """Contact, timing and continuity of ``planned`` (already added to ``animator``)."""
    rep = MotionReport()
    for p, (before, after) in zip(planned, _neighbour_impacts(planned), strict=True):
        c, f = contact_distance(animator, p, p.impact)
        t = _timing(animator, p, before, after) if timing else 0.0
        rep.notes.append(NoteCheck(p.motion.name, p.impact, c, t, f))
    if planned:
        t0 = min(p.start for p in planned)
        t1 = max(p.impact for p in planned) + 0.6
        rep.continuity_connection, rep.continuity_within, rep.frames = continuity(
            animator, t0, t1, fps
        )
    return rep
