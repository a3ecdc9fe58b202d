"""The TOML config file: parse errors and unknown tables name the file."""

from __future__ import annotations

from pathlib import Path

import pytest

from virja.config import load_config
from virja.errors import ConfigError, InputFileError


def test_valid_config_loads(tmp_path: Path) -> None:
    p = tmp_path / "v.toml"
    p.write_text("[routing]\ndrum_channels = [10, 11]\n")
    assert load_config(p) == {"routing": {"drum_channels": [10, 11]}}


def test_invalid_toml_names_the_file(tmp_path: Path) -> None:
    p = tmp_path / "bad.toml"
    p.write_text("[routing\n")
    with pytest.raises(InputFileError, match="bad.toml: invalid TOML"):
        load_config(p)


def test_unknown_table_is_rejected(tmp_path: Path) -> None:
    p = tmp_path / "u.toml"
    p.write_text("[colours]\n")
    with pytest.raises(ConfigError, match="unknown table"):
        load_config(p)


def test_no_config_is_empty() -> None:
    assert load_config(None) == {}
