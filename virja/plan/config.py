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

import tomllib
from dataclasses import dataclass
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
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from exc


@dataclass(frozen=True)
class BassSetup:
    """The bass: ``strings`` low to high as (name, open MIDI note)."""

    strings: tuple[tuple[str, int], ...]
    frets: int
    double_stop_span_frets: int

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
    reference_spb: float
    rest_s: float
    kinds: dict[str, MotionTiming]

    def get(self, kind: str) -> MotionTiming:
        try:
            return self.kinds[kind]
        except KeyError:
            raise ConfigError(f"timing table has no motion kind {kind!r}") from None


@dataclass(frozen=True)
class PlanConfig:
    bass: BassSetup
    kit: DrumKit
    costs: DrumCosts
    timing: Timing


def parse_bass(data: dict[str, Any], *, tuning: str | None = None) -> BassSetup:
    try:
        tunings = data["tunings"]
        name = tuning or data["default_tuning"]
        if name not in tunings:
            raise ConfigError(f"unknown bass tuning {name!r}; known: {sorted(tunings)}")
        strings = tuple((str(s["name"]), int(s["open"])) for s in tunings[name]["strings"])
        return BassSetup(strings, int(data["frets"]), int(data["double_stop_span_frets"]))
    except (KeyError, TypeError) as exc:
        raise ConfigError(f"bass table incomplete: missing {exc}") from None


def parse_kit(data: dict[str, Any]) -> DrumKit:
    prio = data.get("priority", {})
    notes: dict[int, DrumNote] = {}
    for key, entry in data.get("notes", {}).items():
        piece = str(entry["piece"])
        limb = entry.get("limb")
        if limb is None and piece not in HAND_PIECES:
            raise ConfigError(f"drum note {key}: piece {piece!r} is not a hand piece")
        if limb is not None and (piece, limb) not in FOOT_KINDS:
            raise ConfigError(f"drum note {key}: {piece} cannot be played by {limb}")
        notes[int(key)] = DrumNote(
            piece=piece,
            limb=limb,
            priority=int(entry.get("priority", prio.get(piece, 5))),
            articulation=entry.get("articulation"),
            name=str(entry.get("name", "")),
        )
    return DrumKit(notes)


def parse_costs(data: dict[str, Any]) -> DrumCosts:
    motions = tuple(str(m) for m in data["motions"])
    expected = {f"{p}_{h}" for p in HAND_PIECES for h in HANDS}
    if set(motions) != expected or len(motions) != 14:
        raise ConfigError("drum cost table: motions must be the 14 <piece>_<hand> motions")
    rows = data["rows"]
    table = []
    for row_name in (*motions, "none"):
        row = rows.get(row_name)
        if row is None or set(row) != set(motions):
            raise ConfigError(f"drum cost table: row {row_name!r} must give all 14 columns")
        table.append(tuple(float(row[c]) for c in motions))
    return DrumCosts(motions, tuple(table), float(data.get("drop_penalty", 1000)))


def parse_timing(data: dict[str, Any]) -> Timing:
    kinds = {
        name: MotionTiming(
            float(v["anticipation_s"]), float(v["min_anticipation_s"]), float(v["min_interval_s"])
        )
        for name, v in data["motion"].items()
    }
    for name, mt in kinds.items():
        if not 0 <= mt.min_anticipation_s <= mt.anticipation_s:
            raise ConfigError(f"timing {name}: need 0 <= min_anticipation_s <= anticipation_s")
    needed = {*HAND_PIECES, "kick", "hihat_pedal", "pluck"}
    if missing := needed - set(kinds):
        raise ConfigError(f"timing table lacks motion kinds {sorted(missing)}")
    return Timing(60.0 / float(data["reference_bpm"]), float(data["rest_s"]), kinds)


def default_config() -> PlanConfig:
    """The tables shipped in motions/."""
    return load_plan_config(None)


def load_plan_config(path: str | Path | None) -> PlanConfig:
    """The shipped tables with the overrides of the ``[plan]`` table of config file ``path``."""
    if path is None:
        return plan_config_from_table({}, None)
    doc = load_config(path)
    return plan_config_from_table(section(doc, "plan"), Path(path).parent)


def plan_config_from_table(over: dict[str, Any], root: Path | None) -> PlanConfig:
    """The shipped tables with a ``[plan]`` table's overrides; paths relative to ``root``."""
    base = motions_dir()

    def table(key: str, default: str) -> dict[str, Any]:
        if key in over:
            return _load_toml((root or Path.cwd()) / str(over[key]))
        return _load_toml(base / default)

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
            f"[plan]: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}"
        )
    try:
        bass = parse_bass(_load_toml(base / "bass.toml"), tuning=over.get("bass_tuning"))
        strings = bass.strings
        if "bass_strings" in over:
            strings = tuple((str(s["name"]), int(s["open"])) for s in over["bass_strings"])
        bass = BassSetup(
            strings,
            int(over.get("bass_frets", bass.frets)),
            int(over.get("double_stop_span_frets", bass.double_stop_span_frets)),
        )
        return PlanConfig(
            bass=bass,
            kit=parse_kit(table("drum_kit", "drum_kit.toml")),
            costs=parse_costs(table("drum_costs", "drum_costs.toml")),
            timing=parse_timing(table("timing", "timing.toml")),
        )
    except ConfigError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise ConfigError(f"plan configuration invalid: {exc!r}") from None
