"""Helpers of the fuzz tests: byte and token mutations, a TOML writer, a hang guard.

Every mutation is a small list of edits drawn by hypothesis and applied to a
valid input built in the test, so that the mutated input is mostly valid and
reaches deep into the parser (random bytes would stop at the magic number).
"""

from __future__ import annotations

import math
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any, Literal

from hypothesis import strategies as st

# byte values that sit on boundaries of lengths, counts, flags and VLQ continuation bits
INTERESTING_BYTES = (0x00, 0x01, 0x7F, 0x80, 0x81, 0xFE, 0xFF)

Edit = tuple[int, int, int]  # (operation, position, value)


def byte_edits(max_edits: int = 6) -> st.SearchStrategy[list[Edit]]:
    """Edits: 0 set a byte, 1 insert a byte, 2 delete a byte, 3 set an interesting byte,
    4 truncate, 5 duplicate a 4-byte run, 6/7 add value - 128 to the 4-aligned u32
    there (little/big-endian: nudges length and count fields)."""
    return st.lists(
        st.tuples(st.integers(0, 7), st.integers(0, 1 << 20), st.integers(0, 255)),
        min_size=1,
        max_size=max_edits,
    )


def apply_byte_edits(data: bytes, edits: list[Edit]) -> bytes:
    b = bytearray(data)
    for op, pos, value in edits:
        if not b:
            b.append(value)
            continue
        i = pos % len(b)
        if op == 0:
            b[i] = value
        elif op == 1:
            b.insert(i, value)
        elif op == 2:
            del b[i]
        elif op == 3:
            b[i] = INTERESTING_BYTES[value % len(INTERESTING_BYTES)]
        elif op == 4:
            del b[i:]
        elif op == 5:
            b[i:i] = b[i : i + 4]
        else:
            j = i & ~3
            if j + 4 <= len(b):
                order: Literal["little", "big"] = "little" if op == 6 else "big"
                word = (int.from_bytes(b[j : j + 4], order) + value - 128) % (1 << 32)
                b[j : j + 4] = word.to_bytes(4, order)
    return bytes(b)


def token_edits(vocabulary: tuple[str, ...], max_edits: int = 5) -> st.SearchStrategy[list[Edit]]:
    """Edits on whitespace tokens: 0 replace, 1 insert, 2 delete, 3 duplicate a line,
    4 delete a line, 5 truncate the text; the value indexes ``vocabulary``."""
    return st.lists(
        st.tuples(st.integers(0, 5), st.integers(0, 1 << 20), st.integers(0, len(vocabulary) - 1)),
        min_size=1,
        max_size=max_edits,
    )


def apply_token_edits(text: str, edits: list[Edit], vocabulary: tuple[str, ...]) -> str:
    """Apply token edits; lines keep their breaks so line numbers stay meaningful."""
    lines = [ln.split() for ln in text.splitlines()]
    for op, pos, value in edits:
        word = vocabulary[value]
        if op in (3, 4, 5):
            i = pos % max(len(lines), 1)
            if op == 3 and lines:
                lines.insert(i, list(lines[i]))
            elif op == 4 and lines:
                del lines[i]
            elif op == 5:
                del lines[i:]
            continue
        spots = [(li, ti) for li, ln in enumerate(lines) for ti in range(len(ln) + 1)]
        if not spots:
            lines.append([word])
            continue
        li, ti = spots[pos % len(spots)]
        if op == 0 and ti < len(lines[li]):
            lines[li][ti] = word
        elif op == 2 and ti < len(lines[li]):
            del lines[li][ti]
        else:
            lines[li].insert(ti, word)
    return "\n".join(" ".join(ln) for ln in lines) + "\n"


# -- TOML ---------------------------------------------------------------------------


def toml_value(v: Any) -> str:
    """One TOML value (inline tables for dicts); enough for the fuzzers' documents."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"no TOML for {type(v).__name__}")


def toml_key(k: str) -> str:
    return k if k and all(c.isalnum() or c in "_-" for c in k) else toml_value(k)


def toml_document(doc: dict[str, Any]) -> str:
    """``key = value`` lines, tables as ``[name]`` sections of their keys."""
    out = []
    tables = []
    for k, v in doc.items():
        if isinstance(v, dict):
            tables.append((k, v))
        else:
            out.append(f"{toml_key(k)} = {toml_value(v)}")
    for name, table in tables:
        out.append(f"[{toml_key(name)}]")
        out.extend(f"{toml_key(k)} = {toml_value(v)}" for k, v in table.items())
    return "\n".join(out) + "\n"


# values a mutated table may hold where the loader expects something else
odd_values: st.SearchStrategy[Any] = st.one_of(
    st.integers(-(1 << 70), 1 << 70),
    st.sampled_from([0, -1, 1, 127, 128, 1 << 63]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, 1e308]),
    st.text(alphabet="abcEADG_ 09", max_size=8),
    st.booleans(),
    st.lists(st.integers(-3, 200), max_size=3),
    st.just({}),
    st.just({"x": 1}),
)

Path_ = tuple[str | int, ...]


def paths_of(doc: Any, prefix: Path_ = ()) -> list[Path_]:
    """Every key path of a parsed document (dict keys and list indexes)."""
    out: list[Path_] = []
    items: list[tuple[str | int, Any]] = []
    if isinstance(doc, dict):
        items = list(doc.items())
    elif isinstance(doc, list):
        items = list(enumerate(doc))
    for k, v in items:
        out.append((*prefix, k))
        out.extend(paths_of(v, (*prefix, k)))
    return out


def mutate_doc(doc: Any, edits: list[tuple[int, int, Any]]) -> Any:
    """Edits: (0 replace | 1 delete, which path, new value) on a copy of ``doc``."""
    import copy

    doc = copy.deepcopy(doc)
    for op, which, value in edits:
        paths = paths_of(doc)
        if not paths:
            break
        path = paths[which % len(paths)]
        parent = doc
        for k in path[:-1]:
            parent = parent[k]
        key = path[-1]
        if op == 0:
            parent[key] = copy.deepcopy(value)  # hypothesis may share one object
        elif isinstance(parent, dict):
            del parent[key]
        else:
            del parent[key]
    return doc


def doc_edits() -> st.SearchStrategy[list[tuple[int, int, Any]]]:
    return st.lists(
        st.tuples(st.integers(0, 1), st.integers(0, 1 << 16), odd_values), min_size=1, max_size=3
    )


# -- hangs ----------------------------------------------------------------------------


class HangError(Exception):
    """The code under test ran past its time limit: a hang, never an accepted outcome."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise HangError in the main thread after ``seconds`` (SIGALRM; pure-Python loops)."""

    def on_alarm(signum: int, frame: FrameType | None) -> None:
        raise HangError(f"no result within {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# -- open bugs ------------------------------------------------------------------------

# (function in virja where the exception escapes, exception type) -> the regression test
# pinning it in test_regressions.py.  The fuzz tests tolerate exactly these so they keep
# looking for new bugs while the suite stays green; remove an entry with its fix.
KNOWN_BUGS: dict[tuple[str, str], str] = {}


def escaping_function(exc: BaseException) -> str:
    """The innermost named function of the virja package in the exception's traceback
    (a comprehension or generator expression counts as the function around it)."""
    name = "?"
    tb = exc.__traceback__
    while tb is not None:
        code = tb.tb_frame.f_code
        if "/virja/" in code.co_filename.replace("\\", "/") and not code.co_name.startswith("<"):
            name = code.co_name
        tb = tb.tb_next
    return name


def raise_unless_known_bug(exc: BaseException) -> None:
    """Re-raise ``exc`` unless it is one of :data:`KNOWN_BUGS` (then the fuzz example passes)."""
    if (escaping_function(exc), type(exc).__name__) not in KNOWN_BUGS:
        raise exc
