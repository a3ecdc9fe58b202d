"""A sampled performance as glTF 2.0: the band and its instruments, animated.

Layout of the file (names are stable; tools may look them up):

- scene ``virja band`` with three top nodes: ``drums`` and ``bass`` (the two
  figures) and ``stage`` (the floor, the kit, the upright bass);
- each figure is a node hierarchy of its joints, named ``<figure>_<joint>``
  (``drums_Hips`` ... ``bass_RightToe``, the joints of
  :data:`virja.motion.skeleton.SKELETON`); a joint's translation is its rest
  offset, its rotation the animated local rotation; the limbs are meshes on
  child nodes (``<figure>_<joint>_bone`` from the parent joint to this one,
  ``<figure>_<joint>_ball`` at the joint, ``<figure>_head``), so they move
  with their joints;
- the sticks ``drums_stick_left`` / ``drums_stick_right`` are children of the
  drummer's hands;
- the kit: ``kit_<piece>`` for every drum and cymbal; cymbals swing
  (``kit_ride``, ``kit_crash``, ``kit_crash2``, ``kit_hihat`` rotate; crash 2 hangs
  on a boom, ``kit_crash2_boom``), the hi-hat's top cymbal
  rises as the left foot lets the pedal up, the pedal boards ``kit_pedal_kick``
  and ``kit_pedal_hihat`` follow the feet;
- the bass: ``bass_instrument`` (rotated and moved as it leans with its player,
  about its endpin) and the strings of the planned tuning ``bass_string_<B|E|A|D|G|C>``
  (E A D G by default; five- and six-string tunings get theirs),
  whose one morph target (the fundamental mode) is weighted by the vibration;
- one animation ``band`` (both figures, the kit, the strings), keyframed at
  the export rate, linear (one clip, so importers that play one animation at
  a time, as Blender does, show the whole band moving).

Metres, y up, the audience at +z (glTF's default frame: front is +z).
Animation time 0 is ``extras.virja.t0_s`` of the scene, seconds from the input's
start, whose session time is ``extras.virja.origin_s`` (0 for a MIDI file; a
recording's first packet, Unix seconds).
"""

from __future__ import annotations

import json
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from virja import quat
from virja.fingerboard import fingerboard
from virja.geometry import GEOMETRY, Cymbal, Drum, Geometry
from virja.motion.skeleton import SKELETON, STICK_AXIS_LOCAL, STICK_BUTT_M, STICK_TIP_M
from virja.vocab import BASS_STRINGS

F64 = NDArray[np.float64]

# base colours (linear RGB), as the renderer draws them
COLOURS: dict[str, tuple[float, float, float]] = {
    "floor": (0.075, 0.05, 0.04),
    "shell": (0.45, 0.05, 0.06),
    "head": (0.86, 0.84, 0.78),
    "brass": (0.78, 0.56, 0.18),
    "chrome": (0.62, 0.64, 0.68),
    "black": (0.03, 0.03, 0.035),
    "wood": (0.42, 0.18, 0.06),
    "ebony": (0.04, 0.03, 0.03),
    "string": (0.75, 0.72, 0.62),
    "stick": (0.85, 0.72, 0.48),
    "skin": (0.80, 0.58, 0.45),
    "drummer_shirt": (0.16, 0.30, 0.62),
    "bassist_shirt": (0.55, 0.42, 0.12),
    "trousers": (0.10, 0.10, 0.12),
}
METALLIC = frozenset({"brass", "chrome", "string"})

FLOAT, USHORT = 5126, 5123
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Sampled:
    """A performance sampled at ``times`` (m,), session seconds, sorted.

    - ``local``: (m, 2, n_joints, 4) local rotations of [drums, bass], w x y z;
    - ``roots``: (2, 3) root (hips) positions of the two figures;
    - ``cymbal_swing``: piece -> (m,) radians; ``hihat_open``: (m,) 0..1;
    - ``kick_down``: (m,) 0 (pedal up) .. 1 (pressed), from the right foot;
    - ``string_vibration``: string -> (m,) metres, one per string of the tuning
      (only those strings are drawn);
    - ``hihat_down``: (m,) 0 (pedal up) .. 1 (pressed), from the left foot (None:
      ``1 - hihat_open``);
    - ``origin_s``: the session time of the input's start (what users call 0).
    - ``bass_transform``: (m, 4, 4) the upright bass's world transform, leaning with
      its player (``BandPose.bass_transform``; None: it stands still).
    """

    times: F64
    local: F64
    roots: F64
    cymbal_swing: dict[str, F64]
    hihat_open: F64
    kick_down: F64
    string_vibration: dict[str, F64]
    hihat_down: F64 | None = None
    origin_s: float = 0.0
    bass_transform: F64 | None = None


# ---------------------------------------------------------------- unit meshes


def _cylinder(n: int = 16) -> tuple[F64, F64, NDArray[np.uint16]]:
    """Radius 1, from y = 0 to y = 1, with caps."""
    a = 2 * np.pi * np.arange(n) / n
    ring = np.stack([np.cos(a), np.zeros(n), np.sin(a)], axis=1)
    side_pos = np.concatenate([ring, ring + Y])
    side_nrm = np.concatenate([ring, ring])
    bottom, top = ring.copy(), ring + Y
    pos = np.concatenate([side_pos, bottom, top, [[0, 0, 0], [0, 1, 0]]])
    nrm = np.concatenate([side_nrm, np.tile(-Y, (n, 1)), np.tile(Y, (n, 1)), [-Y, Y]])
    idx: list[int] = []
    for i in range(n):
        j = (i + 1) % n
        idx += [i, n + i, j, j, n + i, n + j]
        cb, ct = 4 * n, 4 * n + 1
        idx += [cb, 2 * n + i, 2 * n + j]
        idx += [ct, 3 * n + j, 3 * n + i]
    return pos, nrm, np.array(idx, dtype=np.uint16)


def _sphere(nu: int = 16, nv: int = 10) -> tuple[F64, F64, NDArray[np.uint16]]:
    """Radius 1 about the origin."""
    v = np.linspace(0.0, np.pi, nv + 1)
    u = 2 * np.pi * np.arange(nu) / nu
    vv, uu = np.meshgrid(v, u, indexing="ij")
    pos = np.stack([np.sin(vv) * np.cos(uu), np.cos(vv), np.sin(vv) * np.sin(uu)], axis=-1)
    pos = pos.reshape(-1, 3)
    idx: list[int] = []
    for r in range(nv):
        for c in range(nu):
            a, b = r * nu + c, r * nu + (c + 1) % nu
            d, e = a + nu, b + nu
            if r > 0:
                idx += [a, b, d]
            if r < nv - 1:
                idx += [b, e, d]
    return pos, pos.copy(), np.array(idx, dtype=np.uint16)


def _box() -> tuple[F64, F64, NDArray[np.uint16]]:
    """Unit cube centred on the origin (side 1)."""
    pos: list[F64] = []
    nrm: list[F64] = []
    idx: list[int] = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            w = np.cross(n, u)
            base = len(pos)
            for su, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos.append(0.5 * (n + su * u + sw * w))
                nrm.append(n)
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return np.array(pos), np.array(nrm), np.array(idx, dtype=np.uint16)


def _hexahedron(corners: F64) -> tuple[F64, F64, NDArray[np.uint16]]:
    """A six-sided solid with flat faces from its 8 ``corners`` (bit i of a corner's index:
    which end along axis i, as :meth:`virja.fingerboard.Fingerboard.corners` orders them)."""
    pos: list[F64] = []
    nrm: list[F64] = []
    idx: list[int] = []
    centre = corners.mean(axis=0)
    for axis in range(3):
        for side in (0, 1):
            quad = [i for i in range(8) if (i >> (2 - axis)) & 1 == side]
            a, b, c, d = (corners[i] for i in (quad[0], quad[1], quad[3], quad[2]))
            n = np.cross(b - a, d - a)
            n /= np.linalg.norm(n)
            if np.dot(n, a - centre) < 0:  # outward, counter-clockwise seen from outside
                n = -n
                a, b, c, d = a, d, c, b
            base = len(pos)
            pos += [a, b, c, d]
            nrm += [n] * 4
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return np.array(pos), np.array(nrm), np.array(idx, dtype=np.uint16)


def _string_mesh(n: int = 16) -> tuple[F64, F64, NDArray[np.uint16], F64]:
    """A thin cylinder y 0..1 (4 sides, n segments) and its bow target: x += sin(pi y)."""
    k = 4
    a = 2 * np.pi * np.arange(k) / k
    ys = np.linspace(0.0, 1.0, n + 1)
    pos = np.array([[np.cos(t), y, np.sin(t)] for y in ys for t in a])
    nrm = pos * [1.0, 0.0, 1.0]
    idx: list[int] = []
    for s in range(n):
        for i in range(k):
            j = (i + 1) % k
            p, q = s * k + i, s * k + j
            idx += [p, p + k, q, q, p + k, q + k]
    target = np.zeros_like(pos)
    target[:, 0] = np.sin(np.pi * pos[:, 1])
    return pos, nrm, np.array(idx, dtype=np.uint16), target


# ---------------------------------------------------------------- the builder


def _xyzw(q: F64) -> list[float]:
    """virja's w x y z -> glTF's x y z w."""
    return [float(q[1]), float(q[2]), float(q[3]), float(q[0])]


def _continuous(q: F64) -> F64:
    """Quaternion keyframes (m, 4) with signs flipped so neighbours agree (short slerps)."""
    out = np.array(q, dtype=np.float64)
    if len(out) > 1:
        d = np.sum(out[1:] * out[:-1], axis=-1)
        sign = np.cumprod(np.where(d < 0, -1.0, 1.0))
        out[1:] *= sign[:, None]
    return out


@dataclass
class GltfBuilder:
    """Accumulates a glTF document and its one binary buffer."""

    doc: dict[str, Any] = field(
        default_factory=lambda: {
            "asset": {"version": "2.0", "generator": "virja export"},
            "scene": 0,
            "scenes": [],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
            "animations": [],
        }
    )
    blob: bytearray = field(default_factory=bytearray)
    _materials: dict[str, int] = field(default_factory=dict)
    _meshes: dict[tuple[str, str], int] = field(default_factory=dict)

    def _view(self, data: bytes, target: int | None = None) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.blob.extend(data)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(
        self, arr: np.ndarray, kind: str, *, target: int | None = None, bounds: bool = False
    ) -> int:
        if arr.dtype == np.uint16:
            comp = USHORT
            data = np.ascontiguousarray(arr, dtype="<u2")
        else:
            comp = FLOAT
            data = np.ascontiguousarray(arr, dtype="<f4")
        count = data.shape[0]
        acc: dict[str, Any] = {
            "bufferView": self._view(data.tobytes(), target),
            "componentType": comp,
            "count": int(count),
            "type": kind,
        }
        if bounds:
            flat = data.reshape(count, -1)
            acc["min"] = [float(x) for x in flat.min(axis=0)]
            acc["max"] = [float(x) for x in flat.max(axis=0)]
            if comp == USHORT:
                acc["min"] = [int(x) for x in acc["min"]]
                acc["max"] = [int(x) for x in acc["max"]]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name: str) -> int:
        if name not in self._materials:
            r, g, b = COLOURS[name]
            self.doc["materials"].append(
                {
                    "name": name,
                    "pbrMetallicRoughness": {
                        "baseColorFactor": [r, g, b, 1.0],
                        "metallicFactor": 0.8 if name in METALLIC else 0.0,
                        "roughnessFactor": 0.35 if name in METALLIC else 0.8,
                    },
                }
            )
            self._materials[name] = len(self.doc["materials"]) - 1
        return self._materials[name]

    def _primitive(
        self, pos: F64, nrm: F64, idx: NDArray[np.uint16], colour: str
    ) -> dict[str, Any]:
        return {
            "attributes": {
                "POSITION": self.accessor(pos, "VEC3", target=ARRAY_BUFFER, bounds=True),
                "NORMAL": self.accessor(nrm, "VEC3", target=ARRAY_BUFFER),
            },
            "indices": self.accessor(idx, "SCALAR", target=ELEMENT_ARRAY_BUFFER, bounds=True),
            "material": self.material(colour),
        }

    def mesh(self, shape: str, colour: str) -> int:
        """A unit ``cylinder``, ``sphere`` or ``box`` in ``colour``, shared by every node using it."""
        key = (shape, colour)
        if key not in self._meshes:
            shapes: dict[str, Callable[[], tuple[F64, F64, NDArray[np.uint16]]]] = {
                "cylinder": _cylinder,
                "sphere": _sphere,
                "box": _box,
            }
            pos, nrm, idx = shapes[shape]()
            self.doc["meshes"].append(
                {
                    "name": f"{shape}_{colour}",
                    "primitives": [self._primitive(pos, nrm, idx, colour)],
                }
            )
            self._meshes[key] = len(self.doc["meshes"]) - 1
        return self._meshes[key]

    def custom_mesh(
        self, name: str, pos: F64, nrm: F64, idx: NDArray[np.uint16], colour: str
    ) -> int:
        """A mesh of its own (``pos``, ``nrm`` (k, 3), triangle ``idx``) in ``colour``."""
        self.doc["meshes"].append(
            {"name": name, "primitives": [self._primitive(pos, nrm, idx, colour)]}
        )
        return len(self.doc["meshes"]) - 1

    def string_mesh(self, name: str) -> int:
        pos, nrm, idx, target = _string_mesh()
        prim = self._primitive(pos, nrm, idx, "string")
        prim["targets"] = [
            {"POSITION": self.accessor(target, "VEC3", target=ARRAY_BUFFER, bounds=True)}
        ]
        self.doc["meshes"].append({"name": name, "primitives": [prim], "weights": [0.0]})
        return len(self.doc["meshes"]) - 1

    def node(
        self,
        name: str,
        parent: int | None = None,
        *,
        translation: F64 | None = None,
        rotation: F64 | None = None,
        scale: F64 | None = None,
        mesh: int | None = None,
    ) -> int:
        n: dict[str, Any] = {"name": name}
        if translation is not None:
            n["translation"] = [float(x) for x in translation]
        if rotation is not None:
            n["rotation"] = _xyzw(quat.normalize(rotation))
        if scale is not None:
            n["scale"] = [float(x) for x in scale]
        if mesh is not None:
            n["mesh"] = mesh
        self.doc["nodes"].append(n)
        i = len(self.doc["nodes"]) - 1
        if parent is not None:
            self.doc["nodes"][parent].setdefault("children", []).append(i)
        return i

    def segment(
        self, name: str, parent: int, a: F64, b: F64, radius: float, colour: str
    ) -> int | None:
        """A cylinder from ``a`` to ``b`` (in the parent's frame)."""
        d = np.asarray(b, dtype=np.float64) - np.asarray(a, dtype=np.float64)
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            return None
        return self.node(
            name,
            parent,
            translation=np.asarray(a, dtype=np.float64),
            rotation=quat.from_two_vectors(Y, d),
            scale=np.array([radius, length, radius]),
            mesh=self.mesh("cylinder", colour),
        )

    def disc(
        self,
        name: str,
        parent: int,
        centre: F64,
        normal: F64,
        radius: float,
        thick: float,
        colour: str,
    ) -> int:
        """A disc centred on ``centre`` facing ``normal``."""
        n = np.asarray(normal, dtype=np.float64)
        return self.node(
            name,
            parent,
            translation=np.asarray(centre, dtype=np.float64) - n * thick / 2,
            rotation=quat.from_two_vectors(Y, n),
            scale=np.array([radius, thick, radius]),
            mesh=self.mesh("cylinder", colour),
        )

    def ball(self, name: str, parent: int, centre: F64, radius: float, colour: str) -> int:
        return self.node(
            name,
            parent,
            translation=np.asarray(centre, dtype=np.float64),
            scale=np.full(3, radius),
            mesh=self.mesh("sphere", colour),
        )

    def box(
        self, name: str, parent: int, centre: F64, size: F64, rot: F64 | None, colour: str
    ) -> int:
        return self.node(
            name,
            parent,
            translation=np.asarray(centre, dtype=np.float64),
            rotation=rot,
            scale=np.asarray(size, dtype=np.float64),
            mesh=self.mesh("box", colour),
        )

    def to_bytes_glb(self) -> bytes:
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.blob)}]
        js = json.dumps(self.doc, separators=(",", ":")).encode("utf-8")
        js += b" " * (-len(js) % 4)
        total = 12 + 8 + len(js) + 8 + len(self.blob)
        out = bytearray(struct.pack("<III", 0x46546C67, 2, total))
        out += struct.pack("<II", len(js), 0x4E4F534A) + js
        out += struct.pack("<II", len(self.blob), 0x004E4942) + self.blob
        return bytes(out)

    def write(self, path: Path) -> list[Path]:
        """``.glb`` (one file) or ``.gltf`` (JSON and ``<stem>.bin`` beside it)."""
        if path.suffix.lower() == ".glb":
            path.write_bytes(self.to_bytes_glb())
            return [path]
        while len(self.blob) % 4:
            self.blob.append(0)
        bin_path = path.with_suffix(".bin")
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": bin_path.name}]
        bin_path.write_bytes(bytes(self.blob))
        path.write_text(json.dumps(self.doc, indent=1), encoding="utf-8")
        return [path, bin_path]


# ---------------------------------------------------------------- the band


def _limb_colour(name: str, shirt: str) -> str:
    n = name.lower()
    if any(k in n for k in ("hand", "finger", "head", "neck", "thumb")):
        return "skin"
    if any(k in n for k in ("leg", "foot", "toe", "hip")):
        return "trousers"
    return shirt


class _Anim:
    """Channels of one animation over shared keyframe times."""

    def __init__(self, b: GltfBuilder, name: str, times: F64) -> None:
        self.b = b
        self.anim: dict[str, Any] = {"name": name, "channels": [], "samplers": []}
        self.input = b.accessor(times.astype(np.float32), "SCALAR", bounds=True)

    def channel(self, node: int, path: str, values: F64) -> None:
        kind = {"rotation": "VEC4", "translation": "VEC3", "scale": "VEC3", "weights": "SCALAR"}
        if path == "rotation":
            values = _continuous(values)[:, [1, 2, 3, 0]]  # w x y z -> x y z w
        s = len(self.anim["samplers"])
        self.anim["samplers"].append(
            {
                "input": self.input,
                "output": self.b.accessor(values, kind[path]),
                "interpolation": "LINEAR",
            }
        )
        self.anim["channels"].append({"sampler": s, "target": {"node": node, "path": path}})

    def done(self) -> None:
        if self.anim["channels"]:
            self.b.doc["animations"].append(self.anim)


def _figure(
    b: GltfBuilder, fig: str, fi: int, s: Sampled, anim: _Anim, shirt: str
) -> tuple[int, dict[str, int]]:
    sk = SKELETON
    top = b.node(fig)
    joints: dict[str, int] = {}
    for i, name in enumerate(sk.names):
        par = int(sk.parents[i])
        parent = top if par < 0 else joints[sk.names[par]]
        trans = s.roots[fi] if par < 0 else sk.offsets[i]
        joints[name] = b.node(
            f"{fig}_{name}", parent, translation=trans, rotation=s.local[0, fi, i]
        )
        anim.channel(joints[name], "rotation", s.local[:, fi, i])
    for i, name in enumerate(sk.names):
        par = int(sk.parents[i])
        colour = _limb_colour(name, shirt)
        head_part = name.lower() in ("head", "headend")
        if par >= 0 and not head_part:
            b.segment(
                f"{fig}_{name}_bone",
                joints[sk.names[par]],
                np.zeros(3),
                sk.offsets[i],
                float(sk.radii[i]),
                colour,
            )
        if not head_part:
            b.ball(
                f"{fig}_{name}_ball", joints[name], np.zeros(3), float(sk.radii[i]) * 1.05, colour
            )
    if "Head" in joints and "HeadEnd" in joints:
        centre = sk.offsets[sk.index("HeadEnd")] / 2
        b.ball(f"{fig}_head", joints["Head"], centre, 0.105, "skin")
        b.ball(f"{fig}_nose", joints["Head"], centre + 0.1 * Z, 0.022, "skin")
    return top, joints


def _sticks(b: GltfBuilder, joints: dict[str, int]) -> None:
    for side in ("Left", "Right"):
        hand = joints[f"{side}Hand"]
        grip = SKELETON.offsets[SKELETON.index(f"{side}HandEnd")]
        butt = grip - STICK_BUTT_M * STICK_AXIS_LOCAL
        tip = grip + STICK_TIP_M * STICK_AXIS_LOCAL
        b.segment(f"drums_stick_{side.lower()}", hand, butt, tip, 0.0075, "stick")
        b.ball(f"drums_stick_{side.lower()}_tip", hand, tip, 0.009, "stick")


def _swing_axis(normal: F64) -> F64:
    axis = np.cross(normal, Z)
    if np.linalg.norm(axis) < 1e-6:
        return np.array([1.0, 0.0, 0.0])
    return axis / np.linalg.norm(axis)


def _kit(b: GltfBuilder, stage: int, geo: Geometry, s: Sampled, anim: _Anim) -> None:
    kit = geo.kit
    k = b.node("kit", stage)
    b.segment(
        "kit_throne_post", k, kit.throne_centre - [0, 0.5, 0], kit.throne_centre, 0.03, "chrome"
    )
    b.segment(
        "kit_throne",
        k,
        kit.throne_centre - [0, 0.05, 0],
        kit.throne_centre,
        kit.throne_radius,
        "black",
    )
    m = len(s.times)
    for name, piece in kit.pieces.items():
        if isinstance(piece, Drum):
            node = b.node(f"kit_{name}", k)
            back = piece.centre - piece.normal * piece.depth
            b.segment(
                f"kit_{name}_shell",
                node,
                back,
                piece.centre - piece.normal * 0.004,
                piece.radius,
                "shell",
            )
            b.segment(
                f"kit_{name}_hoop",
                node,
                piece.centre - piece.normal * 0.012,
                piece.centre + piece.normal * 0.006,
                piece.radius + 0.008,
                "chrome",
            )
            b.disc(
                f"kit_{name}_head", node, piece.centre, piece.normal, piece.radius, 0.004, "head"
            )
            if name != "kick":
                foot = np.array([piece.centre[0], 0.0, piece.centre[2]])
                b.segment(f"kit_{name}_stand", node, foot, back, 0.012, "chrome")
            continue
        assert isinstance(piece, Cymbal)
        path = piece.stand()  # floor to under the cymbal: a stand, or mast and boom
        for i, part in enumerate(("stand", "boom")[: len(path) - 1]):
            b.segment(f"kit_{name}_{part}", k, path[i], path[i + 1], 0.011, "chrome")
        centre = piece.centre
        if name == "hihat":
            bottom = centre - np.array([0.0, 0.02, 0.0])
            b.disc(
                "kit_hihat_bottom", k, bottom, piece.normal, piece.radius, piece.thickness, "brass"
            )
            centre = bottom + np.array([0.0, 0.004, 0.0])
        rest = quat.from_two_vectors(Y, piece.normal)
        swing = s.cymbal_swing.get(name, np.zeros(m))
        axis = np.broadcast_to(_swing_axis(piece.normal), (m, 3))
        rot = quat.multiply(quat.from_axis_angle(axis, swing), rest)
        node = b.node(f"kit_{name}", k, translation=centre, rotation=rot[0])
        anim.channel(node, "rotation", rot)
        if name == "hihat":
            lift = 0.004 + 0.016 * np.clip(s.hihat_open, 0.0, 1.0)
            pos = (centre - np.array([0.0, 0.004, 0.0]))[None, :] + lift[:, None] * Y
            b.doc["nodes"][node]["translation"] = [float(x) for x in pos[0]]
            anim.channel(node, "translation", pos)
        b.node(
            f"kit_{name}_cymbal",
            node,
            translation=np.array([0.0, -piece.thickness / 2, 0.0]),
            scale=np.array([piece.radius, piece.thickness, piece.radius]),
            mesh=b.mesh("cylinder", "brass"),
        )
        b.ball(f"kit_{name}_bell", node, np.zeros(3), piece.radius * 0.14, "brass")
    hihat_down = 1.0 - s.hihat_open if s.hihat_down is None else s.hihat_down
    for pedal, down in ((kit.kick_pedal, s.kick_down), (kit.hihat_pedal, hihat_down)):
        d = np.clip(np.asarray(down, dtype=np.float64), 0.0, 1.0)[:, None]
        board = (1 - d) * pedal.board + d * pedal.pressed_board
        rot = quat.from_two_vectors(np.broadcast_to(Z, board.shape), board)
        node = b.node(f"kit_pedal_{pedal.name}", k, translation=pedal.heel, rotation=rot[0])
        anim.channel(node, "rotation", rot)
        b.box(
            f"kit_pedal_{pedal.name}_board",
            node,
            np.array([0.0, 0.0, pedal.length / 2]),
            np.array([0.09, 0.02, pedal.length]),
            None,
            "chrome",
        )


def _orient(geo: Geometry) -> F64:
    bb = geo.bass
    lateral = np.cross(bb.axis, bb.front)
    lateral /= np.linalg.norm(lateral)
    return quat.from_matrix(np.stack([lateral, bb.axis, bb.front], axis=1))


def _upright_bass(b: GltfBuilder, stage: int, geo: Geometry, s: Sampled, anim: _Anim) -> None:
    bb = geo.bass
    up = bb.axis
    node = b.node("bass_instrument", stage)
    if s.bass_transform is not None:  # it leans with its player: a rotation about its endpin
        m = np.asarray(s.bass_transform, dtype=np.float64)
        rot = quat.from_matrix(m[:, :3, :3])
        b.doc["nodes"][node]["rotation"] = _xyzw(quat.normalize(rot[0]))
        b.doc["nodes"][node]["translation"] = [float(x) for x in m[0, :3, 3]]
        anim.channel(node, "rotation", rot)
        anim.channel(node, "translation", m[:, :3, 3])
    o = _orient(geo)
    for label, c, sc in (
        ("lower_bout", bb.body_centre - 0.22 * up, [bb.body_width / 2, 0.34, bb.body_depth / 2]),
        (
            "upper_bout",
            bb.body_centre + 0.28 * up,
            [bb.body_width / 2 * 0.8, 0.26, bb.body_depth / 2],
        ),
    ):
        b.node(
            f"bass_{label}",
            node,
            translation=c,
            rotation=o,
            scale=np.array(sc),
            mesh=b.mesh("sphere", "wood"),
        )
    b.box(
        "bass_waist",
        node,
        bb.body_centre + 0.05 * up,
        np.array([bb.body_width * 0.55, 0.3, bb.body_depth * 0.9]),
        o,
        "wood",
    )
    nut_c = np.mean([bb.nut[x] for x in bb.nut], axis=0)
    bridge_c = np.mean([bb.bridge[x] for x in bb.bridge], axis=0)
    b.segment(
        "bass_neck",
        node,
        bb.body_centre + 0.5 * up - 0.03 * bb.front,
        nut_c - 0.02 * bb.front + 0.02 * up,
        0.028,
        "wood",
    )
    b.ball("bass_scroll", node, nut_c + 0.10 * up - 0.02 * bb.front, 0.05, "wood")
    # the strings of the tuning the performance was planned on (string_vibration's keys)
    tuning = [n for n in bb.strings if n in s.string_vibration] or list(BASS_STRINGS)
    # the fingerboard tapers with the tuning's strings (virja.fingerboard): its own mesh
    board = fingerboard(bb, tuple(tuning))
    pos, nrm, idx = _hexahedron(board.corners())
    b.node("bass_fingerboard", node, mesh=b.custom_mesh("bass_fingerboard", pos, nrm, idx, "ebony"))
    lat = [
        float((bb.bridge[n] - bridge_c) @ quat.rotate(o, np.array([1.0, 0.0, 0.0]))) for n in tuning
    ]
    bridge_w = max(0.13, max(lat) - min(lat) + 0.02)  # as wide as its strings need
    b.box(
        "bass_bridge",
        node,
        bridge_c - 0.02 * bb.front,
        np.array([bridge_w, 0.08, 0.012]),
        o,
        "wood",
    )
    b.box("bass_tailpiece", node, bridge_c - 0.20 * up, np.array([0.09, 0.22, 0.012]), o, "ebony")
    b.segment("bass_endpin", node, bb.endpin, bb.endpin + 0.2 * up, 0.008, "chrome")
    lateral = np.cross(bb.axis, bb.front)
    lateral /= np.linalg.norm(lateral)
    for k, name in enumerate(bb.strings):
        if name not in tuning:
            continue
        a, z = bb.nut[name], bb.bridge[name]
        d = z - a
        rot_y = quat.from_two_vectors(Y, d)
        # turn about the string so the mesh's +x (the bow target) points along the bass' lateral
        x_now = quat.rotate(rot_y, np.array([1.0, 0.0, 0.0]))
        lat = lateral - np.dot(lateral, d / np.linalg.norm(d)) * d / np.linalg.norm(d)
        twist = quat.from_two_vectors(x_now, lat)
        radius = 0.0022 - 0.0003 * k
        node_s = b.node(
            f"bass_string_{name}",
            node,
            translation=a,
            rotation=quat.multiply(twist, rot_y),
            scale=np.array([radius, float(np.linalg.norm(d)), radius]),
            mesh=b.string_mesh(f"string_{name}"),
        )
        amp = s.string_vibration.get(name)
        if amp is not None:
            swing = np.cos(2 * np.pi * (9.0 + 1.3 * k) * s.times)
            # the target moves x by sin(pi y) mesh units; x is scaled by the radius
            anim.channel(node_s, "weights", amp * swing / radius)


def build_gltf(s: Sampled, geo: Geometry = GEOMETRY) -> GltfBuilder:
    """The whole band, its instruments and their animations, as a :class:`GltfBuilder`."""
    b = GltfBuilder()
    times = s.times - s.times[0]
    # one animation for the band: importers that play one clip at a time (Blender makes
    # the first one active) show everybody moving
    drums_anim = bass_anim = _Anim(b, "band", times)
    drums, joints = _figure(b, "drums", 0, s, drums_anim, "drummer_shirt")
    _sticks(b, joints)
    bass, _ = _figure(b, "bass", 1, s, bass_anim, "bassist_shirt")
    stage = b.node("stage")
    w, d = geo.stage.floor_size
    b.box("stage_floor", stage, np.array([0.0, -0.05, 0.0]), np.array([w, 0.1, d]), None, "floor")
    _kit(b, stage, geo, s, drums_anim)
    _upright_bass(b, stage, geo, s, bass_anim)
    drums_anim.done()
    b.doc["scenes"] = [
        {
            "name": "virja band",
            "nodes": [drums, bass, stage],
            "extras": {
                "virja": {
                    "t0_s": round(float(s.times[0]) - s.origin_s, 6),
                    "origin_s": s.origin_s,
                    "fps": _fps(s.times),
                }
            },
        }
    ]
    return b


def _fps(times: F64) -> float:
    return float(1.0 / np.median(np.diff(times))) if len(times) > 1 else 0.0


def write_gltf(s: Sampled, path: Path, geo: Geometry = GEOMETRY) -> list[Path]:
    """Write ``path`` (``.glb``, or ``.gltf`` with ``<stem>.bin``); returns the files written."""
    return build_gltf(s, geo).write(path)
