"""Which inputs a batch has, and where each one's outputs go (pure, no I/O but the walk).

An output mirrors its input's path below the input folder:
``IN/drummer1/session1/take.mid`` with ``--export plan,bvh`` gives
``OUT/drummer1/session1/take.plan.jsonl``, ``take_drums.bvh`` and ``take_bass.bvh``.
"""

from __future__ import annotations

import enum
import os
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from virja.errors import ConfigError, InputFileError
from virja.input import MIDI_SUFFIXES, PCAP_SUFFIXES

INPUT_SUFFIXES = MIDI_SUFFIXES | PCAP_SUFFIXES


class OutputKind(enum.StrEnum):
    """What a batch can make of one input; the value is the name on the command line."""

    PLAN = "plan"  # the plan, exactly as `virja plan --json` prints it
    BVH = "bvh"  # one BVH per figure (`virja export --bvh`)
    GLTF = "gltf"  # the band as binary glTF (`virja export --gltf`)
    MUSICXML = "musicxml"  # notation with string/fret and sticking (`virja export --musicxml`)
    MP4 = "mp4"  # video with sound (`virja render`)


# file names of each kind's outputs, from the input's stem
OUTPUT_NAMES: dict[OutputKind, tuple[str, ...]] = {
    OutputKind.PLAN: ("{stem}.plan.jsonl",),
    OutputKind.BVH: ("{stem}_drums.bvh", "{stem}_bass.bvh"),
    OutputKind.GLTF: ("{stem}.glb",),
    OutputKind.MUSICXML: ("{stem}.musicxml",),
    OutputKind.MP4: ("{stem}.mp4",),
}


def parse_kinds(text: str) -> tuple[OutputKind, ...]:
    """ "plan,bvh" -> (PLAN, BVH); unknown or repeated names are a ConfigError."""
    names = [n.strip().lower() for n in text.split(",") if n.strip()]
    if not names:
        raise ConfigError(
            "--export needs at least one of " + ", ".join(k.value for k in OutputKind)
        )
    kinds: list[OutputKind] = []
    for name in names:
        try:
            kind = OutputKind(name)
        except ValueError:
            raise ConfigError(
                f"--export: unknown output {name!r}; choose from "
                + ", ".join(k.value for k in OutputKind)
            ) from None
        if kind in kinds:
            raise ConfigError(f"--export: {name!r} named twice")
        kinds.append(kind)
    return tuple(kinds)


@dataclass(frozen=True)
class Job:
    """One input and the outputs to make of it.

    ``rel`` is the input's path below the input folder (POSIX form, as it
    appears in the manifest's mirror of the tree); ``outputs`` pairs each kind
    with the files it makes, relative to the output folder.
    """

    rel: str
    kinds: tuple[OutputKind, ...]

    @property
    def stem(self) -> str:
        return PurePosixPath(self.rel).stem

    def output_names(self, kind: OutputKind) -> tuple[str, ...]:
        parent = PurePosixPath(self.rel).parent
        return tuple(str(parent / name.format(stem=self.stem)) for name in OUTPUT_NAMES[kind])

    def all_outputs(self) -> tuple[str, ...]:
        return tuple(name for kind in self.kinds for name in self.output_names(kind))


def discover(root: Path) -> list[str]:
    """Every MIDI file and pcap below ``root``, as sorted POSIX paths relative to it.

    Hidden folders and files (a name starting with a dot) are passed over, as
    are symbolic links to folders (no cycles).  A missing or empty folder is an
    InputFileError.
    """
    if not root.is_dir():
        raise InputFileError(root, "not a folder (give the folder that holds the MIDI files)")
    found: list[str] = []
    for folder, dirs, files in os.walk(root, onerror=None, followlinks=False):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for name in files:
            if name.startswith(".") or Path(name).suffix.lower() not in INPUT_SUFFIXES:
                continue
            found.append(Path(folder, name).relative_to(root).as_posix())
    if not found:
        raise InputFileError(
            root,
            "no MIDI files or pcap recordings below it (" + ", ".join(sorted(INPUT_SUFFIXES)) + ")",
        )
    return sorted(found)


def make_jobs(rels: list[str], kinds: tuple[OutputKind, ...]) -> list[Job]:
    """One job per input.  Two inputs whose outputs would collide (``a.mid`` and
    ``a.midi`` in one folder) are refused before any work."""
    jobs = [Job(rel, kinds) for rel in rels]
    owner: dict[str, str] = {}
    for job in jobs:
        for name in job.all_outputs():
            if name in owner:
                raise ConfigError(
                    f"{owner[name]} and {job.rel} would both write {name}; "
                    "rename one of them or batch them separately"
                )
            owner[name] = job.rel
    return jobs
