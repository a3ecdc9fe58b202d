"""Export a performance as BVH: both players' skeletons sampled at a fixed rate.

``performance_to_bvh(animator, t0, t1, fps, path)`` writes one BVH per figure
(``<stem>_drums.bvh`` and ``<stem>_bass.bvh``; a BVH holds a single root),
frames at ``t0 + i / fps`` exactly, joints named as in
:data:`virja.motion.skeleton.SKELETON`, metres, y up, Euler ZXY degrees.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from virja.motion.band import FIGURES, BandAnimator
from virja.motion.bvh import Bvh, BvhJoint, write_bvh
from virja.motion.skeleton import SKELETON


def skeleton_joints() -> list[BvhJoint]:
    """BVH joints of the project skeleton (the root with position channels)."""
    out = []
    for i, name in enumerate(SKELETON.names):
        ch: tuple[str, ...] = ("Zrotation", "Xrotation", "Yrotation")
        if i == 0:
            ch = ("Xposition", "Yposition", "Zposition", *ch)
        off = SKELETON.offsets[i]
        out.append(
            BvhJoint(
                name, int(SKELETON.parents[i]), (float(off[0]), float(off[1]), float(off[2])), ch
            )
        )
    return out


def bvh_paths(path: str | Path) -> list[Path]:
    """The files :func:`performance_to_bvh` writes for ``path``: one per figure."""
    p = Path(path)
    stem = p.with_suffix("") if p.suffix.lower() == ".bvh" else p
    return [stem.parent / f"{stem.name}_{fig}.bvh" for fig in FIGURES]


def performance_to_bvh(
    animator: BandAnimator,
    t0: float,
    t1: float,
    fps: float,
    path: str | Path,
    local: np.ndarray | None = None,
) -> list[Path]:
    """Sample [t0, t1] at ``fps`` and write ``<stem>_drums.bvh`` and ``<stem>_bass.bvh``.

    Returns the paths written.  ``path`` may end in ``.bvh`` or not.  ``local``:
    the animator's ``local_rotations_many`` of exactly those frame times, if the
    caller has them already.
    """
    if not fps > 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    if t1 < t0:
        raise ValueError(f"end {t1} before start {t0}")
    n = int(np.floor((t1 - t0) * fps + 1e-9)) + 1
    loc = animator.local_rotations_many(t0 + np.arange(n) / fps) if local is None else local
    if loc.shape[0] != n:
        raise ValueError(f"local has {loc.shape[0]} frames, [t0, t1] at {fps} fps has {n}")
    joints = skeleton_joints()
    written = []
    for fi, (fig, out) in enumerate(zip(FIGURES, bvh_paths(path), strict=True)):
        pos = np.broadcast_to(SKELETON.offsets, (n, SKELETON.n_joints, 3)).copy()
        pos[:, 0] = animator.idle[fig].root_positions[0]
        write_bvh(Bvh(joints, 1.0 / fps, loc[:, fi], pos), out)
        written.append(out)
    return written
