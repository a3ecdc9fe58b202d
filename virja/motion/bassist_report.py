"""The bassist's figures for ``virja motion-report`` (docs/motion.md).

Sampled from the animator at 30 fps (what a viewer sees) and 120 fps (speeds):

- **contact / timing** at impact of the bass notes (from :func:`virja.motion.metrics.measure`);
- **wrist speed** p99 and max (m/s), both wrists, 120 fps;
- **largest jump** (m): the largest move of any of the bassist's joints or
  fingertips from one 30 fps frame to the next;
- **torso range** (degrees): the largest angle between the chest's orientations
  at any two frames;
- **collisions**: frames where the centre line of a hand or forearm passes
  through the fingerboard (1.4 cm thick behind the strings, as wide as the
  tuning's strings need: :mod:`virja.fingerboard`; nut to its end) or the
  neck behind it, or the bass's body (the ellipsoids drawn);
- **fretting hand on the correct side** (share of frames): the left wrist
  toward the low (E, B) side from the fingertip, and either beside the board
  (at most 1 cm over its low edge, less than 2 cm in front of the fingertip,
  the elbow behind the strings: the thumb behind the neck) or, where the hand
  cannot reach round a wide board, arched over it (2 cm or more in front, as
  in thumb position) with the elbow out beyond the low edge
  (:func:`virja.motion.bassist.fretting_side`);
- **shifts per stopped note**: how often the hand position (``_pos`` in the
  motion name) changes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.motion import bass_lean
from virja.motion.band import BandAnimator, PlannedNoteLike
from virja.motion.bassist import fretting_side, neck_frame
from virja.motion.metrics import MotionReport
from virja.motion.skeleton import SKELETON
from virja.vocab import BassPluck

_SK = SKELETON
SEGMENTS = (
    ("LeftForeArm", "LeftHand"),
    ("LeftHand", "LeftHandEnd"),
    ("RightForeArm", "RightHand"),
    ("RightHand", "RightHandEnd"),
)

# targets (issue 16, as for the drummer where they apply)
TARGETS = {
    "contact_mm": 10.0,
    "timing_ms": 0.0,
    "wrist_p99": 5.0,
    "wrist_max": 8.0,
    "jump_cm": 15.0,
    "torso_deg": 3.0,
    "collisions": 0,
    "side_share": 1.0,
}


@dataclass(frozen=True)
class BassistFigures:
    notes: int
    contact_max_m: float
    contacts_over: int
    timing_max_s: float
    wrist_p99: float
    wrist_max: float
    jump_max_m: float
    torso_range_deg: float
    collision_frames: int
    frames: int
    side_share: float
    shifts: int
    stopped: int

    def lines(self) -> list[str]:
        """The report, one figure a line with its target and OK/MISS."""

        def ok(good: bool) -> str:
            return "ok" if good else "MISS"

        t = TARGETS
        per = self.shifts / self.stopped if self.stopped else 0.0
        return [
            f"bassist: {self.notes} notes, {self.frames} frames at 30 fps",
            f"  contact at impact: max {self.contact_max_m * 1e3:.2f} mm, "
            f"{self.contacts_over} over 10 mm  [target < {t['contact_mm']:.0f} mm: "
            f"{ok(self.contacts_over == 0)}]",
            f"  timing at impact: max {self.timing_max_s * 1e3:.1f} ms  "
            f"[target 0 ms: {ok(self.timing_max_s <= 0.0005)}]",
            f"  wrist speed: p99 {self.wrist_p99:.2f} m/s, max {self.wrist_max:.2f} m/s  "
            f"[targets <= {t['wrist_p99']:.0f} / {t['wrist_max']:.0f}: "
            f"{ok(self.wrist_p99 <= t['wrist_p99'] and self.wrist_max <= t['wrist_max'])}]",
            f"  largest jump between 30 fps frames: {self.jump_max_m * 100:.1f} cm  "
            f"[target <= {t['jump_cm']:.0f} cm: {ok(self.jump_max_m * 100 <= t['jump_cm'])}]",
            f"  torso range: {self.torso_range_deg:.1f} deg  "
            f"[target >= {t['torso_deg']:.0f}: {ok(self.torso_range_deg >= t['torso_deg'])}]",
            f"  collisions (hands, forearms vs fingerboard and body): {self.collision_frames} "
            f"frames  [target 0: {ok(self.collision_frames == 0)}]",
            f"  fretting hand on the correct side: {self.side_share * 100:.1f} % of frames  "
            f"[target 100 %: {ok(self.side_share >= 1.0)}]",
            f"  hand shifts: {self.shifts} for {self.stopped} stopped notes ({per:.2f} per note)",
        ]

    @property
    def meets_targets(self) -> bool:
        t = TARGETS
        return (
            self.contacts_over == 0
            and self.timing_max_s <= 0.0005
            and self.wrist_p99 <= t["wrist_p99"]
            and self.wrist_max <= t["wrist_max"]
            and self.jump_max_m * 100 <= t["jump_cm"]
            and self.torso_range_deg >= t["torso_deg"]
            and self.collision_frames == 0
            and self.side_share >= 1.0
        )


def _frames(
    animator: BandAnimator, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(k, n, 3) bassist joint positions, (k, n, 4) rotations, (k, m, 3) finger points (world),
    and (k, n, 3) the joint positions in the bass's own frame (it leans with him)."""
    pos, rot, fingers, own = [], [], [], []
    for pose in animator.poses(np.asarray(times, dtype=np.float64)):  # batched over times
        pos.append(pose.bass.positions)
        rot.append(pose.bass.rotations)
        fingers.append(pose.bass_fingers.reshape(-1, 3))
        own.append(bass_lean.apply(bass_lean.inverse(pose.bass_transform), pose.bass.positions))
    return np.array(pos), np.array(rot), np.array(fingers), np.array(own)


def _in_board(points: np.ndarray, animator: BandAnimator) -> np.ndarray:
    """Which points (..., 3) lie inside the fingerboard (as wide as the tuning's strings,
    :mod:`virja.fingerboard`) and the neck behind it."""
    return neck_frame(animator.geometry, animator.bass_strings).inside(points)


def _in_body(points: np.ndarray, animator: BandAnimator) -> np.ndarray:
    b = animator.geometry.bass
    up = b.axis
    lateral = np.cross(b.axis, b.front)
    lateral /= np.linalg.norm(lateral)
    inside = np.zeros(points.shape[:-1], dtype=bool)
    for c, s in (
        (b.body_centre - 0.22 * up, (b.body_width / 2, 0.34, b.body_depth / 2)),
        (b.body_centre + 0.28 * up, (b.body_width / 2 * 0.8, 0.26, b.body_depth / 2)),
    ):
        rel = points - c
        q = (rel @ lateral / s[0]) ** 2 + (rel @ up / s[1]) ** 2 + (rel @ b.front / s[2]) ** 2
        inside |= q < 1.0
    return inside


def measure_bassist(
    animator: BandAnimator, planned: Sequence[PlannedNoteLike], report: MotionReport
) -> BassistFigures | None:
    """The bassist's figures for ``planned`` (added to ``animator``); None without bass notes."""
    bass = [p for p in planned if p.performer == "bass"]
    if not bass:
        return None
    checks = [c for c in report.notes if c.motion.startswith("pluck_")]
    contacts = [c.contact_m for c in checks] + [
        c.fret_contact_m for c in checks if c.fret_contact_m is not None
    ]
    t0 = min(p.start for p in bass)
    t1 = max(p.impact for p in bass) + 0.6
    fast = t0 + np.arange(int((t1 - t0) * 120) + 1) / 120.0
    pos120, _, _, _ = _frames(animator, fast)
    wrists = pos120[:, [_SK.index("LeftHand"), _SK.index("RightHand")]]
    speed = np.linalg.norm(np.diff(wrists, axis=0), axis=-1).ravel() * 120.0
    slow = t0 + np.arange(int((t1 - t0) * 30) + 1) / 30.0
    pos, rot, fingers, own = _frames(animator, slow)
    every = np.concatenate([pos, fingers], axis=1)
    jump = float(np.linalg.norm(np.diff(every, axis=0), axis=-1).max()) if len(slow) > 1 else 0.0
    chest = rot[:, _SK.index("Chest")]
    torso = 0.0
    for i in range(0, len(chest), 3):
        torso = max(torso, float(quat.angle_between(chest[i], chest).max()))
    # collisions and the fretting side in the bass's own frame (it leans with him)
    u = np.linspace(0.0, 1.0, 9)[:, None, None]
    collide = np.zeros(len(slow), dtype=bool)
    for a, b in SEGMENTS:
        pa, pb = own[:, _SK.index(a)], own[:, _SK.index(b)]
        pts = pa[None] + u * (pb - pa)[None]  # (9, k, 3)
        hit = _in_board(pts, animator) | _in_body(pts, animator)
        collide |= hit.any(axis=0)
    board = neck_frame(animator.geometry, animator.bass_strings)
    side = fretting_side(
        board,
        own[:, _SK.index("LeftForeArm")],
        own[:, _SK.index("LeftHand")],
        own[:, _SK.index("LeftHandEnd")],
    )
    positions = [
        p.motion.position if isinstance(p.motion, BassPluck) else None
        for p in sorted(bass, key=lambda p: p.time)
        if p.fret
    ]
    known = [x for x in positions if x is not None]
    shifts = sum(1 for a, b in zip(known, known[1:], strict=False) if a != b)
    return BassistFigures(
        notes=len(bass),
        contact_max_m=max(contacts, default=0.0),
        contacts_over=sum(1 for c in contacts if c > 0.01),
        timing_max_s=max((abs(c.timing_s) for c in checks), default=0.0),
        wrist_p99=float(np.percentile(speed, 99)) if len(speed) else 0.0,
        wrist_max=float(speed.max()) if len(speed) else 0.0,
        jump_max_m=jump,
        torso_range_deg=float(np.degrees(torso)),
        collision_frames=int(collide.sum()),
        frames=len(slow),
        side_share=float(side.mean()) if len(side) else 1.0,
        shifts=shifts,
        stopped=len(positions),
    )
