"""Every TOML file kind virja reads, through its one schema: a wrong type, a missing key
and an unknown key are each one line naming the file, the key path and what was
expected (no traceback, no bare KeyError)."""

from __future__ import annotations

import copy
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tests.fuzz.mutate import toml_document
from virja import tomlconf
from virja.config import load_config, section
from virja.errors import ConfigError, InputFileError
from virja.jam.options import JamOptions
from virja.motion.band import AnimationSettings
from virja.motion.clip import read_sidecar
from virja.motion.drummer_body import BodySettings
from virja.plan.config import load_plan_config, parse_bass, plan_config_from_table
from virja.resources import motions_dir
from virja.routing import RoutingConfig

ROOT = Path(__file__).resolve().parents[1]
SIDECAR = next((motions_dir() / "drums").glob("*.toml"))


def _shipped(path: Path) -> dict[str, Any]:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def _config(table: str) -> Callable[[Path], object]:
    def load(p: Path) -> object:
        doc = load_config(p)
        where = f"{p} [{table}]"
        if table == "routing":
            return RoutingConfig.from_dict(section(doc, "routing"), where)
        if table == "jam":
            return JamOptions.merge(section(doc, "jam"), {}, where=where)
        return load_plan_config(p)

    return load


# kind: (a valid document, how to load a file of it)
KINDS: dict[str, tuple[dict[str, Any], Callable[[Path], object]]] = {
    "bass": (
        _shipped(motions_dir() / "bass.toml"),
        lambda p: parse_bass(tomlconf.read(p), where=str(p)),
    ),
    "drum_kit": (
        _shipped(motions_dir() / "drum_kit.toml"),
        lambda p: plan_config_from_table({"drum_kit": p.name}, p.parent),
    ),
    "drum_costs": (
        _shipped(motions_dir() / "drum_costs.toml"),
        lambda p: plan_config_from_table({"drum_costs": p.name}, p.parent),
    ),
    "timing": (
        _shipped(motions_dir() / "timing.toml"),
        lambda p: plan_config_from_table({"timing": p.name}, p.parent),
    ),
    "plan": ({"plan": {"bass_frets": 20, "bass_tuning": "five"}}, _config("plan")),
    "routing": (
        {"routing": {"drum_channels": [10], "channels": {"2": "bass"}}},
        _config("routing"),
    ),
    "jam": ({"jam": {"split": "C3", "delay_ms": 10}}, _config("jam")),
    "sidecar": (_shipped(SIDECAR), read_sidecar),
    "animation": (_shipped(motions_dir() / "animation.toml"), AnimationSettings.load),
    "drummer_body": (_shipped(motions_dir() / "drummer_body.toml"), BodySettings.load),
}

# kind: ((key path, wrong value, what the error says), key path to remove, table to add to)
CASES: dict[str, tuple[tuple[tuple[str, ...], object, str], tuple[str, ...], tuple[str, ...]]] = {
    "bass": ((("frets",), "20", "frets must be an integer, got str '20'"), ("frets",), ()),
    "drum_kit": (
        (("notes", "38", "piece"), 3, "notes.38.piece must be a string, got int 3"),
        ("notes", "38", "piece"),
        ("notes", "38"),
    ),
    "drum_costs": (
        (("rows", "none", "ride_left_hand"), "9", "rows.none.ride_left_hand must be a number"),
        ("motions",),
        (),
    ),
    "timing": (
        (("motion", "ride", "anticipation_s"), [1], "motion.ride.anticipation_s must be a number"),
        ("motion", "ride", "min_interval_s"),
        ("motion", "ride"),
    ),
    "plan": (
        (("plan", "bass_frets"), 2.5, "bass_frets must be an integer, got float 2.5"),
        (),
        ("plan",),
    ),
    "routing": (
        (("routing", "drum_channels"), 10, "drum_channels must be a list, got int 10"),
        (),
        ("routing",),
    ),
    "jam": ((("jam", "fps"), "fast", "fps must be a number, got str 'fast'"), (), ("jam",)),
    "sidecar": ((("velocity",), 9.5, "velocity must be an integer, got float 9.5"), ("kind",), ()),
    "animation": (
        (("kit", "ride_swing"), 0.1, "kit.ride_swing must be a list, got float 0.1"),
        ("strings", "decay_s"),
        ("bassist",),
    ),
    "drummer_body": (
        (("breath", "period_s"), "long", "breath.period_s must be a number, got str 'long'"),
        ("arms",),
        ("turn",),
    ),
}


def _write(tmp_path: Path, doc: dict[str, Any]) -> Path:
    p = tmp_path / "the_file.toml"
    p.write_text(toml_document(doc))
    return p


def _error(kind: str, doc: dict[str, Any], tmp_path: Path) -> str:
    with pytest.raises((ConfigError, InputFileError)) as info:
        KINDS[kind][1](_write(tmp_path, doc))
    text = str(info.value)
    assert "\n" not in text and "the_file.toml" in text
    return text


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_the_valid_document_loads(kind: str, tmp_path: Path) -> None:
    doc, load = KINDS[kind]
    assert load(_write(tmp_path, doc)) is not None


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_wrong_type(kind: str, tmp_path: Path) -> None:
    (path, value, says), _, _ = CASES[kind]
    doc = copy.deepcopy(KINDS[kind][0])
    _at(doc, path[:-1])[path[-1]] = value
    assert says in _error(kind, doc, tmp_path)


@pytest.mark.parametrize("kind", [k for k in sorted(KINDS) if CASES[k][1]])
def test_missing_key(kind: str, tmp_path: Path) -> None:
    _, path, _ = CASES[kind]
    doc = copy.deepcopy(KINDS[kind][0])
    del _at(doc, path[:-1])[path[-1]]
    assert f"missing {'.'.join(path)}" in _error(kind, doc, tmp_path)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_unknown_key(kind: str, tmp_path: Path) -> None:
    _, _, table = CASES[kind]
    doc = copy.deepcopy(KINDS[kind][0])
    _at(doc, table)["colour"] = 1
    key = (
        ".".join((*table[1:], "colour"))
        if kind in ("plan", "routing", "jam")
        else ".".join((*table, "colour"))
    )
    assert f"{key}: unknown key; known: " in _error(kind, doc, tmp_path)


def _at(doc: dict[str, Any], path: tuple[str, ...]) -> dict[str, Any]:
    for k in path:
        doc = doc[k]
    return doc


def test_non_finite_numbers_are_refused(tmp_path: Path) -> None:
    doc = copy.deepcopy(KINDS["timing"][0])
    doc["motion"]["snare"]["min_interval_s"] = float("nan")
    assert "motion.snare.min_interval_s must be finite, got nan" in _error("timing", doc, tmp_path)


def test_the_example_config_fits_every_schema() -> None:
    example = ROOT / "docs" / "virja.example.toml"
    for table in ("plan", "routing", "jam"):
        assert _config(table)(example) is not None
