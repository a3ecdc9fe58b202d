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

Bass: an upright 4-string bass; strings run from the nut to the bridge;
:meth:`UprightBass.string_point` is where a finger stops a string at a fret
(equal-temperament distance ``scale * (1 - 2**(-fret/12))`` from the nut),
:meth:`UprightBass.pluck_point` where the right hand plucks.

Everything is plain numpy; ``GEOMETRY`` is the one instance the project uses.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

Vec = np.ndarray  # (3,) float64, metres

DRUM_PIECES = ("kick", "snare", "tom_high", "tom_low", "tom_floor")
CYMBAL_PIECES = ("hihat", "ride", "crash")
PIECES = DRUM_PIECES + CYMBAL_PIECES
BASS_STRINGS = ("E", "A", "D", "G")
# sounding MIDI note of each open string (methods.md: E1 A1 D2 G2)
OPEN_STRING_NOTES = MappingProxyType({"E": 28, "A": 33, "D": 38, "G": 43})


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

    def strike_point(self, piece: str) -> Vec:
        """Where a stick tip lands on ``piece`` (on the head / top face), (3,) metres.

        Strokes land between the centre and the rim on the side nearest the
        throne (cymbals: out toward the edge, where they are played).
        """
        p = self.pieces[piece]
        toward = self.throne_centre - p.centre
        toward = toward - np.dot(toward, p.normal) * p.normal
        n = np.linalg.norm(toward)
        if n < 1e-9:
            return p.centre.copy()
        top = p.centre + (p.thickness / 2 if isinstance(p, Cymbal) else 0.0) * p.normal
        return top + self.strike_in[piece] * p.radius * toward / n

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
    """An upright bass: ``strings`` E A D G, each from its ``nut`` point to its ``bridge`` point.

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
        0.30  # where the right hand plucks: near the end of the fingerboard
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
        """The MIDI note sounding on ``string`` stopped at ``fret``."""
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

    pieces: dict[str, Drum | Cymbal] = {
        # 22" bass drum standing on the floor, batter head facing the drummer (-z)
        "kick": Drum("kick", o + _v(-0.10, 0.28, 0.62), _v(0, 0, -1), 0.279, 0.40),
        # 14" snare between the knees, a little to the left, tipped 8 deg toward the drummer
        "snare": Drum("snare", o + _v(0.10, 0.66, 0.46), tilt(8), 0.178, 0.14),
        # 10" and 12" rack toms over the kick, tipped 25 deg
        "tom_high": Drum("tom_high", o + _v(0.10, 0.86, 0.66), tilt(25, -0.05), 0.127, 0.20),
        "tom_low": Drum("tom_low", o + _v(-0.22, 0.86, 0.66), tilt(25, 0.05), 0.152, 0.22),
        # 16" floor tom at the right knee, flat
        "tom_floor": Drum("tom_floor", o + _v(-0.42, 0.62, 0.38), _v(0, 1, 0), 0.203, 0.40),
        # 14" hi-hat on the left, flat (top cymbal when closed)
        "hihat": Cymbal("hihat", o + _v(0.46, 0.86, 0.50), _v(0, 1, 0), 0.178),
        # 20" ride on the right, 16" crash on the left, both tipped toward the drummer
        "ride": Cymbal("ride", o + _v(-0.55, 1.00, 0.55), tilt(12, 0.1), 0.254),
        "crash": Cymbal("crash", o + _v(0.40, 1.18, 0.66), tilt(15, -0.1), 0.203),
    }
    kick_pedal = Pedal(
        "kick", o + _v(-0.12, 0.02, 0.08), _unit(_v(0, 0.30, 1)), _unit(_v(0, 0.12, 1)), 0.26
    )
    hihat_pedal = Pedal(
        "hihat", o + _v(0.30, 0.02, 0.12), _unit(_v(0, 0.30, 1)), _unit(_v(0, 0.12, 1)), 0.28
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
    # The bass stands on its endpin in front of the player, a little to his left,
    # leaning back toward him 14 deg; its strings face the audience (+z).
    endpin = o + _v(0.14, 0.0, 0.30)
    lean = np.radians(14.0)
    axis = _unit(_v(-0.05, np.cos(lean), -np.sin(lean)))
    front = _unit(np.cross(np.cross(axis, _v(0, 0, 1)), axis))  # +z made perpendicular to axis
    lateral = _unit(np.cross(axis, front))  # toward the player's left (+x) roughly
    scale = 1.05  # 3/4 bass, 41.3 inch string length
    nut_centre = endpin + 1.72 * axis + 0.035 * front
    bridge_centre = nut_centre + scale * _unit(-axis + 0.045 * front)
    nut_half_spacing = (-0.015, -0.005, 0.005, 0.015)  # E A D G across the nut (m)
    bridge_half_spacing = (-0.045, -0.015, 0.015, 0.045)
    nut = {}
    bridge = {}
    for s, dn, db in zip(BASS_STRINGS, nut_half_spacing, bridge_half_spacing, strict=True):
        # E on the player's left (+x), G on his right; strings arch a little at the bridge
        nut[s] = nut_centre - dn * lateral
        bridge[s] = bridge_centre - db * lateral
    # the bridge points are scale_m from the nut points only up to the spacing change;
    # keep the exact scale by re-placing each bridge point along its own direction
    for s in BASS_STRINGS:
        bridge[s] = nut[s] + scale * _unit(bridge[s] - nut[s])
    return UprightBass(
        endpin=endpin,
        axis=axis,
        front=front,
        scale_m=scale,
        nut=MappingProxyType(nut),
        bridge=MappingProxyType(bridge),
        body_centre=endpin + 0.55 * axis - 0.08 * front,
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
