"""Generating motion for new music from a database (method B, steps 1-4).

1. Beats of the new music -> beat frames ``round(t * fps)`` -> beat intervals.
2. :func:`~virja.dance.intervals.correct_intervals` merges them to segment lengths.
3. Each corrected interval's music phrase (8 kHz) gets its AR(3) sound
   parameters; among segments with ``|span - interval| <= tolerance`` the
   one nearest in Euclidean distance of *standardised* sound parameters
   (each coefficient divided by its standard deviation over the database,
   so that a_1, whose spread is largest, does not decide alone) is chosen
   (ties: the earlier in the database).  A phrase whose AR fit fails is
   reported (``Generated.unfitted``) and gets, among the length-matched
   candidates, the one used least so far.
4. Joining: each chosen segment is stretched or compressed to the interval
   (rotations by slerp, the waist's position linearly, at ``span + 1``
   evenly spaced points).  At each join, per part, the ``h`` frames centred on
   it (``h / 2`` either side, clipped to the motion) are replaced by the
   paper's axis-angle interpolation: ``R1`` the posture where the window
   starts, ``R2`` where it ends, ``R1^-1 R2 = rot(theta, n)``, frame ``l`` is
   ``R1 rot(l theta / h, n)``.  ``h = 2 * shortest segment span`` (paper),
   never below ``MIN_H = 10`` (the paper's shortest segment is 5 frames;
   ``teach`` keeps segments of at least ``MIN_SPAN`` frames).
   Joins are smoothed in order, each reading the output so far.  The waist's
   position is kept as increments in the waist's own frame and re-accumulated
   with the smoothed waist rotation (paper; no foot-skate correction).  Known
   consequence: the height drifts by the difference of waist heights at each
   join (docs/dance.md).

Before the first beat the first chosen segment's first pose is held; the
motion ends on the last beat.  Output: a :class:`~virja.motion.bvh.Bvh` on
the database's skeleton.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.dance.ar import ARFitError, sound_parameters
from virja.dance.audio import ANALYSIS_RATE_HZ, FloatArray
from virja.dance.beats import extract_beats
from virja.dance.database import DanceDatabase, DanceError, Segment
from virja.dance.intervals import CorrectedInterval, correct_intervals
from virja.motion.bvh import Bvh

log = logging.getLogger(__name__)

MIN_H = 10
"""Smallest join window: twice the paper's shortest segment (5 frames)."""


@dataclass(frozen=True)
class Generated:
    """A generated dance: the ``bvh``, the corrected ``intervals``, the chosen
    segment index for each, and the output frames where segments join."""

    bvh: Bvh
    beats_s: tuple[float, ...]
    intervals: tuple[CorrectedInterval, ...]
    choices: tuple[int, ...]
    joins: tuple[int, ...]
    h: int = MIN_H
    unfitted: tuple[int, ...] = ()
    """Indices of intervals whose phrase could not be fitted (chosen by length only)."""

    @property
    def distinct(self) -> int:
        """How many different database segments the dance uses."""
        return len(set(self.choices))

    @property
    def most_reused(self) -> int:
        """The largest number of times one segment is used."""
        return max(self.choices.count(c) for c in set(self.choices)) if self.choices else 0

    @property
    def interpolated_share(self) -> float:
        """Share of output frames inside some join window (replaced by interpolation)."""
        n = self.bvh.n_frames
        mask = np.zeros(n, dtype=bool)
        for c in self.joins:
            mask[max(0, c - self.h // 2) : min(n, c + self.h // 2 + 1)] = True
        return float(mask.mean()) if n else 0.0

    def summary(self) -> str:
        """One line: segments, distinct ones, the most reused, interpolated share."""
        exact = sum(1 for iv in self.intervals if iv.tolerance == 0)
        return (
            f"{len(self.intervals)} segments ({exact} exact lengths), {self.distinct} distinct, "
            f"most used {self.most_reused}x, {100 * self.interpolated_share:.0f} % of frames "
            f"in join windows (h = {self.h})"
            + (f", {len(self.unfitted)} phrase(s) not fitted" if self.unfitted else "")
        )


def sound_scale(db: DanceDatabase) -> FloatArray:
    """Per-coefficient standard deviation of the database's sound parameters (1 where flat)."""
    sounds = np.array([s.sound for s in db.segments], dtype=np.float64)
    sd = sounds.std(axis=0) if len(sounds) > 1 else np.ones(sounds.shape[1])
    return np.where(sd > 1e-12, sd, 1.0)


def length_candidates(db: DanceDatabase, interval: CorrectedInterval) -> list[int]:
    """Indices of segments within ``span +- tolerance`` (closest lengths if none)."""
    cands = [
        i for i, s in enumerate(db.segments) if abs(s.span - interval.span) <= interval.tolerance
    ]
    if not cands:  # cannot happen for intervals made from db.spans; kept as a guard
        best = min(abs(s.span - interval.span) for s in db.segments)
        cands = [i for i, s in enumerate(db.segments) if abs(s.span - interval.span) == best]
    return cands


def choose_segment(
    db: DanceDatabase,
    interval: CorrectedInterval,
    sound: FloatArray,
    scale: FloatArray | None = None,
) -> int:
    """Index of the segment within ``span +- tolerance`` nearest to ``sound``.

    Distances are taken on sound parameters divided by ``scale`` (default
    :func:`sound_scale` of ``db``).
    """
    cands = length_candidates(db, interval)
    sc = sound_scale(db) if scale is None else scale
    dists = [float(np.linalg.norm((db.segments[i].sound - sound) / sc)) for i in cands]
    return cands[int(np.argmin(dists))]


def stretch(segment: Segment, span: int) -> tuple[FloatArray, FloatArray]:
    """(span + 1, n_joints, 4) rotations and (span + 1, 3) waist positions of ``segment``
    resampled to ``span`` frames (the ends stay the ends)."""
    u = np.linspace(0.0, float(segment.span), span + 1)
    i0 = np.minimum(np.floor(u).astype(np.int64), segment.span - 1)
    frac = u - i0
    rot = quat.slerp(segment.rotations[i0], segment.rotations[i0 + 1], frac[:, None])
    pos = (
        segment.root_positions[i0] * (1 - frac[:, None])
        + segment.root_positions[i0 + 1] * frac[:, None]
    )
    return rot, pos


def smooth_join(rotations: FloatArray, centre: int, h: int) -> None:
    """Replace, in place, frames ``centre - h/2 .. centre + h/2`` by the axis-angle interpolation."""
    n = rotations.shape[0]
    lo = max(0, centre - h // 2)
    hi = min(n - 1, centre + h // 2)
    width = hi - lo
    if width < 2:
        return
    r1 = rotations[lo]
    r2 = rotations[hi]
    axis, theta = quat.to_axis_angle(quat.multiply(quat.conjugate(r1), r2))  # short way round
    ls = np.arange(width + 1, dtype=np.float64)[:, None]
    step = quat.from_axis_angle(
        np.broadcast_to(axis, (width + 1, *axis.shape)), ls * theta[None, :] / width
    )
    rotations[lo : hi + 1] = quat.normalize(quat.multiply(r1[None], step))


def generate(
    db: DanceDatabase,
    audio_8k: FloatArray,
    beats_s: Sequence[float] | None = None,
    h: int | None = None,
    random_choice: np.random.Generator | None = None,
) -> Generated:
    """Motion for music ``audio_8k`` (mono, 8 kHz) from ``db``; ``beats_s`` default: extracted.

    ``random_choice``: the evaluation's control -- each segment is drawn at
    random among the length-matched candidates instead of by sound.
    """
    if not db.segments:
        raise DanceError("the database has no segments")
    audio = np.asarray(audio_8k, dtype=np.float64)
    beats = np.asarray(extract_beats(audio) if beats_s is None else beats_s, dtype=np.float64)
    fps = db.fps
    frames = np.unique(np.round(beats * fps).astype(np.int64))
    frames = frames[frames >= 0]
    if frames.size < 2:
        raise DanceError(f"the music has {frames.size} beat(s); at least 2 are needed to dance")
    spans = np.diff(frames).tolist()
    intervals = correct_intervals(spans, db.spans)
    h = max(2 * min(db.spans), MIN_H) if h is None else int(h)
    scale = sound_scale(db)
    unfitted: list[int] = []

    pieces_rot: list[FloatArray] = []
    pieces_inc: list[FloatArray] = []
    choices: list[int] = []
    joins: list[int] = []
    root = db.root
    at = int(frames[0])
    for n_iv, iv in enumerate(intervals):
        lo = int(round(frames[iv.first] / fps * ANALYSIS_RATE_HZ))
        hi = int(round(frames[iv.last + 1] / fps * ANALYSIS_RATE_HZ))
        phrase = audio[lo:hi]
        try:
            if random_choice is not None:
                k = int(random_choice.choice(length_candidates(db, iv)))
            else:
                k = choose_segment(db, iv, sound_parameters(phrase), scale)
        except ARFitError as exc:  # reported, never a made-up sound
            log.warning(
                "phrase %d (%.2f-%.2f s) not fitted (%s); segment chosen by length",
                n_iv,
                lo / ANALYSIS_RATE_HZ,
                hi / ANALYSIS_RATE_HZ,
                exc,
            )
            unfitted.append(n_iv)
            k = min(length_candidates(db, iv), key=choices.count)
        choices.append(k)
        rot, pos = stretch(db.segments[k], iv.span)
        inc_world = np.diff(pos, axis=0)
        inc_local = quat.rotate(quat.conjugate(rot[:-1, root]), inc_world)
        if pieces_rot:
            joins.append(at)
        pieces_rot.append(rot[:-1])
        pieces_inc.append(inc_local)
        at += iv.span
    last_seg = db.segments[choices[-1]]
    last_rot = stretch(last_seg, intervals[-1].span)[0]
    lead = int(frames[0])
    first_rot, first_pos = stretch(db.segments[choices[0]], intervals[0].span)
    rotations = np.concatenate([np.repeat(first_rot[:1], lead, axis=0), *pieces_rot, last_rot[-1:]])
    increments = np.concatenate([np.zeros((lead, 3)), *pieces_inc])
    for c in joins:
        smooth_join(rotations, c, h)
    n = rotations.shape[0]
    world_inc = quat.rotate(rotations[:-1, root], increments)
    root_pos = first_pos[0] + np.concatenate([np.zeros((1, 3)), np.cumsum(world_inc, axis=0)])
    offsets = np.array([j.offset for j in db.joints], dtype=np.float64)
    positions = np.broadcast_to(offsets, (n, len(db.joints), 3)).copy()
    positions[:, root] = root_pos
    bvh = Bvh(list(db.joints), 1.0 / fps, rotations, positions, source="<generated>")
    return Generated(
        bvh,
        tuple(float(b) for b in beats),
        tuple(intervals),
        tuple(choices),
        tuple(joins),
        h,
        tuple(unfitted),
    )
