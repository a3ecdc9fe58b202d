"""BVH (Biovision hierarchy) reading and writing.

A :class:`Bvh` holds the hierarchy (joint names, parents, rest offsets,
channel orders, end sites) and the frames converted to our convention:

- ``rotations``: (n_frames, n_joints, 4) float64 local rotations, w x y z
  (see :mod:`virja.quat`); the Euler channels of each joint are read
  in the file's own order (``Zrotation Xrotation Yrotation`` -> ``R = Rz Rx Ry``);
- ``positions``: (n_frames, n_joints, 3) float64 local translations in the
  file's units: the position channels where a joint has them (the root's
  translation), its OFFSET otherwise.

Angles in the file are degrees.  A malformed file raises
:class:`BvhError` (an :class:`~virja.errors.InputFileError`) naming the file
and the line.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from virja import quat
from virja.errors import InputFileError

_ROT = {"Xrotation": "X", "Yrotation": "Y", "Zrotation": "Z"}
_POS = {"Xposition": 0, "Yposition": 1, "Zposition": 2}

# Numbers are ASCII only: str.isdigit() and float() also accept other scripts' digits
# ("²", "٣") and float() accepts "nan", "inf" and "1_0"; none of them belong in a BVH.
_COUNT = re.compile(r"[0-9]+\Z")
_NUM = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_NUMBER = re.compile(_NUM + r"\Z")
_FRAME_LINE = re.compile(rf"\s*(?:{_NUM}(?:\s+{_NUM})*)?\s*\Z")


class BvhError(InputFileError):
    """A BVH file is malformed; the message names the file and the line."""

    def __init__(self, path: object, line: int, reason: str) -> None:
        self.line = line
        super().__init__(path, f"line {line}: {reason}")


@dataclass(frozen=True)
class BvhJoint:
    """One joint: ``parent`` index (-1 for the root), rest ``offset`` (3,), ``channels``."""

    name: str
    parent: int
    offset: tuple[float, float, float]
    channels: tuple[str, ...]
    end_site: tuple[float, float, float] | None = None

    @property
    def rotation_order(self) -> str:
        """Axes of the rotation channels in file order, e.g. ``"ZXY"`` ("" if none)."""
        return "".join(_ROT[c] for c in self.channels if c in _ROT)


@dataclass
class Bvh:
    """A BVH file in memory (see the module docstring for shapes and units)."""

    joints: list[BvhJoint]
    frame_time_s: float
    rotations: np.ndarray
    positions: np.ndarray
    source: str = field(default="<memory>")

    @property
    def names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def parents(self) -> np.ndarray:
        return np.array([j.parent for j in self.joints], dtype=np.int64)

    @property
    def offsets(self) -> np.ndarray:
        return np.array([j.offset for j in self.joints], dtype=np.float64)

    @property
    def n_frames(self) -> int:
        return int(self.rotations.shape[0])

    def __post_init__(self) -> None:
        n = len(self.joints)
        if self.rotations.ndim != 3 or self.rotations.shape[1:] != (n, 4):
            raise ValueError(f"rotations must be (n_frames, {n}, 4), got {self.rotations.shape}")
        if self.positions.shape != self.rotations.shape[:2] + (3,):
            raise ValueError(f"positions must be (n_frames, {n}, 3), got {self.positions.shape}")
        if not self.frame_time_s > 0:
            raise ValueError(f"frame time must be > 0 s, got {self.frame_time_s}")


class _Tokens:
    """Whitespace tokens with their 1-based line numbers."""

    def __init__(self, path: str, lines: list[str], start: int, end: int) -> None:
        self.path = path
        self._items: list[tuple[str, int]] = []
        for n in range(start, end):
            for tok in lines[n].split():
                self._items.append((tok, n + 1))
        self._i = 0
        self._last_line = end if end > 0 else 1

    def next(self, what: str) -> tuple[str, int]:
        if self._i >= len(self._items):
            raise BvhError(
                self.path, self._last_line, f"unexpected end of hierarchy, expected {what}"
            )
        item = self._items[self._i]
        self._i += 1
        return item

    def expect(self, word: str) -> int:
        tok, line = self.next(repr(word))
        if tok != word:
            raise BvhError(self.path, line, f"expected {word!r}, got {tok!r}")
        return line

    def number(self, what: str) -> float:
        """A finite decimal number (ASCII digits; no nan, inf or overflow)."""
        tok, line = self.next(what)
        value = float(tok) if _NUMBER.match(tok) else float("nan")
        if not np.isfinite(value):
            raise BvhError(self.path, line, f"expected a finite number for {what}, got {tok!r}")
        return value

    def count(self, what: str) -> tuple[int, int]:
        """A whole number of ASCII digits, and its line."""
        tok, line = self.next(what)
        if not _COUNT.match(tok):
            raise BvhError(self.path, line, f"expected {what} (a whole number), got {tok!r}")
        return int(tok), line

    def peek(self) -> str | None:
        return self._items[self._i][0] if self._i < len(self._items) else None


def _joint_header(tk: _Tokens, name: str, parent: int) -> BvhJoint:
    """``{ OFFSET x y z CHANNELS n ch...`` of one joint (the opening brace included)."""
    tk.expect("{")
    tk.expect("OFFSET")
    offset = (tk.number("OFFSET x"), tk.number("OFFSET y"), tk.number("OFFSET z"))
    tok, line = tk.next("CHANNELS")
    if tok != "CHANNELS":
        raise BvhError(tk.path, line, f"expected 'CHANNELS' in joint {name!r}, got {tok!r}")
    count, line = tk.count("a channel count")
    if count > 6:
        raise BvhError(tk.path, line, f"joint {name!r} has {count} channels, at most 6 allowed")
    channels: list[str] = []
    for _ in range(count):
        ch, line = tk.next("a channel name")
        if ch not in _ROT and ch not in _POS:
            raise BvhError(tk.path, line, f"unknown channel {ch!r} in joint {name!r}")
        channels.append(ch)
    if len(set(channels)) != len(channels):
        raise BvhError(tk.path, line, f"joint {name!r} lists a channel twice: {' '.join(channels)}")
    rot = [c for c in channels if c in _ROT]
    if rot and len(rot) != 3:
        raise BvhError(
            tk.path, line, f"joint {name!r} needs 0 or 3 rotation channels, has {len(rot)}"
        )
    return BvhJoint(name, parent, offset, tuple(channels))


def _parse_joints(tk: _Tokens, root: str) -> list[BvhJoint]:
    """The joints of one ROOT, depth first, parsed with an explicit stack of open joints
    (no recursion: a hostile file nesting thousands of JOINTs is parsed, not a
    RecursionError)."""
    joints = [_joint_header(tk, root, -1)]
    open_joints = [0]  # indices of the joints whose '}' has not come yet
    while open_joints:
        index = open_joints[-1]
        tok, line = tk.next("'JOINT', 'End' or '}'")
        if tok == "}":
            open_joints.pop()
        elif tok == "JOINT":
            child, _ = tk.next("a joint name")
            joints.append(_joint_header(tk, child, index))
            open_joints.append(len(joints) - 1)
        elif tok == "End":
            tk.expect("Site")
            tk.expect("{")
            tk.expect("OFFSET")
            end = (tk.number("End Site x"), tk.number("End Site y"), tk.number("End Site z"))
            tk.expect("}")
            j = joints[index]
            joints[index] = BvhJoint(j.name, j.parent, j.offset, j.channels, end)
        else:
            raise BvhError(tk.path, line, f"expected 'JOINT', 'End' or '}}', got {tok!r}")
    return joints


def parse_bvh(text: str, path: str = "<string>") -> Bvh:
    """Parse BVH text; errors name ``path`` and the line."""
    lines = text.splitlines()
    motion_at = next((i for i, ln in enumerate(lines) if ln.strip() == "MOTION"), None)
    if motion_at is None:
        raise BvhError(path, max(len(lines), 1), "no MOTION section")
    tk = _Tokens(path, lines, 0, motion_at)
    tk.expect("HIERARCHY")
    tok, line = tk.next("'ROOT'")
    if tok != "ROOT":
        raise BvhError(path, line, f"expected 'ROOT', got {tok!r}")
    name, _ = tk.next("the root's name")
    joints = _parse_joints(tk, name)
    if tk.peek() is not None:
        tok, line = tk.next("end")
        raise BvhError(path, line, f"only one ROOT is supported, got {tok!r} after it")
    dup = {n for n, k in Counter(j.name for j in joints).items() if k > 1}
    if dup:
        raise BvhError(path, 1, f"duplicate joint names {sorted(dup)}")

    n_frames, frame_time, first = _motion_header(lines, motion_at, path)
    n_channels = sum(len(j.channels) for j in joints)
    # count the frame lines before allocating: 'Frames:' is only a claim
    rows = [i for i in range(first, len(lines)) if not lines[i].isspace() and lines[i]]
    if len(rows) > n_frames:
        raise BvhError(path, rows[n_frames] + 1, f"more frame lines than 'Frames: {n_frames}'")
    if len(rows) < n_frames:
        raise BvhError(path, len(lines), f"'Frames: {n_frames}' but {len(rows)} frame lines")
    data = np.empty((n_frames, n_channels), dtype=np.float64)
    for row, i in enumerate(rows):
        if not _FRAME_LINE.match(lines[i]):
            raise BvhError(path, i + 1, "frame values must be decimal numbers")
        s = lines[i].split()
        if len(s) != n_channels:
            raise BvhError(
                path, i + 1, f"frame has {len(s)} values, the hierarchy has {n_channels} channels"
            )
        data[row] = [float(x) for x in s]
    if n_frames and not (finite := np.isfinite(data).all(axis=1)).all():
        i = rows[int(np.argmin(finite))]
        raise BvhError(path, i + 1, "frame value out of range (not a finite number)")
    rotations, positions = _channels_to_arrays(joints, data)
    return Bvh(joints, frame_time, rotations, positions, source=path)


def _motion_header(lines: list[str], motion_at: int, path: str) -> tuple[int, float, int]:
    def field_line(i: int, label: str) -> str:
        if i >= len(lines) or not lines[i].strip().startswith(label):
            raise BvhError(path, min(i + 1, max(len(lines), 1)), f"expected '{label}'")
        return lines[i].strip()[len(label) :].strip()

    frames_s = field_line(motion_at + 1, "Frames:")
    if not _COUNT.match(frames_s):
        raise BvhError(path, motion_at + 2, f"frame count must be a whole number, got {frames_s!r}")
    ft_s = field_line(motion_at + 2, "Frame Time:")
    if not _NUMBER.match(ft_s):
        raise BvhError(path, motion_at + 3, f"frame time must be a number, got {ft_s!r}")
    frame_time = float(ft_s)
    if not 0 < frame_time < float("inf"):
        raise BvhError(path, motion_at + 3, f"frame time must be finite and > 0, got {frame_time}")
    return int(frames_s), frame_time, motion_at + 3


def _channels_to_arrays(joints: list[BvhJoint], data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n_frames = data.shape[0]
    rotations = quat.identity((n_frames, len(joints)))
    positions = np.empty((n_frames, len(joints), 3), dtype=np.float64)
    col = 0
    # joints grouped by rotation order, converted in one call per order (a clip loads in
    # one numpy pass instead of one per joint; each joint's result is the same)
    groups: dict[str, tuple[list[int], list[list[int]]]] = {}
    for j, joint in enumerate(joints):
        positions[:, j] = joint.offset
        rot_cols: list[int] = []
        for ch in joint.channels:
            if ch in _POS:
                positions[:, j, _POS[ch]] = data[:, col]
            else:
                rot_cols.append(col)
            col += 1
        if rot_cols:
            idx, cols = groups.setdefault(joint.rotation_order, ([], []))
            idx.append(j)
            cols.append(rot_cols)
    for order, (idx, cols) in groups.items():
        rotations[:, idx] = quat.from_euler(np.radians(data[:, np.array(cols)]), order)
    return rotations, positions


def read_bvh(path: str | Path) -> Bvh:
    """Read a BVH file; raises :class:`BvhError` naming the file and line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFileError(p, f"cannot read BVH: {exc}") from exc
    return parse_bvh(text, str(p))


def _children(bvh: Bvh) -> dict[int, list[int]]:
    children: dict[int, list[int]] = {}
    for i, j in enumerate(bvh.joints):
        children.setdefault(j.parent, []).append(i)
    return children


def _dfs_order(bvh: Bvh) -> list[int]:
    """Joint indices in the order the hierarchy is written (and frame columns follow).

    ``bvh.joints`` may be in any order (a child before its parent too); raises
    ValueError unless there is exactly one root and every joint hangs from it.
    """
    children = _children(bvh)
    roots = children.get(-1, [])
    if len(roots) != 1:
        raise ValueError(f"a BVH is written with exactly one root joint, got {len(roots)}")
    out: list[int] = []
    stack = list(roots)
    while stack:
        i = stack.pop()
        out.append(i)
        stack.extend(reversed(children.get(i, [])))
    if len(out) != len(bvh.joints):
        lost = sorted(set(range(len(bvh.joints))) - set(out))
        names = [bvh.joints[i].name for i in lost[:5]]
        raise ValueError(f"joints {names} do not hang from the root (bad parent indices)")
    return out


def _hierarchy_lines(bvh: Bvh) -> Iterator[str]:
    """The HIERARCHY section, joints depth first as :func:`_dfs_order` (no recursion)."""
    children = _children(bvh)
    yield "HIERARCHY"
    # (joint, depth, closing): a joint is pushed to open it, then again to close it
    stack = [(root, 0, False) for root in reversed(children.get(-1, []))]
    while stack:
        i, depth, closing = stack.pop()
        j = bvh.joints[i]
        pad = "  " * depth
        if not closing:
            yield f"{pad}{'ROOT' if j.parent < 0 else 'JOINT'} {j.name}"
            yield f"{pad}{{"
            yield f"{pad}  OFFSET {_fmt(j.offset)}"
            yield f"{pad}  CHANNELS {len(j.channels)} {' '.join(j.channels)}".rstrip()
            stack.append((i, depth, True))
            stack.extend((c, depth + 1, False) for c in reversed(children.get(i, [])))
            continue
        if j.end_site is not None:
            yield f"{pad}  End Site"
            yield f"{pad}  {{"
            yield f"{pad}    OFFSET {_fmt(j.end_site)}"
            yield f"{pad}  }}"
        yield f"{pad}}}"


def _fmt(v: tuple[float, ...] | np.ndarray) -> str:
    return " ".join(f"{float(x):.6f}" for x in v)


def format_bvh(bvh: Bvh, decimals: int = 4) -> str:
    """BVH text for ``bvh`` (rotations written as Euler degrees in each joint's channel order).

    The hierarchy is written depth first and the frame columns in that same order,
    whatever the order of ``bvh.joints``: reading the text back gives the joints
    depth first, each with its own channels.  Raises ValueError for a joint list
    that is not one tree (see :func:`_dfs_order`).
    """
    cols: list[np.ndarray] = []
    for j in _dfs_order(bvh):
        joint = bvh.joints[j]
        euler = None
        if joint.rotation_order:
            euler = np.degrees(quat.to_euler(bvh.rotations[:, j], joint.rotation_order))
        r = 0
        for ch in joint.channels:
            if ch in _POS:
                cols.append(bvh.positions[:, j, _POS[ch]])
            else:
                assert euler is not None
                cols.append(euler[:, r])
                r += 1
    data = np.stack(cols, axis=-1) if cols else np.zeros((bvh.n_frames, 0))
    data = np.where(np.abs(data) < 0.5 * 10.0**-decimals, 0.0, data)  # no "-0.0000"
    out = list(_hierarchy_lines(bvh))
    out.append("MOTION")
    out.append(f"Frames: {bvh.n_frames}")
    out.append(f"Frame Time: {bvh.frame_time_s:.8f}")
    # one %-format per row (the same digits as formatting each number alone, several times faster)
    row_fmt = " ".join([f"%.{decimals}f"] * data.shape[1])
    out.extend(row_fmt % tuple(row) for row in data.tolist())
    return "\n".join(out) + "\n"


def write_bvh(bvh: Bvh, path: str | Path, decimals: int = 4) -> None:
    """Write ``bvh`` to ``path`` (see :func:`format_bvh`)."""
    Path(path).write_text(format_bvh(bvh, decimals), encoding="utf-8")


def world_pose(bvh: Bvh) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics of every frame: world positions (n, J, 3) in the file's units
    and world rotations (n, J, 4, w x y z).  Joints are listed parents first."""
    n, n_j = bvh.rotations.shape[:2]
    wrot = np.empty_like(bvh.rotations)
    wpos = np.empty((n, n_j, 3))
    for j, joint in enumerate(bvh.joints):
        p = joint.parent
        if p < 0:
            wrot[:, j] = bvh.rotations[:, j]
            wpos[:, j] = bvh.positions[:, j]
        else:
            wrot[:, j] = quat.multiply(wrot[:, p], bvh.rotations[:, j])
            wpos[:, j] = wpos[:, p] + quat.rotate(wrot[:, p], bvh.positions[:, j])
    return wpos, wrot
