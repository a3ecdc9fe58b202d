"""Basic-motion clips: a BVH file plus a TOML sidecar, and the library of them.

A clip ``motions/<performer>/<name>.bvh`` comes with ``<name>.toml``::

    performer = "drums"          # "drums" | "bass"
    limb = "left_hand"           # left_hand | right_hand | left_foot | right_foot
    kind = "stroke"              # stroke: ends where it began (ready pose);
                                 # hold: stays at its last frame (the bass's left hand);
                                 # idle: the figure's base layer, loops
    impact_s = 0.30              # impact, seconds from the clip's first frame
    joints = ["LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"]   # joints it drives
    piece = "snare"              # drums: what it strikes (or string = "E", fret = 5 for bass)
    velocity = 96                # the loudness the clip was made (or captured) at

The BVH must contain every joint of :data:`virja.motion.skeleton.SKELETON` by
name (order and extra joints do not matter), so a captured BVH with the same
joint names can replace any clip.  Errors name the file (and the line).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from virja import tomlconf
from virja.errors import InputFileError, VirjaError
from virja.motion.bvh import Bvh, read_bvh
from virja.motion.skeleton import SKELETON, Skeleton
from virja.tomlconf import Schema
from virja.vocab import (
    ALL_BASS_STRINGS,
    LIMBS,
    PERFORMERS,
    PIECES,
    BassString,
    Limb,
    Performer,
    Piece,
)

log = logging.getLogger(__name__)

KINDS = ("stroke", "hold", "idle")


class ClipError(InputFileError):
    """A clip's BVH or sidecar is invalid; names the file and, where known, the line."""


class UnknownMotionError(VirjaError, KeyError):
    """A planned note names a motion the library does not have."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "unknown motion"


@dataclass(frozen=True)
class Clip:
    """One basic motion, resampled onto the project skeleton.

    ``rotations`` (n_frames, n_joints, 4) local w x y z in skeleton order;
    ``root_positions`` (n_frames, 3) metres; ``fps`` frames per second;
    ``impact_s`` seconds from the first frame; ``joints`` the driven joints.
    """

    name: str
    performer: Performer
    limb: Limb | None
    kind: str
    fps: float
    rotations: np.ndarray
    root_positions: np.ndarray
    impact_s: float
    joints: tuple[str, ...]
    joint_index: np.ndarray
    piece: Piece | None = None
    string: BassString | None = None
    fret: int | None = None
    velocity: int = 96
    source: str = "<memory>"

    @property
    def n_frames(self) -> int:
        return int(self.rotations.shape[0])

    @property
    def duration_s(self) -> float:
        return (self.n_frames - 1) / self.fps

    def sample(self, clip_time_s: float, joint_index: np.ndarray | None = None) -> np.ndarray:
        """Local rotations (k, 4) of joints ``joint_index`` (default: driven joints) at a time.

        Time is clamped to the clip; between frames the rotations are
        interpolated by :func:`sample_frames`.
        """
        return sample_frames(
            self.rotations,
            self.fps,
            clip_time_s,
            self.joint_index if joint_index is None else joint_index,
        )


def sample_frames(
    frames: np.ndarray, fps: float, time_s: float, joint_index: np.ndarray
) -> np.ndarray:
    """Rotations (k, 4) of ``frames[:, joint_index]`` at ``time_s`` (clamped).

    Between two frames this is normalised lerp: consecutive frames are sign
    aligned at load and a frame step is a small angle (under 0.2 rad at 60 fps
    for these gestures), where nlerp and slerp differ by less than 1e-4 rad;
    on a frame the frame itself is returned exactly (impacts are on frames).
    """
    n = frames.shape[0]
    f = min(max(time_s * fps, 0.0), n - 1.0)
    i0 = int(f)
    frac = f - i0
    if frac < 1e-9 or i0 >= n - 1:
        return frames[i0, joint_index]
    q = (1.0 - frac) * frames[i0, joint_index] + frac * frames[i0 + 1, joint_index]
    return q / np.sqrt(np.einsum("ij,ij->i", q, q))[:, None]


def align_signs(frames: np.ndarray) -> np.ndarray:
    """``frames`` (n, j, 4) with each quaternion's sign flipped to agree with the previous frame."""
    out = frames.copy()
    if out.shape[0] < 2:
        return out
    # frame k's sign is frame k-1's times the sign of their dot product, a running
    # product (flipping a quaternion negates its dot products exactly); a dot of
    # exactly 0 restarts the sign at +1, so such a rare clip takes the plain loop
    d = np.sum(out[1:] * out[:-1], axis=-1)
    if np.any(d == 0):
        for k in range(1, out.shape[0]):
            flip = np.sum(out[k] * out[k - 1], axis=-1) < 0
            out[k, flip] *= -1.0
        return out
    sign = np.cumprod(np.where(d < 0, -1.0, 1.0), axis=0)
    out[1:] *= sign[..., None]
    return out


def _line_of(text: str, key: str) -> int | None:
    for n, ln in enumerate(text.splitlines(), 1):
        if ln.strip().startswith(f"{key} ") or ln.strip().startswith(f"{key}="):
            return n
    return None


def _fail(path: Path, text: str, key: str | None, reason: str) -> ClipError:
    line = _line_of(text, key) if key else None
    where = f"line {line}: " if line else ""
    return ClipError(path, f"{where}{reason}")


class SidecarFile(Schema):
    """A clip's ``<name>.toml`` (the module's docstring explains each key)."""

    performer: str
    kind: str
    impact_s: float
    joints: list[str]
    limb: str | None = None
    piece: str | None = None
    string: str | None = None
    fret: int | None = None
    velocity: int = 96


def _clip_error(where: str, reason: str) -> Exception:
    return ClipError(where, reason)


def read_sidecar(path: Path) -> dict[str, Any]:
    """Parse and validate a clip sidecar; errors name the file and line."""
    text = tomlconf.read_text(path, noun="clip sidecar", error=_clip_error)
    data = tomlconf.parse(text, str(path), error=_clip_error)
    try:
        side = tomlconf.convert(data, SidecarFile, str(path))
    except tomlconf.SchemaError as exc:
        key = exc.key.split(".")[0].split("[")[0]
        raise _fail(path, text, key if key in data else None, exc.reason) from None
    if side.performer not in PERFORMERS:
        raise _fail(
            path,
            text,
            "performer",
            f"performer must be one of {PERFORMERS}, got {side.performer!r}",
        )
    if side.kind not in KINDS:
        raise _fail(path, text, "kind", f"kind must be one of {KINDS}, got {side.kind!r}")
    if side.kind != "idle":
        if side.limb is None:
            raise _fail(path, text, None, "missing key 'limb'")
        if side.limb not in LIMBS:
            raise _fail(path, text, "limb", f"limb must be one of {LIMBS}, got {side.limb!r}")
    if not 0 <= side.impact_s < float("inf"):
        raise _fail(
            path, text, "impact_s", f"impact_s must be finite and >= 0, got {side.impact_s}"
        )
    if not side.joints:
        raise _fail(path, text, "joints", "joints must be a non-empty list of joint names")
    if side.piece is not None and side.piece not in PIECES:
        raise _fail(path, text, "piece", f"unknown piece {side.piece!r}; expected one of {PIECES}")
    if side.string is not None and side.string not in ALL_BASS_STRINGS:
        raise _fail(
            path,
            text,
            "string",
            f"unknown string {side.string!r}; expected one of {ALL_BASS_STRINGS}",
        )
    if side.fret is not None and not 0 <= side.fret <= 24:
        raise _fail(path, text, "fret", f"fret must be a whole number 0-24, got {side.fret!r}")
    if not 1 <= side.velocity <= 127:
        raise _fail(path, text, "velocity", f"velocity must be 1-127, got {side.velocity!r}")
    out: dict[str, Any] = tomlconf.fields(side)
    out["_text"] = text
    return out


def clip_from_bvh(
    bvh: Bvh, meta: Mapping[str, Any], name: str, path: Path, skeleton: Skeleton = SKELETON
) -> Clip:
    """Map a BVH's joints by name onto ``skeleton`` and attach the sidecar's data."""
    text = str(meta.get("_text", ""))
    by_name = {n: i for i, n in enumerate(bvh.names)}
    missing = [n for n in skeleton.names if n not in by_name]
    if missing:
        raise ClipError(path, f"BVH lacks joints {missing} of the project skeleton")
    for j in meta["joints"]:
        if j not in skeleton.names:
            raise _fail(path.with_suffix(".toml"), text, "joints", f"unknown joint {j!r}")
    order = np.array([by_name[n] for n in skeleton.names])
    rot = align_signs(np.ascontiguousarray(bvh.rotations[:, order]))
    root = np.ascontiguousarray(bvh.positions[:, order[0]])
    fps = 1.0 / bvh.frame_time_s
    duration = (bvh.n_frames - 1) / fps
    if meta["impact_s"] > duration + 1e-9:
        raise _fail(
            path.with_suffix(".toml"),
            text,
            "impact_s",
            f"impact_s {meta['impact_s']} is past the clip's end ({duration:.3f} s)",
        )
    return Clip(
        name=name,
        performer=meta["performer"],
        limb=meta["limb"],
        kind=meta["kind"],
        fps=fps,
        rotations=rot,
        root_positions=root,
        impact_s=float(meta["impact_s"]),
        joints=tuple(meta["joints"]),
        joint_index=skeleton.mask(meta["joints"]).nonzero()[0],
        piece=meta.get("piece"),
        string=meta.get("string"),
        fret=meta.get("fret"),
        velocity=int(meta["velocity"]),
        source=str(path),
    )


def load_clip(bvh_path: str | Path, skeleton: Skeleton = SKELETON) -> Clip:
    """Load ``X.bvh`` with its ``X.toml`` sidecar."""
    p = Path(bvh_path)
    side = p.with_suffix(".toml")
    if not side.is_file():
        raise ClipError(p, f"no sidecar {side.name} next to the BVH")
    meta = read_sidecar(side)
    return clip_from_bvh(read_bvh(p), meta, p.stem, p, skeleton)


class MotionLibrary:
    """All clips under a folder (default: the package's ``motions/``), by name."""

    def __init__(self, clips: Mapping[str, Clip]) -> None:
        self._clips = dict(clips)

    @classmethod
    def load(cls, folder: str | Path | None = None) -> MotionLibrary:
        if folder is None:
            from virja.resources import motions_dir

            folder = motions_dir()
        root = Path(folder)
        clips: dict[str, Clip] = {}
        for bvh_path in sorted(root.rglob("*.bvh")):
            clip = load_clip(bvh_path)
            if clip.name in clips:
                raise ClipError(
                    bvh_path, f"clip name {clip.name!r} also used by {clips[clip.name].source}"
                )
            clips[clip.name] = clip
        if not clips:
            raise ClipError(root, "no clips (*.bvh with a .toml sidecar) found")
        log.debug("loaded %d clips from %s", len(clips), root)
        return cls(clips)

    def __getitem__(self, name: str) -> Clip:
        try:
            return self._clips[name]
        except KeyError:
            raise UnknownMotionError(f"no basic motion {name!r} in the library") from None

    def __contains__(self, name: object) -> bool:
        return name in self._clips

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(self._clips))

    def __len__(self) -> int:
        return len(self._clips)

    def clips(self) -> list[Clip]:
        return [self._clips[n] for n in sorted(self._clips)]


_DEFAULT: MotionLibrary | None = None


def default_library() -> MotionLibrary:
    """The package's library, loaded once per process."""
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = MotionLibrary.load()
    return _DEFAULT
