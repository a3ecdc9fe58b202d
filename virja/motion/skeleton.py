"""Skeletons (joint hierarchies with rest offsets, bone radii, joint limits) and FK.

Both players share one joint set (BVH-style names).  The rest pose (every
local rotation the identity) stands upright, arms hanging, facing +z, y up,
metres; a player's left is +x.  Clips seat the drummer by rotating his legs.

Forward kinematics is vectorised over frames and done level by level of the
tree (all joints of one depth in one numpy call):
``fk(local_rotations (..., n, 4) w x y z, root_position (..., 3))`` ->
``(world_positions (..., n, 3), world_rotations (..., n, 4))``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from virja import quat
from virja.vocab import Limb

# name, parent, rest offset from the parent (m), bone radius for drawing (m),
# largest rotation from rest the joint may take (deg) - a coarse limit checked by
# the authoring tool and the tests, enough to catch a flipped elbow or knee.
_JOINTS: tuple[tuple[str, str | None, tuple[float, float, float], float, float], ...] = (
    ("Hips", None, (0.0, 0.0, 0.0), 0.11, 180.0),
    ("Spine", "Hips", (0.0, 0.10, 0.0), 0.12, 45.0),
    ("Chest", "Spine", (0.0, 0.18, 0.0), 0.13, 40.0),
    ("Neck", "Chest", (0.0, 0.22, 0.0), 0.05, 45.0),
    ("Head", "Neck", (0.0, 0.09, 0.0), 0.09, 60.0),
    ("HeadEnd", "Head", (0.0, 0.20, 0.0), 0.09, 0.0),
    ("LeftShoulder", "Chest", (0.03, 0.17, 0.0), 0.05, 30.0),
    ("LeftArm", "LeftShoulder", (0.16, 0.0, 0.0), 0.05, 179.0),
    ("LeftForeArm", "LeftArm", (0.0, -0.29, 0.0), 0.04, 170.0),
    ("LeftHand", "LeftForeArm", (0.0, -0.26, 0.0), 0.035, 180.0),
    ("LeftHandEnd", "LeftHand", (0.0, -0.08, 0.0), 0.03, 0.0),
    ("RightShoulder", "Chest", (-0.03, 0.17, 0.0), 0.05, 30.0),
    ("RightArm", "RightShoulder", (-0.16, 0.0, 0.0), 0.05, 179.0),
    ("RightForeArm", "RightArm", (0.0, -0.29, 0.0), 0.04, 170.0),
    ("RightHand", "RightForeArm", (0.0, -0.26, 0.0), 0.035, 180.0),
    ("RightHandEnd", "RightHand", (0.0, -0.08, 0.0), 0.03, 0.0),
    ("LeftUpLeg", "Hips", (0.10, -0.05, 0.0), 0.07, 150.0),
    ("LeftLeg", "LeftUpLeg", (0.0, -0.43, 0.0), 0.055, 160.0),
    ("LeftFoot", "LeftLeg", (0.0, -0.42, 0.0), 0.045, 90.0),
    ("LeftToe", "LeftFoot", (0.0, -0.06, 0.15), 0.04, 0.0),
    ("RightUpLeg", "Hips", (-0.10, -0.05, 0.0), 0.07, 150.0),
    ("RightLeg", "RightUpLeg", (0.0, -0.43, 0.0), 0.055, 160.0),
    ("RightFoot", "RightLeg", (0.0, -0.42, 0.0), 0.045, 90.0),
    ("RightToe", "RightFoot", (0.0, -0.06, 0.15), 0.04, 0.0),
)

# joints each limb drives; a limb's motion touches only these (the joint masks)
LIMB_JOINTS: dict[Limb, tuple[str, ...]] = {
    "left_hand": ("LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"),
    "right_hand": ("RightShoulder", "RightArm", "RightForeArm", "RightHand"),
    "left_foot": ("LeftUpLeg", "LeftLeg", "LeftFoot"),
    "right_foot": ("RightUpLeg", "RightLeg", "RightFoot"),
}

# Stick held in the fist, in the hand's local frame: from the grip point at the
# hand's end joint it continues the hand's line (-y) bent 45 deg toward the
# hand's -z, which is "down" when the forearm reaches forward (the elbow hinge
# is about -x), as a matched grip does; a 0.41 m stick held a quarter from its butt.
STICK_AXIS_LOCAL = np.array([0.0, -1.0, -1.0]) / np.sqrt(2.0)
STICK_BUTT_M = 0.10
STICK_TIP_M = 0.31


@dataclass(frozen=True)
class Skeleton:
    """A joint hierarchy: ``names``, ``parents`` (n,) int (-1 root), ``offsets`` (n, 3) m,
    ``radii`` (n,) m, ``limits_deg`` (n,) largest rotation from rest."""

    names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    radii: np.ndarray
    limits_deg: np.ndarray
    _levels: tuple[tuple[np.ndarray, np.ndarray], ...] = field(repr=False, compare=False)

    @property
    def _offset_cols(self) -> np.ndarray:
        return self.offsets[:, :, None]

    @functools.cached_property
    def _level_offsets(self) -> tuple[np.ndarray, ...]:
        """Each level's joint offsets as columns (k, 3, 1), made once (FK runs per frame)."""
        return tuple(self._offset_cols[idx] for idx, _par in self._levels)

    @property
    def n_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no joint {name!r} in the skeleton") from None

    def mask(self, names: tuple[str, ...] | list[str]) -> np.ndarray:
        """Boolean (n,) mask of the given joints."""
        m = np.zeros(self.n_joints, dtype=bool)
        for n in names:
            m[self.index(n)] = True
        return m

    def fk(self, local: np.ndarray, root_position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World positions (..., n, 3) and rotations (..., n, 4) from local rotations.

        ``local`` (..., n, 4) w x y z; ``root_position`` (..., 3) metres (the
        root's own offset is ignored: the root sits at ``root_position``).
        """
        wpos, rw = self.fk_matrices(local, root_position)
        return wpos, quat.from_matrix(rw)

    def fk_matrices(
        self, local: np.ndarray, root_position: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`fk` with world rotations as matrices (..., n, 3, 3): callers that need
        the rotations of a few joints convert only those (``quat.from_matrix``)."""
        # rotation matrices multiply faster than quaternions for these small arrays
        rl = quat.to_matrix(np.asarray(local, dtype=np.float64))
        rw = np.empty_like(rl)
        wpos = np.empty(rl.shape[:-2] + (3,), dtype=np.float64)
        rw[..., 0, :, :] = rl[..., 0, :, :]
        wpos[..., 0, :] = root_position
        for (idx, par), off in zip(self._levels, self._level_offsets, strict=True):
            rp = rw[..., par, :, :]
            rw[..., idx, :, :] = rp @ rl[..., idx, :, :]
            wpos[..., idx, :] = wpos[..., par, :] + (rp @ off)[..., 0]
        return wpos, rw

    def rest_positions(self, root_position: np.ndarray | None = None) -> np.ndarray:
        """World positions (n, 3) of the rest pose."""
        root = np.zeros(3) if root_position is None else root_position
        return self.fk(quat.identity((self.n_joints,)), root)[0]


def make_skeleton(
    table: tuple[tuple[str, str | None, tuple[float, float, float], float, float], ...] = _JOINTS,
) -> Skeleton:
    """Build a :class:`Skeleton` from a table of (name, parent, offset, radius, limit)."""
    names = tuple(t[0] for t in table)
    parents = np.array([-1 if t[1] is None else names.index(t[1]) for t in table], dtype=np.int64)
    if (
        parents[0] != -1
        or np.any(parents[1:] < 0)
        or np.any(parents[1:] >= np.arange(1, len(names)))
    ):
        raise ValueError("joints must be listed parents first with a single root at index 0")
    depth = np.zeros(len(names), dtype=np.int64)
    for i in range(1, len(names)):
        depth[i] = depth[parents[i]] + 1
    levels = tuple(
        (np.flatnonzero(depth == d), parents[depth == d]) for d in range(1, int(depth.max()) + 1)
    )
    return Skeleton(
        names,
        parents,
        np.array([t[2] for t in table], dtype=np.float64),
        np.array([t[3] for t in table], dtype=np.float64),
        np.array([t[4] for t in table], dtype=np.float64),
        levels,
    )


SKELETON = make_skeleton()
DRUMMER = SKELETON
BASSIST = SKELETON
