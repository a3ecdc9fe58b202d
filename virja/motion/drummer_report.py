"""The drummer's motion, measured (issue 15): speed, jumps, torso, collisions, hi-hat.

Sampled from a :class:`~virja.motion.band.BandAnimator` over a time span:

- **wrist speed** (m/s): the speed of each hand joint (``LeftHand``,
  ``RightHand``) between frames at ``fps`` (default 120); p99 and max over both.
- **largest hand jump** (m): the largest distance a wrist moves between two
  frames at 30 fps, what a viewer of a 30 fps video sees as a jump.
- **torso range** (degrees): the range of the chest's turn about the vertical
  (yaw) over the span; a body that never turns gives 0.
- **collisions** by pair, each counted once per run of touching frames:
  ``stick-stick`` (the two sticks closer than two stick radii),
  ``stick-<piece>`` (a stick tip more than 5 mm under a head or a cymbal's top,
  inside its rim), ``leg-<drum>`` (a thigh or shin inside a drum's shell),
  ``foot-floor`` (a toe more than 1 cm under the floor).
- **hi-hat agreement**: the share of hi-hat notes whose cymbals are where the
  note says at its impact: closed (and pedal) notes closed (openness <= 0.15),
  open notes open (openness >= 0.3).  Articulations come from the caller (the
  kit map), as note number -> articulation.  A note with a note of the other
  state within 30 ms (MMA writes an open hi-hat, 46, at the instant of the
  pedal, 44: no pair of cymbals can be both) is counted apart, in
  ``hihat_contradictory``, not in the share.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from virja import quat
from virja.geometry import Cymbal
from virja.motion.band import BandAnimator, PlannedNoteLike, sticks
from virja.motion.drummer_clear import segment_closest
from virja.motion.skeleton import SKELETON

_SK = SKELETON
STICK_RADIUS_M = 0.007
PENETRATION_M = 0.005
CLOSED_MAX = 0.15
CONTRADICTION_S = 0.03  # the planner's grouping window: notes meant together
OPEN_MIN = 0.3
HAND_JOINTS = ("LeftHand", "RightHand")
LEG_SEGMENTS = (("LeftUpLeg", "LeftLeg"), ("LeftLeg", "LeftFoot"))
LEG_SEGMENTS_R = (("RightUpLeg", "RightLeg"), ("RightLeg", "RightFoot"))
CLOSED_ARTICULATIONS = frozenset({"closed", "closed_edge", "pedal"})
OPEN_ARTICULATIONS = frozenset({"open", "open_edge"})


class DrumNoteLike(PlannedNoteLike, Protocol):
    """A planned note with its MIDI note number (for the hi-hat's articulation)."""

    @property
    def note(self) -> int: ...


@dataclass
class DrummerFigures:
    """What :func:`measure_drummer` finds (lengths m, speeds m/s, angles degrees)."""

    wrist_speed_p99: float = 0.0
    wrist_speed_max: float = 0.0
    hand_jump_30fps_m: float = 0.0
    torso_range_deg: float = 0.0
    collisions: dict[str, int] = field(default_factory=dict)
    hihat_notes: int = 0
    hihat_agreeing: int = 0
    hihat_contradictory: int = 0  # notes with one of the other state within 30 ms

    @property
    def hihat_agreement(self) -> float | None:
        return None if self.hihat_notes == 0 else self.hihat_agreeing / self.hihat_notes

    def to_json(self) -> dict[str, object]:
        return {
            "wrist_speed_p99_m_s": round(self.wrist_speed_p99, 3),
            "wrist_speed_max_m_s": round(self.wrist_speed_max, 3),
            "hand_jump_30fps_m": round(self.hand_jump_30fps_m, 4),
            "torso_range_deg": round(self.torso_range_deg, 2),
            "collisions": dict(sorted(self.collisions.items())),
            "hihat_notes": self.hihat_notes,
            "hihat_contradictory": self.hihat_contradictory,
            "hihat_agreement": (
                None if self.hihat_agreement is None else round(self.hihat_agreement, 4)
            ),
        }


def _sample(
    animator: BandAnimator, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Drummer joint positions (k, n, 3), rotations (k, n, 4), sticks (k, 2, 2, 3) and
    hi-hat openness (k,) at ``times``."""
    pos, rot = [], []
    for k in range(0, len(times), 512):  # batched (local_rotations_many), bounded memory
        wpos, wrot = _SK.fk(animator.local_rotations_many(times[k : k + 512]), animator._roots)
        pos.append(wpos[:, 0])
        rot.append(wrot[:, 0])
    p, r = np.concatenate(pos), np.concatenate(rot)
    hh = [animator._hihat_open(p[k], float(t)) for k, t in enumerate(times)]
    return p, r, sticks(p, r), np.array(hh)


def _runs(flags: np.ndarray) -> int:
    """Number of runs of True in a 1-D boolean array."""
    if not flags.size:
        return 0
    f = flags.astype(np.int8)
    return int(f[0] + np.count_nonzero(np.diff(f) == 1))


def _segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Closest distance between segments p0-p1 and q0-q1, vectorised over the first axis."""
    pa, pb = segment_closest(p0, p1, q0, q1)
    return np.asarray(np.linalg.norm(pa - pb, axis=1))


def _collisions(animator: BandAnimator, pos: np.ndarray, stk: np.ndarray) -> dict[str, int]:
    kit = animator.geometry.kit
    out: dict[str, int] = {}
    d = _segment_distance(stk[:, 0, 0], stk[:, 0, 1], stk[:, 1, 0], stk[:, 1, 1])
    out["stick-stick"] = _runs(d < 2 * STICK_RADIUS_M)
    for name, piece in kit.pieces.items():
        top = piece.centre + (piece.thickness / 2 if isinstance(piece, Cymbal) else 0.0) * (
            piece.normal
        )
        hits = np.zeros(len(stk), dtype=bool)
        for side in (0, 1):
            rel = stk[:, side, 1] - top
            h = rel @ piece.normal
            radial = np.linalg.norm(rel - h[:, None] * piece.normal, axis=1)
            depth = piece.thickness if isinstance(piece, Cymbal) else piece.depth
            hits |= (h < -PENETRATION_M) & (h > -depth - 0.05) & (radial < piece.radius)
        out[f"stick-{name}"] = _runs(hits)
        if isinstance(piece, Cymbal) or name == "kick":
            continue
        inside = np.zeros(len(pos), dtype=bool)
        for a, b in LEG_SEGMENTS + LEG_SEGMENTS_R:
            pa, pb = pos[:, _SK.index(a)], pos[:, _SK.index(b)]
            for w in np.linspace(0.0, 1.0, 6):
                pt = pa + w * (pb - pa)
                rel = pt - piece.centre
                h = rel @ piece.normal
                radial = np.linalg.norm(rel - h[:, None] * piece.normal, axis=1)
                inside |= (h < 0) & (h > -piece.depth) & (radial < piece.radius)
        out[f"leg-{name}"] = _runs(inside)
    toes = np.stack([pos[:, _SK.index("LeftToe"), 1], pos[:, _SK.index("RightToe"), 1]], axis=1)
    out["foot-floor"] = _runs(np.asarray((toes < -0.01).any(axis=1)))
    return out


def _yaw_deg(rot: np.ndarray) -> np.ndarray:
    fwd = quat.rotate(rot, np.array([0.0, 0.0, 1.0]))
    return np.asarray(np.degrees(np.unwrap(np.arctan2(fwd[..., 0], fwd[..., 2]))))


def measure_drummer(
    animator: BandAnimator,
    planned: Sequence[DrumNoteLike],
    articulation: Mapping[int, str | None],
    *,
    fps: float = 120.0,
) -> DrummerFigures:
    """The figures of the module docstring for the drummer's notes in ``planned``."""
    drums = [p for p in planned if p.performer == "drums"]
    fig = DrummerFigures()
    if not drums:
        return fig
    t0 = min(p.start for p in drums)
    t1 = max(p.impact for p in drums) + 0.5
    times = t0 + np.arange(int((t1 - t0) * fps) + 1) / fps
    pos, rot, stk, _hh = _sample(animator, times)
    hands = pos[:, [_SK.index(j) for j in HAND_JOINTS]]  # (k, 2, 3)
    if len(times) > 1:
        speed = np.linalg.norm(np.diff(hands, axis=0), axis=-1).ravel() * fps
        fig.wrist_speed_p99 = float(np.percentile(speed, 99))
        fig.wrist_speed_max = float(speed.max())
    coarse = t0 + np.arange(int((t1 - t0) * 30.0) + 1) / 30.0
    cpos, _r, _s, _h = _sample(animator, coarse)
    if len(coarse) > 1:
        ch = cpos[:, [_SK.index(j) for j in HAND_JOINTS]]
        fig.hand_jump_30fps_m = float(np.linalg.norm(np.diff(ch, axis=0), axis=-1).max())
    yaw = _yaw_deg(rot[:, _SK.index("Chest")])
    fig.torso_range_deg = float(yaw.max() - yaw.min())
    fig.collisions = _collisions(animator, pos, stk)
    states = [  # (impact, wants closed) of every articulated hi-hat note
        (p.impact, articulation.get(p.note) in CLOSED_ARTICULATIONS)
        for p in drums
        if p.piece == "hihat"
        and articulation.get(p.note) in CLOSED_ARTICULATIONS | OPEN_ARTICULATIONS
    ]
    for p in drums:
        art = articulation.get(p.note)
        if p.piece != "hihat" or art is None:
            continue
        want_closed = art in CLOSED_ARTICULATIONS
        if not want_closed and art not in OPEN_ARTICULATIONS:
            continue
        if any(abs(t - p.impact) <= CONTRADICTION_S and c != want_closed for t, c in states):
            fig.hihat_contradictory += 1
            continue
        wpos, _w = _SK.fk(animator.local_rotations(p.impact), animator._roots)
        openness = animator._hihat_open(wpos[0], p.impact)
        fig.hihat_notes += 1
        if (openness <= CLOSED_MAX) if want_closed else (openness >= OPEN_MIN):
            fig.hihat_agreeing += 1
    return fig
