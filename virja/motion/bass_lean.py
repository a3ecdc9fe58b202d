"""The upright bass leaning with its player.

An upright bass stands on its endpin and rests against the player's belly: as
he shifts his weight from foot to foot and dips on the beat
(:mod:`virja.motion.bassist`), the instrument goes with him a little.  The lean
is a rotation about the endpin's tip (which stays on the floor) that carries
the bass's contact point (the back of its upper bout) ``follow`` of the way
the player's chest moved from where it stands at rest, across the line from
the endpin to that point.  Chest displacements are a centimetre or two, so the
lean is a few tenths of a degree: about 1 cm at the nut.

Both hands go with the lean exactly (the arms are solved to the leaned
targets, :meth:`virja.motion.bassist.Bassist.body`), so the fingers stay on
their strings; everything of the instrument is drawn through
``BandPose.bass_transform`` (:func:`matrix`): body, neck, fingerboard, strings
(:mod:`virja.render.scene`, the web view's frames) and the glTF node
``bass_instrument`` (:mod:`virja.export.gltf`).

Pure, vectorised over any leading axes.
"""

from __future__ import annotations

import numpy as np

from virja import quat
from virja.geometry import UprightBass


def contact_point(bass: UprightBass) -> np.ndarray:
    """(3,) where the bass rests against the player: the back of its upper bout."""
    return np.asarray(
        bass.body_centre + 0.28 * bass.axis - 0.5 * bass.body_depth * bass.front,
        dtype=np.float64,
    )


def lean(chest: np.ndarray, rest_chest: np.ndarray, bass: UprightBass, follow: float) -> np.ndarray:
    """Rotations (..., 4) w x y z of the bass about its endpin for the player's chest at
    ``chest`` (..., 3), which stands at ``rest_chest`` (3,) when he stands still."""
    r = contact_point(bass) - np.asarray(bass.endpin, dtype=np.float64)
    r2 = float(r @ r)
    d = follow * (np.asarray(chest, dtype=np.float64) - np.asarray(rest_chest, dtype=np.float64))
    d = d - (d @ r)[..., None] * r / r2  # along the bass it cannot follow (the endpin holds)
    # rotation vector: the contact point moves by w x r = d
    w = quat.cross(np.broadcast_to(r, d.shape), d) / r2
    angle = np.linalg.norm(w, axis=-1)
    axis = np.where(angle[..., None] > 1e-12, w, np.array([1.0, 0.0, 0.0]))
    return quat.from_axis_angle(axis / np.linalg.norm(axis, axis=-1, keepdims=True), angle)


def matrix(q: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(..., 4, 4) world transforms rotating by ``q`` (..., 4) about ``pivot`` (3,)."""
    r = quat.to_matrix(np.asarray(q, dtype=np.float64))
    m = np.zeros(r.shape[:-2] + (4, 4))
    m[..., :3, :3] = r
    p = np.asarray(pivot, dtype=np.float64)
    m[..., :3, 3] = p - r @ p
    m[..., 3, 3] = 1.0
    return m


def apply(m: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (..., 3) moved by the transform ``m`` (4, 4)."""
    p = np.asarray(points, dtype=np.float64)
    return p @ m[:3, :3].T + m[:3, 3]


def inverse(m: np.ndarray) -> np.ndarray:
    """The inverse of a rigid transform (4, 4)."""
    out = np.eye(4)
    out[:3, :3] = m[:3, :3].T
    out[:3, 3] = -m[:3, :3].T @ m[:3, 3]
    return out


__all__ = ["apply", "contact_point", "inverse", "lean", "matrix"]
