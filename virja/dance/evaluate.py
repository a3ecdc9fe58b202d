"""Objective scores for generated dance (the paper names one as future work).

Beat alignment ("BeatAlign" of AIST++, Li et al. 2021, in the corrected
form of Bailando, Siyao et al. 2022): motion beats are the local minima of
the mean joint speed (world positions by forward kinematics, speed smoothed
by a Gaussian of ``smooth_frames`` = 2 frames); the score is the mean *over
music beats* of ``exp(-d^2 / (2 sigma^2))``, ``d`` the distance from the
music beat to the nearest motion beat, ``sigma = 0.05 s``.  Averaging over
music beats means a motion with many small speed minima cannot score by
having one near every beat by chance less than a motion that rests on each
beat; it is read beside controls (``tools/dance_eval.py``): the same motion
against beats shifted by half a beat, a dance of randomly chosen
length-matched segments, and the teacher's own capture.

Style: :func:`motion_features` describes windows of motion (posture of every
joint relative to the waist, joint speeds, joint accelerations);
:func:`feature_distance` is a Fréchet distance between two sets of windows,
each summarised by the per-feature mean and standard deviation, on features
standardised by a reference set.  Measured against a *held-out* capture of
the teacher (not the one the database was cut from) and against held-out
captures of the other teachers, it asks whether the dance moves like its
teacher rather than whether it copies the database.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.ndimage import gaussian_filter1d

from virja import quat
from virja.dance.audio import FloatArray
from virja.dance.segment import local_minima
from virja.motion.bvh import Bvh
from virja.motion.bvh import world_pose as bvh_world_pose

BEAT_SIGMA_S = 0.05
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
    """Mean over music beats of exp(-d^2 / (2 sigma^2)), d to the nearest motion beat; 0 if none."""
    m = np.asarray(motion_beats_s, dtype=np.float64)
    b = np.asarray(music_beats_s, dtype=np.float64)
    if m.size == 0 or b.size == 0:
        return 0.0
    d = np.min(np.abs(b[:, None] - m[None, :]), axis=1)
    return float(np.mean(np.exp(-(d**2) / (2 * sigma_s**2))))


def beat_align_bvh(
    bvh: Bvh, music_beats_s: Sequence[float], sigma_s: float = BEAT_SIGMA_S
) -> float:
    """:func:`beat_align` of a motion's own beats (in seconds) against music beats
    (those within the motion's time span)."""
    span = (bvh.n_frames - 1) * bvh.frame_time_s
    beats = [b for b in music_beats_s if 0.0 <= b <= span]
    return beat_align((motion_beats(bvh) * bvh.frame_time_s).tolist(), beats, sigma_s)


def motion_features(bvh: Bvh, window: int = WINDOW_FRAMES, hop: int = WINDOW_HOP) -> FloatArray:
    """(n_windows, 5 * n_joints) features of windows of ``window`` frames, ``hop`` apart.

    Per joint: its mean position relative to the waist, in the waist's
    heading frame (3), its mean speed and its mean acceleration magnitude
    (file units per second, per second squared).  Posture, tempo of motion
    and sharpness, all invariant to where on the floor and which way round
    the dancer stands.
    """
    pos, rot = bvh_world_pose(bvh)
    root = next(i for i, j in enumerate(bvh.joints) if j.parent < 0)
    fwd = quat.rotate(rot[:, root], np.array([0.0, 0.0, 1.0]))
    heading = np.arctan2(fwd[:, 0], fwd[:, 2])
    unturn = quat.from_axis_angle(
        np.broadcast_to(np.array([0.0, 1.0, 0.0]), (len(heading), 3)), -heading
    )
    rel = quat.rotate(unturn[:, None, :], pos - pos[:, root : root + 1])
    fps = 1.0 / bvh.frame_time_s
    vel = np.gradient(pos, axis=0) * fps
    acc = np.gradient(vel, axis=0) * fps
    speed = np.linalg.norm(vel, axis=-1)
    accel = np.linalg.norm(acc, axis=-1)
    n = bvh.n_frames
    rows = []
    for s0 in range(0, max(n - window, 0) + 1, hop):
        sl = slice(s0, s0 + window)
        rows.append(
            np.concatenate(
                [rel[sl].mean(axis=0).ravel(), speed[sl].mean(axis=0), accel[sl].mean(axis=0)]
            )
        )
    return np.asarray(rows, dtype=np.float64)


def feature_distance(a: FloatArray, b: FloatArray, reference: FloatArray) -> float:
    """Fréchet distance of two sets of feature rows, diagonal Gaussians, per feature.

    Features are standardised by ``reference`` (mean, std per column; flat
    columns dropped); the distance is ``mean over features of
    (mu_a - mu_b)^2 + (sd_a - sd_b)^2``: 0 for the same distribution, 2 for
    two sets one reference standard deviation apart in every feature.
    """
    ref = np.asarray(reference, dtype=np.float64)
    sd = ref.std(axis=0)
    keep = sd > 1e-9 * max(1.0, float(np.abs(ref).max()))
    za = (np.asarray(a)[:, keep] - ref.mean(axis=0)[keep]) / sd[keep]
    zb = (np.asarray(b)[:, keep] - ref.mean(axis=0)[keep]) / sd[keep]
    d = (za.mean(axis=0) - zb.mean(axis=0)) ** 2 + (za.std(axis=0) - zb.std(axis=0)) ** 2
    return float(d.mean())
