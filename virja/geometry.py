"""Instrument and stage geometry as data: what the renderer draws and motions aim at.

World frame: metres, **y up**, the audience at **+z**, the stage floor at
``y = 0``.  Both players face +z, so a player's *left* is **+x**.  The
drummer sits on the left of the stage as the audience sees it (x < 0), the
bassist stands on the right (x > 0).

Drums: every piece is a :class:`Drum` (a cylinder: ``centre`` of the batter
head, unit ``normal`` pointing out of the head, ``radius``, ``depth``) or a
:class:`Cymbal` (a disc: ``centre``, ``normal`` up out of the top face,
``radius``, ``thickness``); strokes land on :meth:`DrumKit.strike_point`.
Pedals are :class:`Pedal` (heel point, footboard direction, length).

Bass: an upright bass; strings run from the nut to the bridge.  The neck has
room for six: the four-string E A D G in the middle, a low B beside the E and a
high C beside the G (``virja.vocab.ALL_BASS_STRINGS``); a figure plays and is drawn
with the strings of its tuning (``virja.vocab.BASS_STRINGS``, the four, by default);
:meth:`UprightBass.string_point` is where a finger stops a string at a fret
(equal-temperament distance ``scale * (1 - 2**(-fret/12))`` from the nut),
:meth:`UprightBass.pluck_point` where the right hand plucks.

Everything is plain numpy; ``GEOMETRY`` is the one instance the project uses.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from virja.vocab import ALL_BASS_STRINGS, OPEN_STRING_NOTES

Vec = np.ndarray  # (3,) float64, metres


def _v(x: float, y: float, z: float) -> Vec:
    return np.array([x, y, z], dtype=np.float64)


def _unit(v: Vec) -> Vec:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class Drum:
    """A drum: batter-head ``centre`` (3,), unit head ``normal`` (3,), ``radius``, ``depth`` (m)."""

    name: str
    centre: Vec
    normal: Vec
    radius: float
    depth: float


@dataclass(frozen=True)
class Cymbal:
    """A cymbal disc: ``centre`` (3,), unit ``normal`` (3,) out of the top, ``radius``, ``thickness``."""

    name: str
    centre: Vec
    normal: Vec
    radius: float
    thickness: float = 0.004
    # a boom stand: the top of its mast (3,), which stands on the floor below it, the
    # boom reaching from there to under the cymbal; None: a straight stand under it
    boom: Vec | None = None

    def stand(self) -> tuple[Vec, ...]:
        """The stand as a path from the floor to under the cymbal: two points (a
        straight stand), or three (mast and boom)."""
        top = self.centre - 0.02 * self.normal
        if self.boom is None:
            return (_v(self.centre[0], 0.0, self.centre[2]), top)
        return (_v(self.boom[0], 0.0, self.boom[2]), np.asarray(self.boom, dtype=np.float64), top)


@dataclass(frozen=True)
class Pedal:
    """A foot pedal: ``heel`` (3,) on the floor, unit ``board`` direction heel->toe at rest
    (raised), ``pressed_board`` when pressed, board ``length`` (m)."""

    name: str
    heel: Vec
    board: Vec
    pressed_board: Vec
    length: float

    def toe_point(self, pressed: bool) -> Vec:
        """Where the ball of the foot rests on the board (3/4 of its length from the heel)."""
        d = self.pressed_board if pressed else self.board
        return self.heel + 0.75 * self.length * d


@dataclass(frozen=True)
class DrumKit:
    """The kit around the drummer; ``pieces`` maps piece name -> Drum | Cymbal."""

    pieces: MappingProxyType[str, Drum | Cymbal]
    kick_pedal: Pedal
    hihat_pedal: Pedal
    throne_centre: Vec  # top of the seat
    throne_radius: float
    # how far in from the rim strokes land, as a fraction of the radius (toward the drummer)
    strike_in: MappingProxyType[str, float]

    def strike_point(
        self, piece: str, toward: Vec | None = None, fraction: float | None = None
    ) -> Vec:
        """Where a stick tip lands on ``piece`` (on the head / top face), (3,) metres.

        Strokes land between the centre and the rim on the side nearest
        ``toward`` (default the throne; the authoring tool passes the striking
        hand's shoulder, so each hand plays the side of a head nearest itself);
        cymbals out toward the edge, where they are played.  ``fraction`` of
        the radius from the centre overrides the piece's ``strike_in``.
        """
        p = self.pieces[piece]
        ref = self.throne_centre if toward is None else np.asarray(toward, dtype=np.float64)
        toward_v = ref - p.centre
        toward_v = toward_v - np.dot(toward_v, p.normal) * p.normal
        n = np.linalg.norm(toward_v)
        top = p.centre + (p.thickness / 2 if isinstance(p, Cymbal) else 0.0) * p.normal
        if n < 1e-9:
            return top
        frac = self.strike_in[piece] if fraction is None else fraction
        return top + frac * p.radius * toward_v / n

    def surface_distance(self, piece: str, point: Vec) -> float:
        """Distance (m) from ``point`` to the struck surface of ``piece`` (head disc or cymbal top)."""
        p = self.pieces[piece]
        top = p.centre + (p.thickness / 2 if isinstance(p, Cymbal) else 0.0) * p.normal
        rel = np.asarray(point, dtype=np.float64) - top
        h = float(np.dot(rel, p.normal))
        radial = rel - h * p.normal
        r = float(np.linalg.norm(radial))
        out = max(0.0, r - p.radius)
        return float(np.hypot(h, out))


@dataclass(frozen=True)
class UprightBass:
    """An upright bass: ``strings`` B E A D G C, each from its ``nut`` point to its ``bridge``
    point (a four-string bass uses E A D G of them).

    ``axis`` (3,) unit from endpin toward the scroll; ``front`` (3,) unit, the
    side the strings face; ``scale_m`` the vibrating length of every string.
    """

    endpin: Vec
    axis: Vec
    front: Vec
    scale_m: float
    nut: MappingProxyType[str, Vec]
    bridge: MappingProxyType[str, Vec]
    body_centre: Vec
    body_height: float
    body_width: float
    body_depth: float
    neck_length: float
    max_fret: int = 20
    pluck_from_bridge_m: float = (
        0.34  # where the right hand plucks: near the end of the fingerboard
    )

    @property
    def strings(self) -> tuple[str, ...]:
        return tuple(self.nut)

    def string_dir(self, string: str) -> Vec:
        """Unit direction nut -> bridge of ``string``."""
        return _unit(self.bridge[string] - self.nut[string])

    def fret_distance(self, fret: int) -> float:
        """Distance (m) from the nut where ``fret`` is stopped (equal temperament)."""
        if not 0 <= fret <= self.max_fret:
            raise ValueError(f"fret must be 0-{self.max_fret}, got {fret}")
        return float(self.scale_m * (1.0 - 2.0 ** (-fret / 12.0)))

    def string_point(self, string: str, fret: int) -> Vec:
        """Where a finger stops ``string`` at ``fret`` (fret 0: the nut), (3,) metres."""
        if string not in self.nut:
            raise ValueError(f"unknown string {string!r}; the bass has {', '.join(self.nut)}")
        return self.nut[string] + self.fret_distance(fret) * self.string_dir(string)

    def pluck_point(self, string: str) -> Vec:
        """Where the right hand plucks ``string``, (3,) metres."""
        if string not in self.bridge:
            raise ValueError(f"unknown string {string!r}; the bass has {', '.join(self.bridge)}")
        return self.bridge[string] - self.pluck_from_bridge_m * self.string_dir(string)

    def note_of(self, string: str, fret: int) -> int:
        """The MIDI note sounding on ``string`` stopped at ``fret`` (standard tuning)."""
        return OPEN_STRING_NOTES[string] + fret


@dataclass(frozen=True)
class Stage:
    """The floor (y = 0) and where the players are."""

    floor_size: tuple[float, float] = (6.0, 4.0)  # x by z extent, centred on the origin
    drummer_origin: Vec = field(default_factory=lambda: _v(-0.9, 0.0, -0.3))
    bassist_origin: Vec = field(default_factory=lambda: _v(0.9, 0.0, 0.0))


@dataclass(frozen=True)
class Geometry:
    """The whole stage: ``stage``, ``kit`` (world coordinates), ``bass`` (world coordinates)."""

    stage: Stage
    kit: DrumKit
    bass: UprightBass


def _make_kit(o: Vec) -> DrumKit:
    def tilt(deg: float, toward_x: float = 0.0) -> Vec:
        # head normal tipped toward the drummer (-z) by ``deg``, and sideways by toward_x
        r = np.radians(deg)
        return _unit(_v(toward_x, np.cos(r), -np.sin(r)))

    # A realistic layout for a seated drummer whose hip joints are at ``o``
    # (throne top 0.52 m): the hands work 35-45 cm in front of the shoulders,
    # so the elbows bend 60-100 deg, not the 110-170 deg of a kit crowded
    # against the body.
    pieces: dict[str, Drum | Cymbal] = {
        # 22" bass drum on the floor in front of the right leg, batter head facing
        # the drummer (-z), just past the end of the kick pedal's board
        "kick": Drum("kick", o + _v(-0.10, 0.28, 0.70), _v(0, 0, -1), 0.279, 0.40),
        # 14" snare between the knees, a little to the left, its near rim ~22 cm in
        # front of the belly; head a hand above the thighs, tipped 8 deg toward him
        "snare": Drum("snare", o + _v(0.10, 0.68, 0.52), tilt(8), 0.178, 0.14),
        # 10" and 12" rack toms over the kick, tipped 25 deg toward the drummer
        "tom_high": Drum("tom_high", o + _v(0.06, 0.88, 0.76), tilt(25, -0.05), 0.127, 0.20),
        "tom_low": Drum("tom_low", o + _v(-0.26, 0.88, 0.76), tilt(25, 0.05), 0.152, 0.22),
        # 16" floor tom beside the right knee, flat, level with the snare
        "tom_floor": Drum("tom_floor", o + _v(-0.50, 0.64, 0.46), _v(0, 1, 0), 0.203, 0.40),
        # 14" hi-hat on the left, past the snare, flat (top cymbal when closed)
        "hihat": Cymbal("hihat", o + _v(0.48, 0.90, 0.56), _v(0, 1, 0), 0.178),
        # 20" ride on the right and forward of the floor tom, 16" crash front left,
        # both tipped toward the drummer
        "ride": Cymbal("ride", o + _v(-0.60, 1.02, 0.72), tilt(12, 0.1), 0.254),
        "crash": Cymbal("crash", o + _v(0.40, 1.20, 0.80), tilt(15, -0.1), 0.203),
        # 18" crash 2 on the right (the TD-11's second crash, GM 57): on a boom over
        # the low tom's far side, between the rack toms and the ride, 16 cm higher
        # than the ride and 28 cm in from its centre, so the two overlap seen from
        # above (as on a real kit) with a stick's room between them (11 cm); crash 1
        # mirrored, a little further out.  Tipped 18 deg toward the drummer and a
        # little toward the middle.  Seen from above its rim stays 3 cm off the low
        # tom's strike point and 10 cm off the ride's: a stick going down to either
        # never passes under it.  Nearer, and the stick from crash 2 to the low tom
        # went under its rim; further or higher, and the left hand could not reach
        # it across the body (tools/author_motions.py).  A straight stand under it
        # would stand in the bass drum and the low tom: it hangs on a boom whose
        # mast stands behind the bass drum, right of its shell.
        "crash2": Cymbal(
            "crash2",
            o + _v(-0.40, 1.18, 0.92),
            tilt(18, 0.12),
            0.229,
            boom=o + _v(-0.44, 0.98, 1.28),
        ),
    }
    # pedals a shin's length ahead of the knees' plumb line, so the shins slope forward
    kick_pedal = Pedal(
        "kick", o + _v(-0.12, 0.02, 0.30), _unit(_v(0, 0.30, 1)), _unit(_v(0, 0.12, 1)), 0.26
    )
    hihat_pedal = Pedal(
        "hihat", o + _v(0.30, 0.02, 0.30), _unit(_v(0, 0.30, 1)), _unit(_v(0, 0.12, 1)), 0.28
    )
    strike_in = {
        "kick": 0.0,  # the beater hits the centre
        "snare": 0.35,
        "tom_high": 0.35,
        "tom_low": 0.35,
        "tom_floor": 0.35,
        "hihat": 0.55,  # hi-hat and ride played between bell and edge
        "ride": 0.55,
        "crash": 0.85,  # crash struck near the edge
        "crash2": 0.85,
    }
    return DrumKit(
        MappingProxyType(pieces),
        kick_pedal,
        hihat_pedal,
        o + _v(0.0, 0.52, 0.0),
        0.18,
        MappingProxyType(strike_in),
    )


def _make_bass(o: Vec) -> UprightBass:
    # The player (hip joints over ``o``, facing +z) stands behind and to the right
    # of the bass: it stands on its endpin in front of him, a little to his left,
    # leaning back so the upper bout rests against his belly and the neck passes
    # his head on the left, the nut at eye height (1.66 m) 26 cm left of his nose;
    # the strings face forward and 28 deg to his right, toward his plucking hand.
    endpin = o + _v(0.0, 0.0, 0.40)
    nut_target = o + _v(0.22, 1.66, 0.04)
    axis = _unit(nut_target - endpin)
    yaw = np.radians(28.0)
    facing = _v(-np.sin(yaw), 0.0, np.cos(yaw))  # forward, turned to the player's right (-x)
    front = _unit(facing - np.dot(facing, axis) * axis)  # made perpendicular to the axis
    lateral = _unit(np.cross(axis, front))  # toward the player's left (+x) roughly
    scale = 1.05  # 3/4 bass, 41.3 inch string length
    nut_centre = endpin + float(np.linalg.norm(nut_target - endpin)) * axis + 0.035 * front
    bridge_centre = nut_centre + scale * _unit(-axis + 0.045 * front)
    # B E A D G C across the nut (m): E A D G 10 mm apart, B and C 9 mm outside them
    nut_half_spacing = (-0.024, -0.015, -0.005, 0.005, 0.015, 0.024)
    # and across the bridge: E A D G 30 mm apart, B and C 20 mm outside them
    bridge_half_spacing = (-0.065, -0.045, -0.015, 0.015, 0.045, 0.065)
    nut: dict[str, Vec] = {}
    bridge: dict[str, Vec] = {}
    for s, dn, db in zip(ALL_BASS_STRINGS, nut_half_spacing, bridge_half_spacing, strict=True):
        # E on the player's left (+x), G on his right; strings arch a little at the bridge
        nut[s] = nut_centre - dn * lateral
        bridge[s] = bridge_centre - db * lateral
    # the bridge points are scale_m from the nut points only up to the spacing change;
    # keep the exact scale by re-placing each bridge point along its own direction
    for s in ALL_BASS_STRINGS:
        bridge[s] = nut[s] + scale * _unit(bridge[s] - nut[s])
    return UprightBass(
        endpin=endpin,
        axis=axis,
        front=front,
        scale_m=scale,
        nut=MappingProxyType(nut),
        bridge=MappingProxyType(bridge),
        # the body starts 6 cm above the endpin's tip; the bridge stands near its waist
        body_centre=endpin + 0.62 * axis - 0.08 * front,
        body_height=1.10,
        body_width=0.62,
        body_depth=0.22,
        neck_length=0.62,
    )


def make_geometry(stage: Stage | None = None) -> Geometry:
    """The stage with the kit around the drummer and the bass by the bassist."""
    st = stage or Stage()
    return Geometry(st, _make_kit(st.drummer_origin), _make_bass(st.bassist_origin))


GEOMETRY = make_geometry()
