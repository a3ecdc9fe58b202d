"""The upright bass's fingerboard for a tuning: as wide as its strings, tapering with them.

The strings of a bass spread from the nut to the bridge (E to G 30 mm apart
at the nut, 90 mm at the bridge; a five-string's low B and a six-string's high
C a further 9-20 mm outside them, :mod:`virja.geometry`).  The fingerboard
follows the strings of the tuning played: from the outermost string on each
side, ``margin_nut_m`` beyond it at the nut and ``margin_end_m`` at the
board's end, straight between (a trapezoid, wider on the side of a low B or a
high C).  The renderer (:mod:`virja.render.scene`), the glTF export and the
bassist's motion (the fretting wrist beside the board's low edge, the
collision checks of ``motion-report``) all take it from here.

Coordinates: :meth:`Fingerboard.coords` gives (along, lateral, face) in metres
from the centre of the middle four strings at the nut: ``along`` toward the
bridge, ``lateral`` toward the low (E, B) side, ``face`` out of the board
toward the strings.  The board's face lies ``face_m`` behind the line of the
strings' centres, the neck's back ``back_m`` behind it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from virja.geometry import UprightBass
from virja.vocab import BASS_STRINGS


@dataclass(frozen=True)
class BoardSpec:
    """How the fingerboard is made (m): its margins beyond the outer strings, where it ends
    (a share of the way from the nut to the bridge), its face and thickness, the neck's back."""

    margin_nut_m: float = 0.006
    margin_end_m: float = 0.012
    end_share: float = 0.78
    face_m: float = -0.006  # the strings stand 6 mm over it (an upright's action: 5-10 mm)
    thickness_m: float = 0.014
    back_m: float = -0.030


BOARD = BoardSpec()


@dataclass(frozen=True)
class Fingerboard:
    """The fingerboard of a tuning in the bass's own frame (see the module docstring).

    ``low`` and ``high``: the lateral place (m) of its low-side edge (> 0) and its
    high-side edge (< 0), each at the nut and at the board's end."""

    nut: np.ndarray  # (3,)
    along: np.ndarray
    lateral: np.ndarray
    face: np.ndarray
    length: float
    low: tuple[float, float]
    high: tuple[float, float]
    spec: BoardSpec = BOARD

    def coords(self, points: np.ndarray) -> np.ndarray:
        """(..., 3) -> (..., 3) (along, lateral, face) of points, m from the nut's centre."""
        rel = np.asarray(points, dtype=np.float64) - self.nut
        return np.stack([rel @ self.along, rel @ self.lateral, rel @ self.face], axis=-1)

    def low_edge(self, along: np.ndarray | float) -> np.ndarray:
        """The lateral place (m) of the low-side edge at ``along`` m from the nut (the
        straight edge carried on beyond the board's ends)."""
        u = np.asarray(along, dtype=np.float64) / self.length
        return np.asarray(self.low[0] + u * (self.low[1] - self.low[0]))

    def high_edge(self, along: np.ndarray | float) -> np.ndarray:
        """The lateral place (m, < 0) of the high-side edge at ``along`` m from the nut."""
        u = np.asarray(along, dtype=np.float64) / self.length
        return np.asarray(self.high[0] + u * (self.high[1] - self.high[0]))

    def width(self, along: np.ndarray | float) -> np.ndarray:
        return np.asarray(self.low_edge(along) - self.high_edge(along))

    def inside(self, points: np.ndarray) -> np.ndarray:
        """Which points (..., 3) lie inside the board or the neck behind it."""
        c = self.coords(points)
        return np.asarray(
            (c[..., 0] > 0.0)
            & (c[..., 0] < self.length)
            & (c[..., 1] < self.low_edge(c[..., 0]))
            & (c[..., 1] > self.high_edge(c[..., 0]))
            & (c[..., 2] < self.spec.face_m)
            & (c[..., 2] > self.spec.back_m)
        )

    def corners(self) -> np.ndarray:
        """(8, 3) the board's corners in the bass's frame: (nut, end) x (low, high) x
        (back, face), in that order of bits (i = 4 * end + 2 * high + face)."""
        out = np.empty((8, 3))
        for i in range(8):
            end, high, top = (i >> 2) & 1, (i >> 1) & 1, i & 1
            a = self.length * end
            lat = (self.high if high else self.low)[end]
            f = self.spec.face_m - (0.0 if top else self.spec.thickness_m)
            out[i] = self.nut + a * self.along + lat * self.lateral + f * self.face
        return out

    def pieces(self) -> np.ndarray:
        """(3, 4, 4) affine models of a unit box (centred, side 1) drawing the board exactly:
        three boxes sheared along the board (one by each edge, one by its centre line),
        each as wide as the board at the nut; together they fill the trapezoid as long as
        it is at most three times as wide at its end as at its nut."""
        w0 = self.low[0] - self.high[0]
        mid_face = self.spec.face_m - self.spec.thickness_m / 2
        out = np.tile(np.eye(4), (3, 1, 1))
        for k, (lat0, lat1) in enumerate(
            (
                (self.low[0] - w0 / 2, self.low[1] - w0 / 2),
                ((self.low[0] + self.high[0]) / 2, (self.low[1] + self.high[1]) / 2),
                (self.high[0] + w0 / 2, self.high[1] + w0 / 2),
            )
        ):
            a = self.nut + 0.5 * (lat0 + lat1) * self.lateral
            centre = a + 0.5 * self.length * self.along + mid_face * self.face
            out[k, :3, 0] = w0 * self.lateral
            out[k, :3, 1] = self.length * self.along + (lat1 - lat0) * self.lateral
            out[k, :3, 2] = self.spec.thickness_m * self.face
            out[k, :3, 3] = centre
        return out


_CACHE: dict[tuple[int, tuple[str, ...], BoardSpec], tuple[UprightBass, Fingerboard]] = {}


def fingerboard(
    bass: UprightBass, strings: tuple[str, ...] = BASS_STRINGS, spec: BoardSpec = BOARD
) -> Fingerboard:
    """The fingerboard under ``strings`` (the tuning's, low to high) of ``bass``."""
    key = (id(bass), tuple(strings), spec)
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is bass:
        return hit[1]
    unknown = [s for s in strings if s not in bass.nut]
    if unknown or not strings:
        raise ValueError(
            f"the bass has the strings {' '.join(bass.strings)}; got {' '.join(strings) or 'none'}"
        )
    four = [s for s in bass.strings if s in BASS_STRINGS]
    nut = np.mean([bass.nut[s] for s in four], axis=0)
    along = np.mean([bass.bridge[s] for s in four], axis=0) - nut
    length = spec.end_share * float(np.linalg.norm(along))
    along = along / np.linalg.norm(along)
    face = bass.front - np.dot(bass.front, along) * along
    face = face / np.linalg.norm(face)
    lateral = np.cross(face, along)
    # each string's lateral place at the nut and where the board ends
    lat = np.empty((len(strings), 2))
    for i, s in enumerate(strings):
        d = bass.string_dir(s)
        p0 = bass.nut[s] - nut
        t = (length - p0 @ along) / (d @ along)
        lat[i] = p0 @ lateral, (p0 + t * d) @ lateral
    margin = np.array([spec.margin_nut_m, spec.margin_end_m])
    low = lat.max(axis=0) + margin
    high = lat.min(axis=0) - margin
    board = Fingerboard(
        nut=nut,
        along=along,
        lateral=lateral,
        face=face,
        length=length,
        low=(float(low[0]), float(low[1])),
        high=(float(high[0]), float(high[1])),
        spec=spec,
    )
    _CACHE[key] = (bass, board)
    return board
