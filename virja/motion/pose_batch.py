"""``BandPoses``: the band at many instants, as arrays (what the render loops draw).

:meth:`virja.motion.band.BandAnimator.pose_batch` computes a chunk of frames at
once (the offline render a stretch of frames, the live window a few ahead);
:func:`virja.render.scene_batch.band_scenes` turns it into the frames'
instances without building a :class:`~virja.motion.pose.BandPose` per frame.
:meth:`BandPoses.pose` gives one frame as a ``BandPose`` for everything else.
Arrays are float64, indexed by frame first, and read-only for consumers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from virja.motion.pose import BandPose, FigurePose


@dataclass(frozen=True)
class BandPoses:
    """``m`` frames of the band (the fields of :class:`BandPose`, one row a frame).

    - ``times`` (m,); ``positions`` (m, 2, n, 3) and ``rotations`` (m, 2, n, 4): the
      [drums, bass] figures' world joints (``names``, ``parents``, ``radii`` per joint);
    - ``sticks`` (m, 2, 2, 3); ``hihat_open`` (m,);
    - ``cymbals`` / ``cymbal_swing`` (m, len(cymbals)), ``drums`` / ``head_hits``
      (m, len(drums)), ``strings`` / ``string_vibration`` and ``string_stops`` (int)
      (m, len(strings)): the mappings of ``BandPose`` as columns;
    - ``fretting_tip``, ``plucking_tip`` (m, 3); ``bass_fingers`` (m, k, 2, 3);
      ``bass_transform`` (m, 4, 4).
    """

    times: np.ndarray
    names: tuple[str, ...]
    parents: np.ndarray
    radii: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    sticks: np.ndarray
    hihat_open: np.ndarray
    cymbals: tuple[str, ...]
    cymbal_swing: np.ndarray
    drums: tuple[str, ...]
    head_hits: np.ndarray
    strings: tuple[str, ...]
    string_vibration: np.ndarray
    string_stops: np.ndarray
    fretting_tip: np.ndarray
    plucking_tip: np.ndarray
    bass_fingers: np.ndarray
    bass_transform: np.ndarray

    def __len__(self) -> int:
        return int(self.times.size)

    def pose(self, k: int) -> BandPose:
        """Frame ``k`` as a :class:`BandPose` (equal to ``BandAnimator.pose(times[k])``)."""
        p, r = self.positions[k], self.rotations[k]
        figs = [FigurePose(self.names, self.parents, p[i], r[i], self.radii) for i in range(2)]
        vib = self.string_vibration[k].tolist()
        stops = self.string_stops[k].tolist()
        return BandPose(
            time_s=float(self.times[k]),
            drums=figs[0],
            bass=figs[1],
            sticks=self.sticks[k],
            hihat_open=float(self.hihat_open[k]),
            cymbal_swing=dict(zip(self.cymbals, self.cymbal_swing[k].tolist(), strict=True)),
            head_hits=dict(zip(self.drums, self.head_hits[k].tolist(), strict=True)),
            string_vibration=dict(zip(self.strings, vib, strict=True)),
            string_stops={s: int(f) for s, f in zip(self.strings, stops, strict=True)},
            fretting_tip=self.fretting_tip[k],
            plucking_tip=self.plucking_tip[k],
            bass_fingers=self.bass_fingers[k],
            bass_transform=self.bass_transform[k],
        )

    def all(self) -> list[BandPose]:
        """Every frame as a :class:`BandPose`."""
        return [self.pose(k) for k in range(len(self))]


__all__ = ["BandPoses"]
