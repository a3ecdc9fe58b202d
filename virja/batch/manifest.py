"""A job's result, its outputs placed atomically, and the manifest of the batch.

Outputs are written under a private temporary name in the output folder and
renamed into place (``os.replace``), so a file under its final name is always
whole: a batch killed halfway leaves no half-written file that
``--skip-existing`` could take as done.  The manifest (``manifest.jsonl``) gets
one JSON object per input as it finishes (appended and flushed, so a killed
batch leaves the lines of what it did), and is rewritten in input order at the
end.
"""

from __future__ import annotations

import enum
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

MANIFEST_NAME = "manifest.jsonl"
PARTIAL_DIR = ".virja-partial"  # temporary files while outputs are placed


class Status(enum.StrEnum):
    OK = "ok"
    ERROR = "error"
    SKIPPED = "skipped"


@dataclass
class JobResult:
    """What became of one input.  ``files`` maps output names (relative to the
    output folder) to their bytes, until :func:`place_outputs` writes them."""

    rel: str
    status: Status
    seconds: float
    files: dict[str, bytes] = field(default_factory=dict)
    outputs: list[str] = field(default_factory=list)
    error: str | None = None

    def manifest_row(self, input_dir: Path, out_dir: Path) -> dict[str, Any]:
        row: dict[str, Any] = {
            "input": str(input_dir / self.rel),
            "status": self.status.value,
            "outputs": [str(out_dir / name) for name in self.outputs],
            "seconds": round(self.seconds, 3),
        }
        if self.error is not None:
            row["error"] = self.error
        return row


def outputs_exist(out_dir: Path, names: tuple[str, ...]) -> bool:
    """True when every output is there under its final name (so it is whole)."""
    return bool(names) and all((out_dir / name).is_file() for name in names)


def _file_mode() -> int:
    """rw for everyone the umask allows, as ``open()`` would create the file."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def place_outputs(result: JobResult, out_dir: Path) -> None:
    """Write ``result.files`` into ``out_dir`` atomically; on failure the result
    becomes an error naming the file and the reason, and no partial file stays."""
    partial = out_dir / PARTIAL_DIR
    mode = _file_mode()
    placed: list[str] = []
    try:
        partial.mkdir(parents=True, exist_ok=True)
        for name, data in result.files.items():
            final = out_dir / name
            final.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=partial, prefix=final.name + ".")
            try:
                os.fchmod(fd, mode)  # mkstemp makes 0600; outputs are ordinary files
                with os.fdopen(fd, "wb") as fh:
                    fh.write(data)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.replace(tmp, final)
            except BaseException:
                Path(tmp).unlink(missing_ok=True)
                raise
            placed.append(name)
    except OSError as exc:
        result.status = Status.ERROR
        where = exc.filename or out_dir
        result.error = f"cannot write {where}: {exc.strerror or exc}"
        for name in placed:  # all or nothing: an input's outputs are whole or absent
            (out_dir / name).unlink(missing_ok=True)
        placed = []
    result.outputs = placed
    result.files = {}


def clear_partial(out_dir: Path) -> None:
    """Remove what a killed batch left in the temporary folder."""
    shutil.rmtree(out_dir / PARTIAL_DIR, ignore_errors=True)


class Manifest:
    """``OUT/manifest.jsonl``: a line per finished input, flushed as it comes."""

    def __init__(self, input_dir: Path, out_dir: Path) -> None:
        self.input_dir = input_dir
        self.out_dir = out_dir
        self.path = out_dir / MANIFEST_NAME
        self.rows: list[dict[str, Any]] = []
        self._fh: IO[str] = self.path.open("w", encoding="utf-8")

    def add(self, result: JobResult) -> dict[str, Any]:
        row = result.manifest_row(self.input_dir, self.out_dir)
        self.rows.append(row)
        self._fh.write(json.dumps(row) + "\n")
        self._fh.flush()
        return row

    def close(self) -> None:
        """Rewrite the manifest in input order (atomically) and close it."""
        self._fh.close()
        rows = sorted(self.rows, key=lambda r: str(r["input"]))
        tmp = self.path.with_name(self.path.name + ".tmp")
        with tmp.open("w", encoding="utf-8") as fh:
            for row in rows:
                fh.write(json.dumps(row) + "\n")
        os.replace(tmp, self.path)


def read_manifest(path: Path) -> list[dict[str, Any]]:
    """The rows of a manifest (for tests and tools)."""
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]
