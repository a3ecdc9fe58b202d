"""The scheduler's TOML tables are type-checked: a value of the wrong type anywhere is a
ConfigError naming the file and the key (found by fuzzing: AttributeError, OverflowError,
ZeroDivisionError escaped before)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import pytest

from tests.fuzz.mutate import toml_document
from virja.errors import ConfigError
from virja.plan.config import load_plan_config, plan_config_from_table
from virja.resources import motions_dir


def shipped(name: str) -> dict[str, Any]:
    return tomllib.loads((motions_dir() / name).read_text())


def set_key(doc: dict[str, Any], path: tuple[str, ...], value: object) -> dict[str, Any]:
    doc = copy.deepcopy(doc)
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    parent[path[-1]] = value
    return doc


CASES = [
    ("drum_kit", "drum_kit.toml", ("priority",), 0, "priority must be a table"),
    ("drum_kit", "drum_kit.toml", ("notes",), [1], "notes must be a table"),
    ("drum_kit", "drum_kit.toml", ("notes", "38"), "x", "notes.38 must be a table"),
    ("drum_kit", "drum_kit.toml", ("notes", "38", "piece"), 3, "notes.38.piece must be a string"),
    ("drum_kit", "drum_kit.toml", ("notes", "38", "limb"), [], "notes.38.limb must be a string"),
    ("drum_kit", "drum_kit.toml", ("notes", "38", "priority"), 1.5, "notes.38.priority must be"),
    ("drum_kit", "drum_kit.toml", ("notes", "38", "name"), 7, "notes.38.name must be a string"),
    ("drum_kit", "drum_kit.toml", ("priority", "snare"), "high", "priority.snare must be"),
    ("drum_costs", "drum_costs.toml", ("rows",), 1, "rows must be a table"),
    ("drum_costs", "drum_costs.toml", ("motions",), "snare", "motions must be a list"),
    ("drum_costs", "drum_costs.toml", ("rows", "none"), 0, "rows.none must be a table"),
    ("drum_costs", "drum_costs.toml", ("rows", "none", "ride_left_hand"), "9", "must be a number"),
    ("drum_costs", "drum_costs.toml", ("rows", "none", "ride_left_hand"), float("nan"), "finite"),
    ("drum_costs", "drum_costs.toml", ("rows", "none", "ride_left_hand"), 1 << 1100, "range"),
    ("drum_costs", "drum_costs.toml", ("drop_penalty",), True, "drop_penalty must be a number"),
    ("timing", "timing.toml", ("motion",), 3, "motion must be a table"),
    ("timing", "timing.toml", ("motion", "snare"), 3, "motion.snare must be a table"),
    ("timing", "timing.toml", ("motion", "snare", "anticipation_s"), "0.2", "must be a number"),
    ("timing", "timing.toml", ("motion", "ride", "min_interval_s"), -0.1, "must be >= 0"),
    ("timing", "timing.toml", ("reference_bpm",), 0.0, "reference_bpm must be > 0"),
    ("timing", "timing.toml", ("reference_bpm",), -120, "reference_bpm must be > 0"),
    ("timing", "timing.toml", ("reference_bpm",), float("inf"), "reference_bpm must be finite"),
    ("timing", "timing.toml", ("rest_s",), -1.0, "rest_s must be >= 0"),
]


@pytest.mark.parametrize(("key", "name", "path", "value", "message"), CASES)
def test_wrong_type_in_a_table_is_config_error_naming_file_and_key(
    tmp_path: Path, key: str, name: str, path: tuple[str, ...], value: object, message: str
) -> None:
    """One value of the shipped table replaced: ConfigError naming the file and the key."""
    p = tmp_path / "t.toml"
    p.write_text(toml_document(set_key(shipped(name), path, value)))
    with pytest.raises(ConfigError, match="t.toml") as info:
        plan_config_from_table({key: p.name}, tmp_path)
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("bass_frets = inf", "bass_frets must be an integer"),
        ("bass_frets = 20.0", "bass_frets must be an integer"),
        ("bass_frets = true", "bass_frets must be an integer"),
        ("double_stop_span_frets = '4'", "double_stop_span_frets must be an integer"),
        ("bass_tuning = 4", "bass_tuning must be a string"),
        ("bass_strings = 'EADG'", "bass_strings must be a list"),
        ("bass_strings = [1]", "bass_strings[0] must be a table"),
        ("bass_strings = [{ name = 'E', open = inf }]", "bass_strings[0].open must be an integer"),
        ("bass_strings = [{ name = 'E' }]", "missing bass_strings[0].open"),
        ("drum_kit = 3", "drum_kit must be a string"),
    ],
)
def test_wrong_type_in_user_plan_table_is_config_error_naming_file_and_key(
    tmp_path: Path, text: str, message: str
) -> None:
    """A user's [plan] override of the wrong type: ConfigError naming the config file and key."""
    p = tmp_path / "virja.toml"
    p.write_text(f"[plan]\n{text}\n")
    with pytest.raises(ConfigError, match=r"virja\.toml \[plan\]") as info:
        load_plan_config(p)
    assert message in str(info.value)


def test_table_not_utf8_is_config_error(tmp_path: Path) -> None:
    """A replacement table that is not UTF-8 is a ConfigError naming it."""
    (tmp_path / "t.toml").write_bytes(b"reference_bpm = 120.0 # \xff\n")
    with pytest.raises(ConfigError, match=r"t\.toml: not UTF-8"):
        plan_config_from_table({"timing": "t.toml"}, tmp_path)
