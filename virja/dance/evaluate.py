"""Objective scores for generated dance (the paper names one as future work).

Beat alignment (as AIST++ "BeatAlign", Li et al. 2021): motion beats are the
local minima of the mean joint speed (world positions by forward kinematics,
speed smoothed by a Gaussian of ``smooth_frames`` = 2 frames); the score is
the mean over motion beats of ``exp(-d^2 / (2 sigma^2))``, ``d`` the distance to
the nearest music beat and ``sigma = 0.1 s`` (3 frames at 30 fps, AIST++'s
value in frames).  1 = every motion beat on a music beat.

Style inheritance: a nearest-centroid classifier on motion features
(:func:`style_features`: per window of 60 frames, hop 30, the mean and the
standard deviation of each joint's rotation vector, the log of its local
rotation, and of the waist's height), standardised by the training set.
Trained on the teachers' captures, it labels windows of generated motion;
:func:`style_accuracy` is the fraction labelled with the teacher whose
database generated them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

from virja.dance.audio import FloatArray
from virja.dance.segment import local_minima
from virja.motion import quat
from virja.motion.bvh import Bvh
from virja.motion.bvh import world_pose as bvh_world_pose

BEAT_SIGMA_S = 0.1
SPEED_SMOOTH_FRAMES = 2.0
WINDOW_FRAMES = 60
WINDOW_HOP = 30


def world_positions(bvh: Bvh) -> FloatArray:
    """(n_frames, n_joints, 3) world positions of every joint (file units)."""
    return bvh_world_pose(bvh)[0]


def motion_beats(bvh: Bvh, smooth_frames: float = SPEED_SMOOTH_FRAMES) -> FloatArray:
    """Frames of the local minima of the (smoothed) mean joint speed."""
    pos = world_positions(bvh)
    speed = np.linalg.norm(np.diff(pos, axis=0), axis=-1).mean(axis=1)
    if smooth_frames > 0:
        speed = gaussian_filter1d(speed, smooth_frames)
    return local_minima(speed).astype(np.float64) + 0.5  # speed i is between frames i and i+1


def beat_align(
    motion_beats_s: Sequence[float], music_beats_s: Sequence[float], sigma_s: float = BEAT_SIGMA_S
) -> float:
    """Mean over motion beats of exp(-min distance^2 / (2 sigma^2)); 0 with no motion beats."""
    m = np.asarray(motion_beats_s, dtype=np.float64)
    b = np.asarray(music_beats_s, dtype=np.float64)
    if m.size == 0 or b.size == 0:
        return 0.0
    d = np.min(np.abs(m[:, None] - b[None, :]), axis=1)
    return float(np.mean(np.exp(-(d**2) / (2 * sigma_s**2))))


def beat_align_bvh(
    bvh: Bvh, music_beats_s: Sequence[float], sigma_s: float = BEAT_SIGMA_S
) -> float:
    """:func:`beat_align` of a motion's own beats (in seconds) against music beats."""
    return beat_align((motion_beats(bvh) * bvh.frame_time_s).tolist(), music_beats_s, sigma_s)


def style_features(bvh: Bvh, window: int = WINDOW_FRAMES, hop: int = WINDOW_HOP) -> FloatArray:
    """(n_windows, 6 * n_joints + 2) features, one row per window of ``window`` frames."""
    axis, ang = quat.to_axis_angle(quat.normalize(bvh.rotations))
    rv = (axis * ang[..., None]).reshape(bvh.n_frames, -1)
    root = next(i for i, j in enumerate(bvh.joints) if j.parent < 0)
    height = bvh.positions[:, root, 1:2]
    x = np.concatenate([rv, height], axis=1)
    rows = [
        np.concatenate([x[s : s + window].mean(axis=0), x[s : s + window].std(axis=0)])
        for s in range(0, max(bvh.n_frames - window, 0) + 1, hop)
    ]
    return np.asarray(rows, dtype=np.float64)


@dataclass(frozen=True)
class NearestCentroid:
    """A nearest-centroid classifier on standardised features."""

    labels: tuple[str, ...]
    centroids: FloatArray
    mean: FloatArray
    scale: FloatArray

    @classmethod
    def fit(cls, data: Mapping[str, FloatArray]) -> NearestCentroid:
        labels = tuple(sorted(data))
        allx = np.concatenate([data[k] for k in labels])
        mean = allx.mean(axis=0)
        scale = allx.std(axis=0)
        scale = np.where(scale > 1e-12, scale, 1.0)
        cents = np.stack([((data[k] - mean) / scale).mean(axis=0) for k in labels])
        return cls(labels, cents, mean, scale)

    def predict(self, x: FloatArray) -> list[str]:
        z = (np.asarray(x) - self.mean) / self.scale
        d = np.linalg.norm(z[:, None, :] - self.centroids[None, :, :], axis=-1)
        return [self.labels[i] for i in np.argmin(d, axis=1)]


@dataclass(frozen=True)
class StyleReport:
    """Accuracy overall and per teacher, and the confusion counts (true -> predicted -> n)."""

    accuracy: float
    per_teacher: dict[str, float]
    confusion: dict[str, dict[str, int]]


def style_accuracy(teachers: Mapping[str, Bvh], generated: Mapping[str, Bvh]) -> StyleReport:
    """Train on ``teachers``' captures, label windows of each ``generated[teacher]`` motion."""
    clf = NearestCentroid.fit({k: style_features(v) for k, v in teachers.items()})
    confusion: dict[str, dict[str, int]] = {}
    per: dict[str, float] = {}
    hits = total = 0
    for label, bvh in generated.items():
        pred = clf.predict(style_features(bvh))
        confusion[label] = {k: pred.count(k) for k in clf.labels}
        per[label] = pred.count(label) / len(pred) if pred else 0.0
        hits += pred.count(label)
        total += len(pred)
    return StyleReport(hits / total if total else 0.0, per, confusion)
