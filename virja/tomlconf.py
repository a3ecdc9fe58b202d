"""The one loader of every TOML file virja reads: read, parse, convert to a schema.

Each file kind declares its schema once, as :class:`Schema` structs (msgspec,
docs/dependencies.md) beside the code that uses it; :func:`load` (a file) and
:func:`convert` (a table already read, e.g. ``[routing]`` of the config file)
turn a document into that schema.  A wrong type, a missing key, an unknown key,
a number that is not finite or a value refused by a schema's ``__post_init__``
is one error of one line naming the file, the key path and what was expected::

    virja.toml [plan]: bass_frets must be an integer, got str '20'
    motions/timing.toml: motion.snare.min_interval_s must be a number, got str '0.2'
    clip.toml: colour: unknown key; known: fret, impact_s, joints, ...

Every float a TOML file gives must be finite (no schema here wants ``nan`` or
``inf``).  Checks of meaning beyond one value (strings low to high, a kit note's
limb fitting its piece) stay with the types built from the schema.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
import tomllib
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

import msgspec

from virja.errors import ConfigError

T = TypeVar("T")
ErrorFactory = Callable[[str, str], Exception]  # (where, reason) -> the error to raise


class Schema(msgspec.Struct, forbid_unknown_fields=True, kw_only=True):
    """Base of every TOML schema: unknown keys are refused, fields are named."""


class SchemaError(ConfigError):
    """A table does not fit its schema: ``where`` (the file), ``key`` (the key path,
    "" for the whole table) and ``reason`` (a sentence that starts with the key)."""

    def __init__(self, where: str, key: str, reason: str) -> None:
        self.where, self.key, self.reason = where, key, reason
        super().__init__(f"{where}: {reason}")


def config_error(where: str, reason: str) -> Exception:
    return ConfigError(f"{where}: {reason}")


def read_text(path: str | Path, *, noun: str = "", error: ErrorFactory = config_error) -> str:
    """The text of the file at ``path``; an unreadable or non-UTF-8 file is
    ``error(path, reason)`` (``noun``, e.g. "config file", names it in the reason)."""
    p = Path(path)
    what = f" {noun}" if noun else ""
    try:
        return p.read_text(encoding="utf-8")
    except OSError as exc:
        raise error(str(p), f"cannot read{what}: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        is_ = f"{noun} is " if noun else ""
        raise error(str(p), f"{is_}not UTF-8 text: {exc.reason} at byte {exc.start}") from None
    except ValueError as exc:  # a path with a NUL byte
        raise error(repr(str(p)), f"cannot read{what}: {exc}") from None


def parse(text: str, where: str, *, error: ErrorFactory = config_error) -> dict[str, Any]:
    """The TOML document ``text``; invalid TOML is ``error(where, reason)``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(where, f"invalid TOML: {exc}") from None


def read(path: str | Path, *, noun: str = "", error: ErrorFactory = config_error) -> dict[str, Any]:
    """The TOML document at ``path`` (see :func:`read_text`)."""
    return parse(read_text(path, noun=noun, error=error), str(path), error=error)


def load(
    path: str | Path, schema: type[T], *, noun: str = "", error: ErrorFactory = config_error
) -> T:
    """The file at ``path`` as ``schema``: reading errors by ``error``, a document that
    does not fit the schema by :class:`SchemaError`."""
    return convert(read(path, noun=noun, error=error), schema, str(path))


def convert(data: Mapping[str, Any], schema: type[T], where: str, *, finite: bool = True) -> T:
    """``data`` (a TOML table) as ``schema``; ``where`` names the table in errors.
    Raises :class:`SchemaError`.  ``finite=False`` leaves the check of numbers to the
    schemas of the tables inside (the config document's layers)."""
    try:
        out = msgspec.convert(data, schema, strict=True, str_keys=True)
    except msgspec.ValidationError as exc:
        key, reason = _reason(data, schema, str(exc))
        raise SchemaError(where, key, reason) from None
    if finite:
        _check_finite(data, (), where)
    return out


def schema_of(cls: type[Any]) -> type[Schema]:
    """A schema with the fields, types and defaults of dataclass ``cls`` (a flat table
    whose keys are exactly the dataclass's fields); build ``cls`` with :func:`fields`."""
    hints = typing.get_type_hints(cls)
    spec: list[tuple[str, Any, Any] | tuple[str, Any]] = []
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            spec.append((f.name, hints[f.name], f.default))
        else:
            spec.append((f.name, hints[f.name]))
    return typing.cast(
        type[Schema],
        msgspec.defstruct(
            f"{cls.__name__}Table",
            spec,
            bases=(Schema,),
            forbid_unknown_fields=True,
            kw_only=True,
            module=cls.__module__,
        ),
    )


def fields(value: Schema) -> dict[str, Any]:
    """A schema value's fields as keyword arguments."""
    return msgspec.structs.asdict(value)


# -- errors in words --------------------------------------------------------------

_AT = re.compile(r"^(?P<msg>.*?)(?: - at `\$(?P<path>[^`]*)`)?$", re.S)
_SEGMENT = re.compile(r"\.([^.\[]+)|\[([^\]]*)\]")
_EXPECTED = re.compile(r"^Expected `(?P<types>[^`]+)`(?P<rest>.*?), got `(?P<got>[^`]+)`$")
_UNKNOWN = re.compile(r"^Object contains unknown field `(?P<key>[^`]+)`$")
_MISSING = re.compile(r"^Object missing required field `(?P<key>[^`]+)`$")
_NOUNS = {
    "int": "an integer",
    "float": "a number",
    "str": "a string",
    "bool": "true or false",
    "object": "a table",
    "array": "a list",
}

Segment = str | int


def _key_path(path: tuple[Segment, ...]) -> str:
    out = ""
    for seg in path:
        out += f"[{seg}]" if isinstance(seg, int) else (f".{seg}" if out else seg)
    return out


def _what(value: object) -> str:
    return f"{type(value).__name__} {value!r}"[:80]


def _check_finite(value: object, path: tuple[Segment, ...], where: str) -> None:
    if isinstance(value, float) and not math.isfinite(value):
        key = _key_path(path)
        raise SchemaError(where, key, f"{key} must be finite, got {value!r}")
    if isinstance(value, Mapping):
        for k, v in value.items():
            _check_finite(v, (*path, str(k)), where)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_finite(v, (*path, i), where)


def _at(data: object, path: tuple[Segment, ...]) -> object:
    for seg in path:
        data = data[seg]  # type: ignore[index]
    return data


def _replace(data: object, path: tuple[Segment, ...], value: object) -> object:
    if not path:
        return value
    out = copy.copy(data)
    out[path[0]] = _replace(data[path[0]], path[1:], value)  # type: ignore[index]
    return out


def _pin_keys(
    data: Mapping[str, Any], schema: type[Any], msg: str, path: tuple[Segment | None, ...]
) -> tuple[Segment, ...]:
    """msgspec writes ``[...]`` for a table's key: find which key fails with ``msg``
    by converting the document with that table cut down to one entry at a time."""
    known: tuple[Segment, ...] = ()
    for i, seg in enumerate(path):
        if seg is not None:
            known = (*known, seg)
            continue
        table = _at(data, known)
        if not isinstance(table, Mapping):
            return known
        for key, value in table.items():
            trial = _replace(data, known, {key: value})
            try:
                msgspec.convert(trial, schema, strict=True, str_keys=True)
            except msgspec.ValidationError as exc:
                if _AT.match(str(exc)).group("msg") == msg:  # type: ignore[union-attr]
                    known = (*known, str(key))
                    break
        else:
            return (*known, "[...]", *(s for s in path[i + 1 :] if s is not None))
    return known


def _reason(data: Mapping[str, Any], schema: type[Any], text: str) -> tuple[str, str]:
    m = _AT.match(text)
    assert m is not None
    msg, raw = m.group("msg"), m.group("path") or ""
    segs: list[Segment | None] = []
    for name, index in _SEGMENT.findall(raw):
        if name:
            segs.append(name)
        else:
            segs.append(None if index == "..." else int(index))
    path = _pin_keys(data, schema, msg, tuple(segs))
    here = _key_path(path)
    if u := _UNKNOWN.match(msg):
        key = _key_path((*path, u.group("key")))
        known = _fields_at(schema, path)
        return key, f"{key}: unknown key" + (f"; known: {', '.join(known)}" if known else "")
    if u := _MISSING.match(msg):
        full = (*path, u.group("key"))
        noun = _noun_at(schema, full)
        return _key_path(full), f"missing {_key_path(full)}" + (f" ({noun})" if noun else "")
    if e := _EXPECTED.match(msg):
        nouns = [_NOUNS.get(t, t) for t in e.group("types").split(" | ") if t != "null"]
        try:
            got = _what(_at(data, path))
        except (KeyError, IndexError, TypeError):
            got = e.group("got")
        return (
            here,
            f"{here or 'the table'} must be {' or '.join(nouns)}{e.group('rest')}, got {got}",
        )
    if msg == "Number out of range":
        return here, f"{here} = {_at(data, path)!r} is out of range"
    return here, (f"{here}: {msg}" if here else msg)


def _type_at(schema: type[Any], path: tuple[Segment, ...]) -> msgspec.inspect.Type:
    """The schema's type of the value at ``path`` (AnyType where it cannot tell)."""
    t: msgspec.inspect.Type = msgspec.inspect.type_info(schema)
    for seg in path:
        t = _inner(t)
        if isinstance(t, msgspec.inspect.StructType) and isinstance(seg, str):
            t = next((f.type for f in t.fields if f.encode_name == seg), msgspec.inspect.AnyType())
        elif isinstance(t, msgspec.inspect.DictType):
            t = t.value_type
        elif isinstance(t, msgspec.inspect.ListType | msgspec.inspect.VarTupleType):
            t = t.item_type
        else:
            return msgspec.inspect.AnyType()
    return _inner(t)


def _fields_at(schema: type[Any], path: tuple[Segment, ...]) -> list[str]:
    """The keys the schema allows in the table at ``path`` (for an unknown key's error)."""
    t = _type_at(schema, path)
    if isinstance(t, msgspec.inspect.StructType):
        return sorted(f.encode_name for f in t.fields)
    return []


_TYPE_NOUNS: tuple[tuple[type[msgspec.inspect.Type], str], ...] = (
    (msgspec.inspect.IntType, "an integer"),
    (msgspec.inspect.FloatType, "a number"),
    (msgspec.inspect.StrType, "a string"),
    (msgspec.inspect.BoolType, "true or false"),
    (msgspec.inspect.StructType, "a table"),
    (msgspec.inspect.DictType, "a table"),
    (msgspec.inspect.ListType, "a list"),
    (msgspec.inspect.TupleType, "a list"),
)


def _noun_at(schema: type[Any], path: tuple[Segment, ...]) -> str:
    t = _type_at(schema, path)
    return next((noun for cls, noun in _TYPE_NOUNS if isinstance(t, cls)), "")


def _inner(t: msgspec.inspect.Type) -> msgspec.inspect.Type:
    """A union's table type (``X | None`` -> X)."""
    if isinstance(t, msgspec.inspect.UnionType):
        for option in t.types:
            if isinstance(
                option,
                msgspec.inspect.StructType | msgspec.inspect.DictType | msgspec.inspect.ListType,
            ):
                return option
    return t
