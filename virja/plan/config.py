"""The scheduler's tables, read from motions/*.toml, and the user's overrides.

- ``motions/bass.toml``: tunings, frets, double-stop span -> :class:`BassSetup`
- ``motions/drum_kit.toml``: GM note -> piece, limb, priority -> :class:`DrumKit`
- ``motions/drum_costs.toml``: the 17 x 16 hand table (the paper's 15 x 14 and crash 2's
  rows and columns) -> :class:`DrumCosts`
- ``motions/timing.toml``: anticipation and inter-stroke times -> :class:`Timing`

A user config file (``virja plan --config FILE.toml``) may override under
``[plan]``: ``bass_tuning`` (a tuning name), ``bass_strings`` (a list of
``{name, open}``), ``bass_frets``, ``double_stop_span_frets``, and
``drum_kit`` / ``drum_costs`` / ``timing`` (paths to replacement tables,
relative to the config file).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import msgspec

from virja import tomlconf
from virja.config import load_config, section
from virja.errors import ConfigError
from virja.kit_file import KitFile
from virja.resources import motions_dir
from virja.tomlconf import Schema, convert, schema_of
from virja.vocab import ALL_BASS_STRINGS, FOOT_KINDS, HAND_PIECES, HANDS, DrumStroke, MotionKey


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
            if name not in ALL_BASS_STRINGS:
                raise ConfigError(
                    f"bass string name {name!r} not one of {sorted(ALL_BASS_STRINGS)}"
                )
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
    """``table[row][col]``: rows are the 16 motions then "none" (index 16)."""

    motions: tuple[str, ...]
    table: tuple[tuple[float, ...], ...]
    drop_penalty: float
    # live only: a note given the other hand than the one drawn moving for it
    # (``Stroke.pin``, drum_costs.toml)
    shown_hand_penalty: float = 4.0
    _rows: dict[tuple[str, str], int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        rows = {}
        for i, name in enumerate(self.motions):
            key = MotionKey.parse(name)
            if isinstance(key, DrumStroke):
                rows[(key.piece, key.limb)] = i
        object.__setattr__(self, "_rows", rows)

    @property
    def none_row(self) -> int:
        return len(self.motions)

    def index(self, piece: str, hand: str) -> int:
        """The row (and column) of the stroke of ``hand`` on ``piece``."""
        try:
            return self._rows[(piece, hand)]
        except KeyError:
            raise ValueError(f"no hand motion {piece!r} by {hand!r} in the cost table") from None


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
    # the hand's stretch (timing.toml [hand_stretch]): what a hand can do when nothing
    # else plays every note, at ``stretch_penalty`` per stroke: a double on one piece
    # down to ``stretch_interval_s``, a move between pieces in ``stretch_moves``.  None:
    # no stretch (every stroke keeps :meth:`gap`)
    stretch_interval_s: float | None = None
    stretch_moves: dict[tuple[str, str], float] = field(default_factory=dict)
    stretch_penalty: float = 0.0
    # two notes of one of these pieces in one group are one hand's double (the second on
    # its rebound) at ``one_hand_double_penalty`` rather than ``stretch_penalty``
    one_hand_doubles: frozenset[str] = frozenset()
    one_hand_double_penalty: float = 0.0
    # the hand's speed (timing.toml [hand_speed]): a stroke on another piece than the
    # hand's last costs the penalty of the fastest tier ``(speed_m_s, penalty)`` whose
    # speed the move needs (``distances[(prev, piece)]`` / time since the last stroke)
    speed_tiers: tuple[tuple[float, float], ...] = ()
    distances: dict[tuple[str, str], float] = field(default_factory=dict)
    speed_memory_s: float = math.inf  # a stroke older than this pays no speed tier
    # crossed arms at short times (timing.toml [hand_cross]): a stroke that leaves the
    # left hand's piece right of the right hand's (``cross_positions``, across the kit
    # left to right), the other hand having struck less than ``cross_window_s`` before
    # (or in the same group), costs ``cross_penalty``; ``cross_home`` lists the (right
    # piece, left piece) pairs of the home posture, which are not a crossing
    cross_window_s: float = 0.0
    cross_penalty: float = 0.0
    cross_positions: dict[str, float] = field(default_factory=dict)
    cross_home: frozenset[tuple[str, str]] = frozenset()

    def crossed(self, left: str, right: str) -> bool:
        """Whether the left hand on ``left`` and the right hand on ``right`` cross the
        arms: the left hand's piece right of the right hand's, but for the home posture.
        False for a piece without a position."""
        pos = self.cross_positions
        if left not in pos or right not in pos or (right, left) in self.cross_home:
            return False
        return pos[left] > pos[right]

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

    def stretch_gap(self, prev: str | None, piece: str) -> float:
        """The least time between two strokes of a hand at a stretch (never more than
        :meth:`gap`): on one piece ``stretch_interval_s``, between two pieces the
        stretched move (no shorter than ``stretch_interval_s`` either)."""
        normal = self.gap(prev, piece)
        if self.stretch_interval_s is None:
            return normal
        floor = self.stretch_interval_s
        if prev is None or prev == piece:
            return min(normal, floor)
        return min(normal, max(floor, self.stretch_moves.get((prev, piece), 0.0)))

    def penalty_steps(self, prev: str | None, piece: str) -> tuple[tuple[float, float], ...]:
        """``(time, penalty)`` pairs, the largest penalty first: a stroke on ``piece`` less
        than ``time`` after the hand's stroke on ``prev`` costs at least ``penalty``.  At
        a stretch (sooner than :meth:`gap`) ``stretch_penalty``; on another piece, each
        speed tier whose speed the move needs (``distance / time`` above ``speed_m_s``)."""
        steps = [(self.gap(prev, piece), self.stretch_penalty)] if self.stretch_penalty else []
        if prev is not None and prev != piece:
            dist = self.distances.get((prev, piece), 0.0)
            mem = self.speed_memory_s
            steps += [
                (min(dist / speed, mem), pen) for speed, pen in self.speed_tiers if pen and dist
            ]
        return tuple(sorted(steps, key=lambda s: (-s[1], -s[0])))

    @property
    def max_gap(self) -> float:
        """The longest :meth:`gap`, speed tier's time or crossing window: a stroke older
        than this constrains nothing and costs nothing."""
        slowest = min((speed for speed, _pen in self.speed_tiers), default=math.inf)
        return max(
            max((mt.min_interval_s for mt in self.kinds.values()), default=0.0),
            max(self.moves.values(), default=0.0),
            min(max(self.distances.values(), default=0.0) / slowest, self.speed_memory_s),
            self.cross_window_s if self.cross_penalty else 0.0,
        )


def hand_distances() -> dict[tuple[str, str], float]:
    """The distance (m) between the strike points of every two hand pieces of the drawn
    kit (virja.geometry)."""
    from virja.geometry import GEOMETRY

    kit = GEOMETRY.kit
    pts = {p: kit.strike_point(p) for p in HAND_PIECES}
    return {
        (a, b): float(math.dist(pts[a], pts[b])) for a in HAND_PIECES for b in HAND_PIECES if a != b
    }


def hand_moves(base_s: float, speed_m_s: float) -> dict[tuple[str, str], float]:
    """``base_s`` + distance / ``speed_m_s`` between the strike points of every two hand
    pieces of the drawn kit (virja.geometry): lifting off one piece and landing on the
    other is quick, travelling across the kit is not."""
    return {ab: base_s + d / speed_m_s for ab, d in hand_distances().items()}


@dataclass(frozen=True)
class PlanConfig:
    bass: BassSetup
    kit: DrumKit
    costs: DrumCosts
    timing: Timing


# -- the files' schemas (virja.tomlconf): types, required and unknown keys ------------


class StringTable(Schema):
    """``{ name = "E", open = 28 }``"""

    name: str
    open: int


class TuningTable(Schema):
    strings: list[StringTable]


FingeringTable = schema_of(Fingering)


class BassFile(Schema):
    """motions/bass.toml"""

    default_tuning: str
    frets: int
    double_stop_span_frets: int
    tunings: dict[str, TuningTable]
    fingering: FingeringTable = msgspec.field(default_factory=FingeringTable)  # type: ignore[valid-type]


class CostsFile(Schema):
    """motions/drum_costs.toml"""

    motions: list[str]
    rows: dict[str, dict[str, float]]
    drop_penalty: float = 1000.0
    shown_hand_penalty: float = 4.0


class HandMoveTable(Schema):
    base_s: float
    speed_m_s: float


class HandStretchTable(Schema):
    min_interval_s: float
    base_s: float
    speed_m_s: float
    penalty: float
    one_hand_doubles: list[str] = []
    one_hand_double_penalty: float = 0.0


class HandSpeedTable(Schema):
    speeds_m_s: list[float]
    penalties: list[float]
    memory_s: float = math.inf


class HandCrossTable(Schema):
    window_s: float
    penalty: float
    positions: dict[str, float]
    home: dict[str, list[str]] = msgspec.field(default_factory=dict)


MotionTimingTable = schema_of(MotionTiming)


class TimingFile(Schema):
    """motions/timing.toml"""

    reference_bpm: float
    rest_s: float
    motion: dict[str, MotionTimingTable]  # type: ignore[valid-type]
    hand_move: HandMoveTable | None = None
    hand_stretch: HandStretchTable | None = None
    hand_speed: HandSpeedTable | None = None
    hand_cross: HandCrossTable | None = None


class PlanTable(Schema):
    """The ``[plan]`` table of the config file (docs/virja.example.toml)."""

    bass_tuning: str | None = None
    bass_strings: list[StringTable] | None = None
    bass_frets: int | None = None
    double_stop_span_frets: int | None = None
    drum_kit: str | None = None
    drum_costs: str | None = None
    timing: str | None = None


def _strings(strings: list[StringTable]) -> tuple[tuple[str, int], ...]:
    return tuple((s.name, s.open) for s in strings)


def parse_bass(
    data: dict[str, Any], *, tuning: str | None = None, where: str = "bass.toml"
) -> BassSetup:
    """The bass of a ``bass.toml`` table, with tuning ``tuning`` (default: its default)."""
    f = convert(data, BassFile, where)
    name = f.default_tuning if tuning is None else tuning
    if name not in f.tunings:
        raise ConfigError(f"{where}: unknown bass tuning {name!r}; known: {sorted(f.tunings)}")
    return BassSetup(
        _strings(f.tunings[name].strings),
        f.frets,
        f.double_stop_span_frets,
        Fingering(**tomlconf.fields(f.fingering)),
    )


def parse_fingering(data: dict[str, Any], where: str) -> Fingering:
    """The ``[fingering]`` table; keys left out keep :class:`Fingering`'s defaults."""
    return Fingering(**tomlconf.fields(convert(data, FingeringTable, f"{where} [fingering]")))


def _note_number(key: str, where: str) -> int:
    if not (key.isascii() and key.isdigit() and 0 <= int(key) <= 127):
        raise ConfigError(f"{where}: notes.{key}: a note key must be a MIDI note number 0-127")
    return int(key)


def parse_kit(data: dict[str, Any], *, where: str = "drum_kit.toml") -> DrumKit:
    """The kit of a ``drum_kit.toml`` table."""
    f = convert(data, KitFile, where)
    notes: dict[int, DrumNote] = {}
    for key, entry in f.notes.items():
        piece, limb = entry.piece, entry.limb
        if piece == "none" and limb is not None:
            raise ConfigError(f'{where}: drum note {key}: piece "none" (nobody) takes no limb')
        if limb is None and piece not in HAND_PIECES and piece != "none":
            raise ConfigError(f"{where}: drum note {key}: piece {piece!r} is not a hand piece")
        if limb is not None and (piece, limb) not in FOOT_KINDS:
            raise ConfigError(f"{where}: drum note {key}: {piece} cannot be played by {limb}")
        priority = f.priority.get(piece, 5) if entry.priority is None else entry.priority
        notes[_note_number(key, where)] = DrumNote(
            piece=piece,
            limb=limb,
            priority=priority,
            articulation=entry.articulation,
            name=entry.name,
        )
    return DrumKit(notes)


def parse_costs(data: dict[str, Any], *, where: str = "drum_costs.toml") -> DrumCosts:
    """The hand cost table of a ``drum_costs.toml`` table (every cost a finite number)."""
    f = convert(data, CostsFile, where)
    motions = tuple(f.motions)
    expected = {DrumStroke(p, h).name for p in HAND_PIECES for h in HANDS}
    if set(motions) != expected or len(motions) != len(expected):
        missing = ", ".join(sorted(expected - set(motions)))
        raise ConfigError(
            f"{where}: motions must be the {len(expected)} <piece>_<hand> motions"
            + (f" (missing {missing})" if missing else "")
        )
    table = []
    for row_name in (*motions, "none"):
        if row_name not in f.rows:
            raise ConfigError(f"{where}: rows.{row_name} is missing")
        row = f.rows[row_name]
        if set(row) != set(motions):
            raise ConfigError(f"{where}: row {row_name!r} must give all {len(motions)} columns")
        table.append(tuple(row[c] for c in motions))
    return DrumCosts(motions, tuple(table), f.drop_penalty, f.shown_hand_penalty)


def parse_timing(data: dict[str, Any], *, where: str = "timing.toml") -> Timing:
    """The timing of a ``timing.toml`` table: reference_bpm > 0, rest_s >= 0, and for each
    kind 0 <= min_anticipation_s <= anticipation_s and min_interval_s >= 0 (all finite)."""
    f = convert(data, TimingFile, where)
    kinds = {}
    for name, value in f.motion.items():
        k = f"motion.{name}"
        mt = MotionTiming(**tomlconf.fields(value))
        if not 0 <= mt.min_anticipation_s <= mt.anticipation_s:
            raise ConfigError(f"{where}: {k}: need 0 <= min_anticipation_s <= anticipation_s")
        if mt.min_interval_s < 0:
            raise ConfigError(f"{where}: {k}.min_interval_s must be >= 0")
        kinds[name] = mt
    needed = {*HAND_PIECES, "kick", "hihat_pedal", "pluck"}
    if missing := needed - set(kinds):
        raise ConfigError(f"{where}: timing table lacks motion kinds {sorted(missing)}")
    if f.reference_bpm <= 0:
        raise ConfigError(f"{where}: reference_bpm must be > 0, got {f.reference_bpm}")
    if f.rest_s < 0:
        raise ConfigError(f"{where}: rest_s must be >= 0, got {f.rest_s}")
    moves: dict[tuple[str, str], float] = {}
    if f.hand_move is not None:
        base_s, speed = f.hand_move.base_s, f.hand_move.speed_m_s
        if base_s < 0 or speed <= 0:
            raise ConfigError(f"{where}: hand_move needs base_s >= 0 and speed_m_s > 0")
        moves = hand_moves(base_s, speed)
    timing = Timing(60.0 / f.reference_bpm, f.rest_s, kinds, moves)
    if (st := f.hand_stretch) is not None:
        if (
            st.min_interval_s < 0
            or st.base_s < 0
            or st.speed_m_s <= 0
            or st.penalty < 0
            or not 0 <= st.one_hand_double_penalty <= st.penalty
            or not set(st.one_hand_doubles) <= set(HAND_PIECES)
        ):
            raise ConfigError(
                f"{where}: hand_stretch needs min_interval_s >= 0, base_s >= 0, "
                "speed_m_s > 0, penalty >= 0, 0 <= one_hand_double_penalty <= penalty "
                f"and one_hand_doubles among the hand pieces {sorted(HAND_PIECES)}"
            )
        timing = dataclasses.replace(
            timing,
            stretch_interval_s=st.min_interval_s,
            stretch_moves=hand_moves(st.base_s, st.speed_m_s),
            stretch_penalty=st.penalty,
            one_hand_doubles=frozenset(st.one_hand_doubles),
            one_hand_double_penalty=st.one_hand_double_penalty,
        )
    if (sp := f.hand_speed) is not None:
        speeds, pens = sp.speeds_m_s, sp.penalties
        if (
            len(speeds) != len(pens)
            or any(v <= 0 for v in speeds)
            or any(p < 0 for p in pens)
            or speeds != sorted(set(speeds))
            or not sp.memory_s > 0
        ):
            raise ConfigError(
                f"{where}: hand_speed needs as many penalties (>= 0) as speeds_m_s "
                "(> 0, rising) and memory_s > 0"
            )
        timing = dataclasses.replace(
            timing,
            speed_tiers=tuple(zip(speeds, pens, strict=True)),
            distances=hand_distances(),
            speed_memory_s=sp.memory_s,
        )
    if (cr := f.hand_cross) is not None:
        pieces = set(HAND_PIECES)
        home = {(r, left) for r, lefts in cr.home.items() for left in lefts}
        if (
            not cr.window_s >= 0
            or not cr.penalty >= 0
            or set(cr.positions) != pieces
            or not {p for pair in home for p in pair} <= pieces
        ):
            raise ConfigError(
                f"{where}: hand_cross needs window_s >= 0, penalty >= 0, a position for "
                f"every hand piece ({', '.join(HAND_PIECES)}) and home pairs of hand pieces"
            )
        timing = dataclasses.replace(
            timing,
            cross_window_s=cr.window_s,
            cross_penalty=cr.penalty,
            cross_positions=dict(cr.positions),
            cross_home=frozenset(home),
        )
    return timing


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
    plan = convert(over, PlanTable, where)

    def table(given: str | None, default: str) -> tuple[dict[str, Any], str]:
        path = base / default if given is None else (root or Path.cwd()) / given
        return tomlconf.read(path), str(path)

    bass_path = base / "bass.toml"
    bass = parse_bass(tomlconf.read(bass_path), tuning=plan.bass_tuning, where=str(bass_path))
    bass = BassSetup(
        bass.strings if plan.bass_strings is None else _strings(plan.bass_strings),
        bass.frets if plan.bass_frets is None else plan.bass_frets,
        bass.double_stop_span_frets
        if plan.double_stop_span_frets is None
        else plan.double_stop_span_frets,
        bass.fingering,
    )
    kit, kit_where = table(plan.drum_kit, "drum_kit.toml")
    costs, costs_where = table(plan.drum_costs, "drum_costs.toml")
    timing, timing_where = table(plan.timing, "timing.toml")
    return PlanConfig(
        bass=bass,
        kit=parse_kit(kit, where=kit_where),
        costs=parse_costs(costs, where=costs_where),
        timing=parse_timing(timing, where=timing_where),
    )
