"""docs/virja.example.toml: it loads, its values are the defaults, and it names every key."""

from __future__ import annotations

import re
from pathlib import Path

from virja.config import KNOWN_TABLES, load_config, section
from virja.errors import ConfigError
from virja.jam.options import _KEYS as JAM_KEYS
from virja.jam.options import JamOptions
from virja.plan.config import load_plan_config, plan_config_from_table
from virja.routing import ROUTING_KEYS, RoutingConfig

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "virja.example.toml"


def plan_keys() -> list[str]:
    """The keys [plan] accepts, as its own error message lists them."""
    try:
        plan_config_from_table({"no_such_key": 1}, None)
    except ConfigError as exc:
        return [k.strip() for k in str(exc).split("known:")[1].split(",")]
    raise AssertionError("an unknown [plan] key was accepted")


def test_the_example_loads_and_states_the_defaults() -> None:
    doc = load_config(EXAMPLE)
    assert set(doc) == KNOWN_TABLES
    assert RoutingConfig.from_dict(section(doc, "routing")) == RoutingConfig()
    assert load_plan_config(EXAMPLE) == load_plan_config(None)
    assert JamOptions.merge(section(doc, "jam"), {}) == JamOptions()


def test_the_example_documents_every_key() -> None:
    """Each key appears, set or commented out, under its table."""
    text = EXAMPLE.read_text()
    tables = re.split(r"^\[(\w+)\]$", text, flags=re.M)
    body = dict(zip(tables[1::2], tables[2::2], strict=True))
    for table, keys in (("routing", ROUTING_KEYS), ("plan", plan_keys()), ("jam", JAM_KEYS)):
        for key in keys:
            assert re.search(rf"^#? ?{key} = ", body[table], flags=re.M), f"[{table}] {key}"
