"""A generated dance as a third figure on stage: a BVH sampled into a ``FigurePose`` at time t.

:class:`DancerTrack` does forward kinematics of every frame once, then
places the motion on the stage: its first frame's waist goes to ``place``
(x, z; default front centre, ahead of the drummer and the bassist), turned
about the vertical so that its first frame faces the audience (+z), and
every frame is lifted or lowered so that its lowest joint rests on the
floor (y = its bone radius; ``ground="frame"``: the dancer stands on the
floor whatever the waist height drift of the joins; ``ground="first"``
lifts all frames by frame 0's amount only).  ``pose(t)`` interpolates joint positions linearly between the two
nearest frames (rotations: the nearer frame) and clamps outside the motion.
Frame 0 is at session time ``t0_s`` (for a MIDI file the audio starts at
session time 0, so a dance generated from the session's audio has
``t0_s = sound_origin_s``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from virja import quat
from virja.dance.audio import FloatArray
from virja.dance.database import DanceDatabase
from virja.dance.generate import Generated, generate
from virja.motion.bvh import Bvh
from virja.motion.bvh import world_pose as bvh_world_pose
from virja.motion.pose import FigurePose
from virja.motion.skeleton import SKELETON

DANCER_PLACE_XZ = (0.0, 1.1)
"""Front centre: between the drummer (x -0.9) and the bassist (x 0.9), 1.1 m ahead of them,
clear of the kit (its front edge is about 0.6 m ahead of the drummer) and the bass."""

DEFAULT_RADIUS_M = 0.04
"""Bone radius for joints the project skeleton does not name."""


def world_pose(bvh: Bvh) -> tuple[FloatArray, FloatArray]:
    """World positions (n, J, 3) and rotations (n, J, 4, w x y z) of every frame."""
    return bvh_world_pose(bvh)


def _radii(names: Sequence[str]) -> FloatArray:
    return np.array(
        [
            float(SKELETON.radii[SKELETON.names.index(n)])
            if n in SKELETON.names
            else DEFAULT_RADIUS_M
            for n in names
        ]
    )


class DancerTrack:
    """A BVH placed on stage, sampled by session time (see the module docstring)."""

    def __init__(
        self,
        bvh: Bvh,
        t0_s: float = 0.0,
        place_xz: tuple[float, float] = DANCER_PLACE_XZ,
        face_audience: bool = True,
        ground: str = "frame",
    ) -> None:
        if ground not in ("frame", "first"):
            raise ValueError(f"ground must be 'frame' or 'first', got {ground!r}")
        if bvh.n_frames < 1:
            raise ValueError("the dance has no frames")
        pos, rot = world_pose(bvh)
        root = next(i for i, j in enumerate(bvh.joints) if j.parent < 0)
        start = pos[0, root].copy()
        if face_audience:
            fwd = quat.rotate(rot[0, root], np.array([0.0, 0.0, 1.0]))
            heading = float(np.arctan2(fwd[0], fwd[2]))  # angle of forward from +z about +y
            turn = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.array(-heading))
            pos = start + quat.rotate(turn, pos - start)
            rot = quat.normalize(quat.multiply(np.broadcast_to(turn, rot.shape), rot))
        self.names = tuple(bvh.names)
        self.parents = bvh.parents
        self.radii = _radii(self.names)
        lowest = np.min(pos[:, :, 1] - self.radii[None, :], axis=1)  # (n,)
        lift = lowest if ground == "frame" else np.full(lowest.shape, lowest[0])
        shift = np.array([place_xz[0] - start[0], 0.0, place_xz[1] - start[2]])
        self.positions: FloatArray = pos + shift
        self.positions[:, :, 1] -= lift[:, None]
        self.rotations: FloatArray = rot
        self.fps = 1.0 / bvh.frame_time_s
        self.t0_s = float(t0_s)

    @property
    def n_frames(self) -> int:
        return int(self.positions.shape[0])

    def pose(self, time_s: float) -> FigurePose:
        """The dancer at session time ``time_s`` (clamped to the motion's ends)."""
        u = float(np.clip((time_s - self.t0_s) * self.fps, 0.0, self.n_frames - 1))
        i0 = min(int(np.floor(u)), self.n_frames - 1)
        i1 = min(i0 + 1, self.n_frames - 1)
        f = u - i0
        pos = self.positions[i0] * (1.0 - f) + self.positions[i1] * f
        rot = self.rotations[i1 if f >= 0.5 else i0]
        return FigurePose(self.names, self.parents, pos, rot.copy(), self.radii)


def dance_to_audio(
    db: DanceDatabase,
    audio_8k: FloatArray,
    t0_s: float = 0.0,
    place_xz: tuple[float, float] = DANCER_PLACE_XZ,
) -> tuple[DancerTrack, Generated]:
    """Generate a dance for ``audio_8k`` (whose sample 0 is session time ``t0_s``) and place it."""
    g = generate(db, audio_8k)
    return DancerTrack(g.bvh, t0_s=t0_s, place_xz=place_xz), g
