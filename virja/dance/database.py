"""The method-B database: {motion segment, sound parameters, span} entries, and teaching.

On disk a database is a folder (``virja teach ... --out DB``):

- ``manifest.json``: ``{"format": "virja-dance-db", "version": 1, "fps", "parts",
  "joints": [{"name", "parent", "offset", "channels", "end_site"}],
  "segments": [{"span", "sound": [a1, a2, a3], "source", "start_frame"}]}``;
- ``segments.npz``: ``rotations`` (sum of (span + 1), n_joints, 4) float64 w x y z
  and ``root_positions`` (sum of (span + 1), 3), the segments one after another
  in manifest order.  A segment of span L keeps L + 1 frames (both cut frames),
  so that stretching and joining see where it ends.

Readers refuse other formats and newer versions with a clear error.
"""

from __future__ import annotations

import json
import logging
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from virja.dance.ar import AR_ORDER, ARFitError, sound_parameters
from virja.dance.audio import ANALYSIS_RATE_HZ, FloatArray
from virja.dance.beats import extract_beats
from virja.dance.segment import (
    DEFAULT_Q_OVER_R,
    DEFAULT_TOLERANCE_FRAMES,
    CutPoint,
    Parts,
    part_weights,
    segment_motion,
)
from virja.errors import InputFileError, VirjaError
from virja.motion.bvh import Bvh, BvhJoint

log = logging.getLogger(__name__)

FORMAT = "virja-dance-db"
VERSION = 1

MIN_SPAN = 5
"""Shortest motion segment ``teach`` keeps, in frames: the paper's shortest (5 at 30 fps).
A cut closer than this to the previous kept cut is dropped (the two pieces become one)."""


class DanceError(VirjaError, ValueError):
    """Method B cannot go on with this input (too few beats, no segments...)."""


@dataclass(frozen=True)
class Segment:
    """One basic motion: ``span`` frames, ``rotations`` (span + 1, n_joints, 4) local w x y z,
    ``root_positions`` (span + 1, 3), ``sound`` (AR_ORDER,) of its music phrase."""

    rotations: FloatArray
    root_positions: FloatArray
    sound: FloatArray
    span: int
    source: str = ""
    start_frame: int = 0


@dataclass(frozen=True)
class DanceDatabase:
    """Segments cut from captures of one skeleton at ``fps`` by ``parts``."""

    joints: tuple[BvhJoint, ...]
    fps: float
    parts: str
    segments: tuple[Segment, ...]
    notes: tuple[str, ...] = field(default=(), compare=False)
    """What ``teach`` left out and why (not saved)."""

    @property
    def spans(self) -> list[int]:
        return [s.span for s in self.segments]

    @property
    def root(self) -> int:
        return next(i for i, j in enumerate(self.joints) if j.parent < 0)


def teach(
    bvh: Bvh,
    audio_8k: FloatArray,
    parts: Parts,
    beats_s: Sequence[float] | None = None,
    tolerance_frames: float = DEFAULT_TOLERANCE_FRAMES,
    q_over_r: float | None = DEFAULT_Q_OVER_R,
    source: str = "",
    audio_offset_s: float = 0.0,
    min_span: int = MIN_SPAN,
) -> DanceDatabase:
    """Cut ``bvh`` at beats of its music and store each segment with its phrase's sound.

    ``audio_8k`` is the music at 8 kHz, starting ``audio_offset_s`` seconds
    after the capture's frame 0 (negative: before).  ``beats_s`` defaults to
    the beats extracted from the audio (capture time).  Cuts closer than
    ``min_span`` frames to the previous kept cut are dropped.  A segment whose
    phrase cannot be fitted (silent, too short) is left out and said in
    ``notes`` (and logged as a warning).
    """
    fps = 1.0 / bvh.frame_time_s
    audio = np.asarray(audio_8k, dtype=np.float64)
    if beats_s is None:
        beats_s = (extract_beats(audio) + audio_offset_s).tolist()
    root = next(i for i, j in enumerate(bvh.joints) if j.parent < 0)
    weights = part_weights(bvh.names, parts, root=root)
    if not np.any(weights):
        raise DanceError(
            f"no joint of the capture matches --parts {parts} (joint names: {bvh.names})"
        )
    all_cuts, _ = segment_motion(bvh.rotations, fps, beats_s, weights, tolerance_frames, q_over_r)
    cuts: list[CutPoint] = []
    for c in all_cuts:
        if not cuts or c.frame - cuts[-1].frame >= max(min_span, 1):
            cuts.append(c)
    segments: list[Segment] = []
    notes: list[str] = []
    for c0, c1 in zip(cuts[:-1], cuts[1:], strict=True):
        span = c1.frame - c0.frame
        lo = int(round((c0.beat_s - audio_offset_s) * ANALYSIS_RATE_HZ))
        hi = int(round((c1.beat_s - audio_offset_s) * ANALYSIS_RATE_HZ))
        phrase = audio[max(lo, 0) : max(hi, 0)]
        try:
            if phrase.size < 4 * AR_ORDER:
                raise ARFitError(f"{phrase.size} samples of music")
            sound = sound_parameters(phrase)
        except ARFitError as exc:
            note = f"frames {c0.frame}-{c1.frame} left out: phrase not fitted ({exc})"
            log.warning("%s: %s", source or "capture", note)
            notes.append(note)
            continue
        segments.append(
            Segment(
                rotations=bvh.rotations[c0.frame : c1.frame + 1].copy(),
                root_positions=bvh.positions[c0.frame : c1.frame + 1, root].copy(),
                sound=sound,
                span=span,
                source=source,
                start_frame=c0.frame,
            )
        )
    return DanceDatabase(tuple(bvh.joints), fps, parts, tuple(segments), tuple(notes))


def merge(databases: Sequence[DanceDatabase]) -> DanceDatabase:
    """One database of all segments; the skeletons, fps and parts must agree."""
    if not databases:
        raise DanceError("nothing to merge")
    first = databases[0]
    for db in databases[1:]:
        if [j.name for j in db.joints] != [j.name for j in first.joints] or db.fps != first.fps:
            raise DanceError("databases of different skeletons or frame rates cannot be merged")
        if db.parts != first.parts:
            raise DanceError(f"databases cut by different parts ({first.parts}, {db.parts})")
    return DanceDatabase(
        first.joints, first.fps, first.parts, tuple(s for db in databases for s in db.segments)
    )


def save_database(db: DanceDatabase, folder: str | Path) -> None:
    """Write ``manifest.json`` and ``segments.npz`` into ``folder`` (created)."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    manifest = {
        "format": FORMAT,
        "version": VERSION,
        "fps": db.fps,
        "parts": db.parts,
        "joints": [
            {
                "name": j.name,
                "parent": j.parent,
                "offset": list(j.offset),
                "channels": list(j.channels),
                "end_site": list(j.end_site) if j.end_site is not None else None,
            }
            for j in db.joints
        ],
        "segments": [
            {
                "span": s.span,
                "sound": [float(x) for x in s.sound],
                "source": s.source,
                "start_frame": s.start_frame,
            }
            for s in db.segments
        ],
    }
    n_j = len(db.joints)
    rot = (
        np.concatenate([s.rotations for s in db.segments]) if db.segments else np.zeros((0, n_j, 4))
    )
    pos = (
        np.concatenate([s.root_positions for s in db.segments]) if db.segments else np.zeros((0, 3))
    )
    np.savez_compressed(out / "segments.npz", rotations=rot, root_positions=pos)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")


def load_database(folder: str | Path) -> DanceDatabase:
    """Read a database folder; :class:`~virja.errors.InputFileError` names what is wrong."""
    src = Path(folder)
    mpath = src / "manifest.json"
    try:
        manifest = json.loads(mpath.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputFileError(src, "not a dance database (no manifest.json)") from None
    except (OSError, ValueError) as exc:
        raise InputFileError(mpath, f"unreadable manifest ({exc})") from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise InputFileError(mpath, f"not a {FORMAT} manifest")
    if manifest.get("version") != VERSION:
        raise InputFileError(
            mpath, f"database version {manifest.get('version')!r}; this virja reads {VERSION}"
        )
    try:
        joints = tuple(
            BvhJoint(
                j["name"],
                int(j["parent"]),
                (float(j["offset"][0]), float(j["offset"][1]), float(j["offset"][2])),
                tuple(j["channels"]),
                tuple(float(x) for x in j["end_site"]) if j["end_site"] is not None else None,  # type: ignore[arg-type]
            )
            for j in manifest["joints"]
        )
        with np.load(src / "segments.npz") as z:
            rot = np.asarray(z["rotations"], dtype=np.float64)
            pos = np.asarray(z["root_positions"], dtype=np.float64)
        segments: list[Segment] = []
        at = 0
        for s in manifest["segments"]:
            span = int(s["span"])
            segments.append(
                Segment(
                    rotations=rot[at : at + span + 1],
                    root_positions=pos[at : at + span + 1],
                    sound=np.asarray(s["sound"], dtype=np.float64),
                    span=span,
                    source=str(s.get("source", "")),
                    start_frame=int(s.get("start_frame", 0)),
                )
            )
            at += span + 1
        if at != rot.shape[0] or rot.shape[0] != pos.shape[0] or rot.shape[1:] != (len(joints), 4):
            raise ValueError(f"segments.npz holds {rot.shape[0]} frames, the manifest {at}")
        return DanceDatabase(
            joints, float(manifest["fps"]), str(manifest["parts"]), tuple(segments)
        )
    except (KeyError, TypeError, ValueError, OSError, IndexError, zipfile.BadZipFile) as exc:
        raise InputFileError(src, f"corrupt dance database ({exc})") from exc
