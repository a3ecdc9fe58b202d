"""The band's frames a chunk at a time: what the render loops draw.

Posing the band one frame at a time costs numpy's overhead per call many times
a frame (the drummer's and the bassist's bodies, the kit, the strings);
:meth:`~virja.motion.band.BandAnimator.pose_batch` and
:func:`~virja.render.scene_batch.band_scenes` spread it over many frames.
:class:`FrameChunks` keeps the scenes (and poses) of the frame times a loop
will ask for next, computed in one batch, and throws them away whenever the
animator is told something new (:meth:`FrameChunks.invalidate`): a pose is
always the one the animator would give at that moment, so a note that arrives
late is never missed.  The offline render (:mod:`virja.render.offline`) asks
for the stretch of frames until the animator's next news; the live window
(:mod:`virja.live.frames`) a few frames ahead.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from virja.geometry import GEOMETRY, Geometry
from virja.motion.pose import BandPose
from virja.motion.pose_batch import BandPoses
from virja.render.renderer import DrawList
from virja.render.scene_batch import band_scenes


class BatchAnimator(Protocol):
    """What :class:`FrameChunks` needs of an animator (a ``BandAnimator``)."""

    def pose_batch(self, times: np.ndarray) -> BandPoses: ...


class FrameChunks:
    """Poses and scenes of ``animator`` for frame times prepared a chunk at a time.

    ``prepare(times)`` computes a chunk (times ascending); ``scene(t)`` and
    ``frame(t)`` return a prepared frame, or compute ``t`` alone when it was not
    prepared.  ``chunks`` and ``frames`` count what was computed, ``served`` what
    was asked, ``pose_s`` and ``scene_s`` the seconds spent posing and building
    instances (``virja bench``'s pose_ms and pose_scene_ms).
    """

    def __init__(self, animator: BatchAnimator, geo: Geometry = GEOMETRY) -> None:
        self.animator = animator
        self.geo = geo
        self._index: dict[float, int] = {}
        self._batch: BandPoses | None = None
        self._scenes: list[DrawList] = []
        self.chunks = 0
        self.frames = 0
        self.served = 0
        self.pose_s = 0.0
        self.scene_s = 0.0

    def invalidate(self) -> None:
        """The animator learnt something: every prepared frame is thrown away."""
        self._index = {}
        self._batch = None
        self._scenes = []

    def has(self, t: float) -> bool:
        return t in self._index

    def prepare(self, times: Sequence[float]) -> None:
        """Compute the frames at ``times`` (ascending) now, replacing the chunk held."""
        ts = np.asarray(times, dtype=np.float64)
        a = time.perf_counter()
        self._batch = self.animator.pose_batch(ts)
        b = time.perf_counter()
        self._scenes = band_scenes(self._batch, self.geo)
        self.pose_s += b - a
        self.scene_s += time.perf_counter() - b
        self._index = {t: k for k, t in enumerate(ts.tolist())}
        self.chunks += 1
        self.frames += ts.size

    def _at(self, t: float) -> int:
        k = self._index.get(t)
        if k is None:
            self.prepare([t])
            k = 0
        self.served += 1
        return k

    def scene(self, t: float) -> DrawList:
        """The moving band's instances at ``t`` (``band_scene(animator.pose(t))``)."""
        return self._scenes[self._at(t)]

    def frame(self, t: float) -> tuple[BandPose, DrawList]:
        """The pose at ``t`` and its instances."""
        k = self._at(t)
        assert self._batch is not None
        return self._batch.pose(k), self._scenes[k]


__all__ = ["BatchAnimator", "FrameChunks"]
