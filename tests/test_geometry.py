"""The kit's layout (virja.geometry): crash 2 on the right, clear of what is around it."""

from __future__ import annotations

import numpy as np

from virja.geometry import GEOMETRY, Cymbal, Drum

KIT = GEOMETRY.kit
O = GEOMETRY.stage.drummer_origin


def _disc_points(c: Cymbal, n: int = 64) -> np.ndarray:
    """Points on the cymbal's rim and halfway in, (2n, 3)."""
    a = np.cross(c.normal, [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    b = np.cross(c.normal, a)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)[:, None]
    ring = np.cos(t) * a + np.sin(t) * b
    return np.concatenate([c.centre + c.radius * ring, c.centre + 0.5 * c.radius * ring])


def _inside_drum(d: Drum, p: np.ndarray) -> bool:
    rel = p - d.centre
    along = float(np.dot(rel, d.normal))  # 0 at the head, -depth at the back
    radial = float(np.linalg.norm(rel - along * d.normal))
    return -d.depth - 0.01 <= along <= 0.01 and radial <= d.radius + 0.02


def test_crash2_hangs_on_the_right_higher_than_the_ride() -> None:
    c2, ride, crash = KIT.pieces["crash2"], KIT.pieces["ride"], KIT.pieces["crash"]
    assert isinstance(c2, Cymbal) and isinstance(ride, Cymbal)
    # the drummer's right is -x; between the rack toms and the ride, over the low tom
    assert ride.centre[0] < c2.centre[0] < KIT.pieces["tom_high"].centre[0]
    assert c2.centre[0] < 0 < crash.centre[0] - O[0]
    assert c2.centre[1] - ride.centre[1] >= 0.15  # higher than the ride
    assert 0.22 <= c2.radius <= 0.24  # an 18" crash


def test_crash2_is_clear_of_the_ride_and_the_drums() -> None:
    c2 = KIT.pieces["crash2"]
    assert isinstance(c2, Cymbal)
    pts = _disc_points(c2)
    for name in KIT.pieces:
        if name == "crash2":
            continue
        gap = min(KIT.surface_distance(name, p) for p in pts)
        assert gap > 0.10, (name, gap)  # a stick plays between
    # the ride's and the low tom's strike points lie outside crash 2's footprint seen
    # from above: a stick going down to them never passes under it
    for name in ("ride", "tom_low", "tom_high", "tom_floor"):
        flat = (KIT.strike_point(name) - c2.centre)[[0, 2]]
        assert float(np.linalg.norm(flat)) > c2.radius + 0.02, name


def test_every_stand_stays_out_of_the_drums() -> None:
    for name, piece in KIT.pieces.items():
        if not isinstance(piece, Cymbal):
            continue
        path = piece.stand()
        assert path[0][1] == 0.0  # on the floor
        for a, b in zip(path[:-1], path[1:], strict=True):
            for u in np.linspace(0.0, 1.0, 50):
                p = a + u * (b - a)
                for other, drum in KIT.pieces.items():
                    if isinstance(drum, Drum):
                        assert not _inside_drum(drum, p), (name, other, p)
    assert len(KIT.pieces["crash2"].stand()) == 3  # mast and boom
