"""Fuzzing the TOML loaders: the scheduler's tables and the motion clip sidecars.

A mutated document gives ConfigError / InputFileError (ClipError for a
sidecar) or a loaded result, never another exception.  Documents are mutated
at the value level (a key replaced by an odd value: huge, negative, NaN, inf,
a string, a list, a table; or deleted) and then written back as TOML, so the
loaders' own checks are reached; a byte-level test covers syntax errors and
invalid UTF-8.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz.mutate import (
    apply_byte_edits,
    byte_edits,
    doc_edits,
    mutate_doc,
    raise_unless_known_bug,
    time_limit,
    toml_document,
)
from virja.errors import ConfigError, InputFileError
from virja.motion.clip import ClipError, read_sidecar
from virja.plan.config import PlanConfig, load_plan_config, plan_config_from_table
from virja.resources import motions_dir

TABLES = {"drum_kit": "drum_kit.toml", "drum_costs": "drum_costs.toml", "timing": "timing.toml"}
SHIPPED = {key: tomllib.loads((motions_dir() / name).read_text()) for key, name in TABLES.items()}
USER_CONFIG: dict[str, Any] = {
    "plan": {
        "bass_tuning": "four",
        "bass_strings": [{"name": "E", "open": 28}, {"name": "A", "open": 33}],
        "bass_frets": 20,
        "double_stop_span_frets": 4,
    }
}
SIDECAR: dict[str, Any] = {
    "performer": "drums",
    "limb": "left_hand",
    "kind": "stroke",
    "impact_s": 0.4,
    "joints": ["LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"],
    "piece": "crash",
    "velocity": 96,
}
SETTINGS = settings(
    max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
Edits = list[tuple[int, int, Any]]


def load_table(tmp_path: Path, key: str, text: str | bytes) -> object:
    """A PlanConfig or its ConfigError/InputFileError; None for the open bugs of KNOWN_BUGS."""
    p = tmp_path / "table.toml"
    p.write_bytes(text.encode() if isinstance(text, str) else text)
    try:
        with time_limit(2.0):
            return plan_config_from_table({key: p.name}, tmp_path)
    except (ConfigError, InputFileError) as exc:
        return exc
    except Exception as exc:
        raise_unless_known_bug(exc)
        return None


def test_seeds_load() -> None:
    """The shipped tables, the user config and the sidecar load as written (the seeds)."""
    assert isinstance(plan_config_from_table({}, None), PlanConfig)
    assert SHIPPED["timing"]["reference_bpm"] > 0


def test_seed_documents_survive_the_toml_writer(tmp_path: Path) -> None:
    """Each seed written back by the fuzzer's TOML writer loads unchanged (no mutation)."""
    for key, doc in SHIPPED.items():
        assert isinstance(load_table(tmp_path, key, toml_document(doc)), PlanConfig), key
    side = tmp_path / "clip.toml"
    side.write_text(toml_document(SIDECAR))
    assert read_sidecar(side)["piece"] == "crash"
    cfg = tmp_path / "virja.toml"
    cfg.write_text(toml_document(USER_CONFIG))
    assert load_plan_config(cfg).bass.frets == 20


@SETTINGS
@given(key=st.sampled_from(sorted(TABLES)), edits=doc_edits())
def test_mutated_plan_table_gives_config_error_or_config(
    tmp_path: Path, key: str, edits: Edits
) -> None:
    """A scheduler table with odd or missing values: ConfigError/InputFileError or a PlanConfig."""
    text = toml_document(mutate_doc(SHIPPED[key], edits))
    result = load_table(tmp_path, key, text)
    assert result is None or isinstance(result, PlanConfig | ConfigError | InputFileError)


@SETTINGS
@given(key=st.sampled_from(sorted(TABLES)), edits=byte_edits())
def test_byte_mutated_plan_table_gives_config_error_or_config(
    tmp_path: Path, key: str, edits: list[tuple[int, int, int]]
) -> None:
    """Byte edits of a shipped table (syntax errors, invalid UTF-8): the same contract."""
    data = apply_byte_edits((motions_dir() / TABLES[key]).read_bytes(), edits)
    result = load_table(tmp_path, key, data)
    assert result is None or isinstance(result, PlanConfig | ConfigError | InputFileError)


@SETTINGS
@given(edits=doc_edits())
def test_mutated_user_plan_config_gives_config_error_or_config(
    tmp_path: Path, edits: Edits
) -> None:
    """A user config's [plan] overrides with odd values: ConfigError/InputFileError or a PlanConfig."""
    p = tmp_path / "virja.toml"
    p.write_text(toml_document(mutate_doc(USER_CONFIG, edits)))
    try:
        with time_limit(2.0):
            load_plan_config(p)
    except (ConfigError, InputFileError):
        pass
    except Exception as exc:
        raise_unless_known_bug(exc)


@SETTINGS
@given(edits=doc_edits())
def test_mutated_sidecar_gives_clip_error_or_metadata(tmp_path: Path, edits: Edits) -> None:
    """A clip sidecar with odd or missing values: ClipError or its checked metadata."""
    p = tmp_path / "clip.toml"
    p.write_text(toml_document(mutate_doc(SIDECAR, edits)))
    try:
        with time_limit(2.0):
            meta = read_sidecar(p)
    except ClipError:
        return
    except Exception as exc:
        raise_unless_known_bug(exc)
        return
    assert meta["performer"] in ("drums", "bass") and meta["joints"]


@SETTINGS
@given(edits=byte_edits())
def test_byte_mutated_sidecar_gives_clip_error_or_metadata(
    tmp_path: Path, edits: list[tuple[int, int, int]]
) -> None:
    """Byte edits of a sidecar (syntax errors, invalid UTF-8): ClipError or metadata."""
    p = tmp_path / "clip.toml"
    p.write_bytes(apply_byte_edits(toml_document(SIDECAR).encode(), edits))
    try:
        with time_limit(2.0):
            read_sidecar(p)
    except ClipError:
        pass
    except Exception as exc:
        raise_unless_known_bug(exc)
