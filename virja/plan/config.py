"""The scheduler's tables, read from motions/*.toml, and the user's overrides.

- ``motions/bass.toml``: tunings, frets, double-stop span -> :class:`BassSetup`
- ``motions/drum_kit.toml``: GM note -> piece, limb, priority -> :class:`DrumKit`
- ``motions/drum_costs.toml``: the 15 x 14 hand table -> :class:`DrumCosts`
- ``motions/timing.toml``: anticipation and inter-stroke times -> :class:`Timing`

A user config file (``virja plan --config FILE.toml``) may override under
``[plan]``: ``bass_tuning`` (a tuning name), ``bass_strings`` (a list of
``{name, open}``), ``bass_frets``, ``double_stop_span_frets``, and
``drum_kit`` / ``drum_costs`` / ``timing`` (paths to replacement tables,
relative to the config file).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from virja.config import load_config, section
from virja.errors import ConfigError
from virja.resources import motions_dir

HAND_PIECES: tuple[str, ...] = (
    "snare",
    "hihat",
    "tom_high",
    "tom_low",
    "tom_floor",
    "ride",
    "crash",
)
HANDS: tuple[str, ...] = ("right_hand", "left_hand")
STRING_NAMES = frozenset({"E", "A", "D", "G", "B", "C"})
FOOT_KINDS = {("kick", "right_foot"): "kick", ("hihat", "left_foot"): "hihat_pedal"}


def _load_toml(path: Path) -> dict[str, Any]:
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text: {exc.reason}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from exc
    except ValueError as exc:  # a path with a NUL byte
        raise ConfigError(f"{path!r}: cannot read: {exc}") from exc


# -- typed access: a value of the wrong type anywhere is a ConfigError naming the key ------


def _what(value: object) -> str:
    return f"{type(value).__name__} {value!r}"[:80]


def _table(value: object, where: str, key: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: {key} must be a table, got {_what(value)}")
    return value


def _list(value: object, where: str, key: str) -> list[Any]:
    if not isinstance(value, list):
        raise ConfigError(f"{where}: {key} must be a list, got {_what(value)}")
    return value


def _str(value: object, where: str, key: str) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"{where}: {key} must be a string, got {_what(value)}")
    return value


def _opt_str(value: object, where: str, key: str) -> str | None:
    return None if value is None else _str(value, where, key)


def _int(value: object, where: str, key: str) -> int:
    """A TOML integer (a bool, a float or a string is refused, not converted)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(f"{where}: {key} must be an integer, got {_what(value)}")
    return value


def _float(value: object, where: str, key: str) -> float:
    """A finite number (TOML integer or float); NaN, inf, bools and strings are refused."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where}: {key} must be a number, got {_what(value)}")
    try:
        out = float(value)
    except OverflowError:  # an integer beyond float range
        raise ConfigError(f"{where}: {key} = {value} is out of range") from None
    if not math.isfinite(out):
        raise ConfigError(f"{where}: {key} must be finite, got {value!r}")
    return out


def _need(data: dict[str, Any], where: str, key: str, prefix: str = "") -> Any:
    try:
        return data[key]
    except KeyError:
        raise ConfigError(f"{where}: missing {prefix}{key}") from None


@dataclass(frozen=True)
class Fingering:
    """How the left hand covers the fingerboard (``[fingering]`` of motions/bass.toml).

    A hand *position* is the fret under the first finger (the thumb in thumb
    position); it covers ``span_frets`` frets above that (1-2-4 fingering: a whole
    tone) below ``thumb_position_fret``, ``thumb_span_frets`` from there on.
    Costs are in the paper's unit (one fret or one string of finger travel).
    """

    span_frets: int = 2
    thumb_position_fret: int = 12
    thumb_span_frets: int = 3
    shift_cost: float = 2.0
    shift_cost_per_fret: float = 0.5
    position_cost_per_fret: float = 0.1
    shift_time_s: float = 0.06
    shift_time_per_fret_s: float = 0.012
    rushed_shift_cost: float = 4.0

    def __post_init__(self) -> None:
        for key in ("span_frets", "thumb_position_fret", "thumb_span_frets"):
            if getattr(self, key) < 0:
                raise ConfigError(f"fingering {key} must be >= 0, got {getattr(self, key)}")
        for key in (
            "shift_cost",
            "shift_cost_per_fret",
            "position_cost_per_fret",
            "shift_time_s",
            "shift_time_per_fret_s",
            "rushed_shift_cost",
        ):
            if not getattr(self, key) >= 0:
                raise ConfigError(f"fingering {key} must be >= 0, got {getattr(self, key)}")

    def span(self, position: int) -> int:
        """Frets covered above ``position`` without a shift."""
        return self.thumb_span_frets if position >= self.thumb_position_fret else self.span_frets

    def shift_time(self, frets: int) -> float:
        """Seconds a shift of the hand by ``frets`` takes."""
        return self.shift_time_s + self.shift_time_per_fret_s * frets


@dataclass(frozen=True)
class BassSetup:
    """The bass: ``strings`` low to high as (name, open MIDI note)."""

    strings: tuple[tuple[str, int], ...]
    frets: int
    double_stop_span_frets: int
    fingering: Fingering = Fingering()

    def __post_init__(self) -> None:
        if not self.strings:
            raise ConfigError("bass needs at least one string")
        for name, open_note in self.strings:
            if name not in STRING_NAMES:
                raise ConfigError(f"bass string name {name!r} not one of {sorted(STRING_NAMES)}")
            if not 0 <= open_note <= 127:
                raise ConfigError(f"bass string {name}: open note {open_note} not 0-127")
        if len({n for n, _ in self.strings}) != len(self.strings):
            raise ConfigError("bass string names must be distinct")
        opens = [o for _, o in self.strings]
        if opens != sorted(opens):
            raise ConfigError("bass strings must be listed low to high")
        if not 1 <= self.frets <= 36:
            raise ConfigError(f"bass frets must be 1-36, got {self.frets}")
        # every note from the lowest open string up must be playable somewhere: the
        # frets must reach from one open string to a semitone below the next
        need = max((b - a - 1 for a, b in zip(opens, opens[1:], strict=False)), default=1)
        if self.frets < need:
            raise ConfigError(
                f"bass frets = {self.frets} leaves notes between the open strings unplayable; "
                f"this tuning needs at least {need} (36 at most)"
            )
        if self.double_stop_span_frets < 0:
            raise ConfigError("double_stop_span_frets must be >= 0")

    @property
    def lowest(self) -> int:
        return self.strings[0][1]

    @property
    def highest(self) -> int:
        return self.strings[-1][1] + self.frets


@dataclass(frozen=True)
class DrumNote:
    """Where a GM percussion note goes on the kit."""

    piece: str
    limb: str | None  # "right_foot"/"left_foot" for pedals; None = a hand, chosen by cost
    priority: int
    articulation: str | None
    name: str


@dataclass(frozen=True)
class DrumKit:
    notes: dict[int, DrumNote]

    def lookup(self, note: int) -> DrumNote | None:
        return self.notes.get(note)


@dataclass(frozen=True)
class DrumCosts:
    """``table[row][col]``: rows are the 14 motions then "none" (index 14)."""

    motions: tuple[str, ...]
    table: tuple[tuple[float, ...], ...]
    drop_penalty: float

    @property
    def none_row(self) -> int:
        return len(self.motions)

    def index(self, piece: str, hand: str) -> int:
        return self.motions.index(f"{piece}_{hand}")


@dataclass(frozen=True)
class MotionTiming:
    anticipation_s: float
    min_anticipation_s: float
    min_interval_s: float


@dataclass(frozen=True)
class Timing:
    """Impact alignment and inter-stroke times.  ``moves[(a, b)]``: the least time
    for one hand from a stroke on piece ``a`` to a stroke on piece ``b``, from the
    distance between them (:func:`hand_moves`); none given: the target's
    ``min_interval_s``."""

    reference_spb: float
    rest_s: float
    kinds: dict[str, MotionTiming]
    moves: dict[tuple[str, str], float] = field(default_factory=dict)
    # notes played at once (jam keys, RTP-MIDI: plan.immediate): the shortest stroke is
    # their normal form, so a note is late only when it lands later than that
    immediate: bool = False

    def get(self, kind: str) -> MotionTiming:
        try:
            return self.kinds[kind]
        except KeyError:
            raise ConfigError(f"timing table has no motion kind {kind!r}") from None

    def gap(self, prev: str | None, piece: str) -> float:
        """The least time between a hand's stroke on ``prev`` and its next on ``piece``:
        the piece's ``min_interval_s`` (rebound doubles on one piece), or the move
        between two pieces if that is longer."""
        base = self.get(piece).min_interval_s
        if prev is None or prev == piece:
            return base
        return max(base, self.moves.get((prev, piece), 0.0))

    @property
    def max_gap(self) -> float:
        """The longest :meth:`gap`: a stroke older than this constrains nothing."""
        return max(
            max((mt.min_interval_s for mt in self.kinds.values()), default=0.0),
            max(self.moves.values(), default=0.0),
        )


def hand_moves(base_s: float, speed_m_s: float) -> dict[tuple[str, str], float]:
    """``base_s`` + distance / ``speed_m_s`` between the strike points of every two hand
    pieces of the drawn kit (virja.geometry): lifting off one piece and landing on the
    other is quick, travelling across the kit is not."""
    from virja.geometry import GEOMETRY

    kit = GEOMETRY.kit
    pts = {p: kit.strike_point(p) for p in HAND_PIECES}
    return {
        (a, b): base_s + float(math.dist(pts[a], pts[b])) / speed_m_s
        for a in HAND_PIECES
        for b in HAND_PIECES
        if a != b
    }


@dataclass(frozen=True)
class PlanConfig:
    bass: BassSetup
    kit: DrumKit
    costs: DrumCosts
    timing: Timing


def parse_bass(
    data: dict[str, Any], *, tuning: str | None = None, where: str = "bass.toml"
) -> BassSetup:
    """The bass of a ``bass.toml`` table, with tuning ``tuning`` (default: its default)."""
    tunings = _table(_need(data, where, "tunings"), where, "tunings")
    name = (
        tuning
        if tuning is not None
        else _str(_need(data, where, "default_tuning"), where, "default_tuning")
    )
    if name not in tunings:
        raise ConfigError(f"{where}: unknown bass tuning {name!r}; known: {sorted(tunings)}")
    chosen = _table(tunings[name], where, f"tunings.{name}")
    strings = parse_strings(
        _need(chosen, where, "strings", f"tunings.{name}."), where, f"tunings.{name}.strings"
    )
    return BassSetup(
        strings,
        _int(_need(data, where, "frets"), where, "frets"),
        _int(_need(data, where, "double_stop_span_frets"), where, "double_stop_span_frets"),
        parse_fingering(_table(data.get("fingering", {}), where, "fingering"), where),
    )


def parse_fingering(data: dict[str, Any], where: str) -> Fingering:
    """The ``[fingering]`` table; keys left out keep :class:`Fingering`'s defaults."""
    ints = ("span_frets", "thumb_position_fret", "thumb_span_frets")
    floats = (
        "shift_cost",
        "shift_cost_per_fret",
        "position_cost_per_fret",
        "shift_time_s",
        "shift_time_per_fret_s",
        "rushed_shift_cost",
    )
    if unknown := sorted(set(data) - set(ints) - set(floats)):
        raise ConfigError(f"{where}: unknown key(s) in [fingering]: {', '.join(unknown)}")
    kw: dict[str, Any] = {k: _int(data[k], where, f"fingering.{k}") for k in ints if k in data}
    kw.update({k: _float(data[k], where, f"fingering.{k}") for k in floats if k in data})
    return Fingering(**kw)


def parse_strings(value: object, where: str, key: str) -> tuple[tuple[str, int], ...]:
    """A list of ``{name, open}`` tables -> ((name, open MIDI note), ...)."""
    out = []
    for i, s in enumerate(_list(value, where, key)):
        entry = _table(s, where, f"{key}[{i}]")
        out.append(
            (
                _str(_need(entry, where, "name", f"{key}[{i}]."), where, f"{key}[{i}].name"),
                _int(_need(entry, where, "open", f"{key}[{i}]."), where, f"{key}[{i}].open"),
            )
        )
    return tuple(out)


def _note_number(key: str, where: str) -> int:
    if not (key.isascii() and key.isdigit() and 0 <= int(key) <= 127):
        raise ConfigError(f"{where}: notes.{key}: a note key must be a MIDI note number 0-127")
    return int(key)


def parse_kit(data: dict[str, Any], *, where: str = "drum_kit.toml") -> DrumKit:
    """The kit of a ``drum_kit.toml`` table."""
    prio = _table(data.get("priority", {}), where, "priority")
    notes: dict[int, DrumNote] = {}
    for key, value in _table(data.get("notes", {}), where, "notes").items():
        k = f"notes.{key}"
        entry = _table(value, where, k)
        piece = _str(_need(entry, where, "piece", f"{k}."), where, f"{k}.piece")
        limb = _opt_str(entry.get("limb"), where, f"{k}.limb")
        if piece == "none" and limb is not None:
            raise ConfigError(f'{where}: drum note {key}: piece "none" (nobody) takes no limb')
        if limb is None and piece not in HAND_PIECES and piece != "none":
            raise ConfigError(f"{where}: drum note {key}: piece {piece!r} is not a hand piece")
        if limb is not None and (piece, limb) not in FOOT_KINDS:
            raise ConfigError(f"{where}: drum note {key}: {piece} cannot be played by {limb}")
        if "priority" in entry:
            priority = _int(entry["priority"], where, f"{k}.priority")
        else:
            priority = _int(prio.get(piece, 5), where, f"priority.{piece}")
        notes[_note_number(key, where)] = DrumNote(
            piece=piece,
            limb=limb,
            priority=priority,
            articulation=_opt_str(entry.get("articulation"), where, f"{k}.articulation"),
            name=_str(entry.get("name", ""), where, f"{k}.name"),
        )
    return DrumKit(notes)


def parse_costs(data: dict[str, Any], *, where: str = "drum_costs.toml") -> DrumCosts:
    """The hand cost table of a ``drum_costs.toml`` table (every cost a finite number)."""
    motions_list = _list(_need(data, where, "motions"), where, "motions")
    motions = tuple(_str(m, where, f"motions[{i}]") for i, m in enumerate(motions_list))
    expected = {f"{p}_{h}" for p in HAND_PIECES for h in HANDS}
    if set(motions) != expected or len(motions) != 14:
        raise ConfigError(f"{where}: motions must be the 14 <piece>_<hand> motions")
    rows = _table(_need(data, where, "rows"), where, "rows")
    table = []
    for row_name in (*motions, "none"):
        if row_name not in rows:
            raise ConfigError(f"{where}: rows.{row_name} is missing")
        row = _table(rows[row_name], where, f"rows.{row_name}")
        if set(row) != set(motions):
            raise ConfigError(f"{where}: row {row_name!r} must give all 14 columns")
        table.append(tuple(_float(row[c], where, f"rows.{row_name}.{c}") for c in motions))
    drop = _float(data.get("drop_penalty", 1000), where, "drop_penalty")
    return DrumCosts(motions, tuple(table), drop)


def parse_timing(data: dict[str, Any], *, where: str = "timing.toml") -> Timing:
    """The timing of a ``timing.toml`` table: reference_bpm > 0, rest_s >= 0, and for each
    kind 0 <= min_anticipation_s <= anticipation_s and min_interval_s >= 0 (all finite)."""
    kinds = {}
    for name, value in _table(_need(data, where, "motion"), where, "motion").items():
        k = f"motion.{name}"
        v = _table(value, where, k)
        mt = MotionTiming(
            *(_float(_need(v, where, f, f"{k}."), where, f"{k}.{f}") for f in _TIMING_FIELDS)
        )
        if not 0 <= mt.min_anticipation_s <= mt.anticipation_s:
            raise ConfigError(f"{where}: {k}: need 0 <= min_anticipation_s <= anticipation_s")
        if mt.min_interval_s < 0:
            raise ConfigError(f"{where}: {k}.min_interval_s must be >= 0")
        kinds[name] = mt
    needed = {*HAND_PIECES, "kick", "hihat_pedal", "pluck"}
    if missing := needed - set(kinds):
        raise ConfigError(f"{where}: timing table lacks motion kinds {sorted(missing)}")
    bpm = _float(_need(data, where, "reference_bpm"), where, "reference_bpm")
    if bpm <= 0:
        raise ConfigError(f"{where}: reference_bpm must be > 0, got {bpm}")
    rest_s = _float(_need(data, where, "rest_s"), where, "rest_s")
    if rest_s < 0:
        raise ConfigError(f"{where}: rest_s must be >= 0, got {rest_s}")
    moves: dict[tuple[str, str], float] = {}
    if "hand_move" in data:
        hm = _table(data["hand_move"], where, "hand_move")
        base_s = _float(_need(hm, where, "base_s", "hand_move."), where, "hand_move.base_s")
        speed = _float(_need(hm, where, "speed_m_s", "hand_move."), where, "hand_move.speed_m_s")
        if base_s < 0 or speed <= 0:
            raise ConfigError(f"{where}: hand_move needs base_s >= 0 and speed_m_s > 0")
        moves = hand_moves(base_s, speed)
    return Timing(60.0 / bpm, rest_s, kinds, moves)


_TIMING_FIELDS = ("anticipation_s", "min_anticipation_s", "min_interval_s")


def default_config() -> PlanConfig:
    """The tables shipped in motions/."""
    return load_plan_config(None)


def load_plan_config(path: str | Path | None) -> PlanConfig:
    """The shipped tables with the overrides of the ``[plan]`` table of config file ``path``."""
    if path is None:
        return plan_config_from_table({}, None)
    doc = load_config(path)
    return plan_config_from_table(section(doc, "plan"), Path(path).parent, where=f"{path} [plan]")


def plan_config_from_table(
    over: dict[str, Any], root: Path | None, *, where: str = "[plan]"
) -> PlanConfig:
    """The shipped tables with a ``[plan]`` table's overrides; paths relative to ``root``.

    Every value is type-checked: a wrong type, a non-finite number or a missing key,
    here or in a table file, is a ConfigError naming the file (``where`` for the
    overrides) and the key.
    """
    base = motions_dir()

    def table(key: str, default: str) -> tuple[dict[str, Any], str]:
        path = base / default
        if key in over:
            path = (root or Path.cwd()) / _str(over[key], where, key)
        return _load_toml(path), str(path)

    known = {
        "bass_tuning",
        "bass_strings",
        "bass_frets",
        "double_stop_span_frets",
        "drum_kit",
        "drum_costs",
        "timing",
    }
    if unknown := sorted(set(over) - known):
        raise ConfigError(
            f"{where}: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}"
        )
    tuning = _opt_str(over.get("bass_tuning"), where, "bass_tuning")
    bass_path = base / "bass.toml"
    bass = parse_bass(_load_toml(bass_path), tuning=tuning, where=str(bass_path))
    strings = bass.strings
    if "bass_strings" in over:
        strings = parse_strings(over["bass_strings"], where, "bass_strings")
    bass = BassSetup(
        strings,
        _int(over.get("bass_frets", bass.frets), where, "bass_frets"),
        _int(
            over.get("double_stop_span_frets", bass.double_stop_span_frets),
            where,
            "double_stop_span_frets",
        ),
        bass.fingering,
    )
    kit, kit_where = table("drum_kit", "drum_kit.toml")
    costs, costs_where = table("drum_costs", "drum_costs.toml")
    timing, timing_where = table("timing", "timing.toml")
    return PlanConfig(
        bass=bass,
        kit=parse_kit(kit, where=kit_where),
        costs=parse_costs(costs, where=costs_where),
        timing=parse_timing(timing, where=timing_where),
    )
