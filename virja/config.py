"""The configuration file: one TOML document, one table per layer.

```toml
[routing]      # virja.routing.RoutingConfig (docs/routing.md)
[plan]         # virja.plan.config: tunings, frets, replacement tables (docs/scheduler.md)
[jam]          # virja.jam.options: split, upper keys, delay, ports (docs/jam.md)
```

Any other table is refused (a misspelt one must not be ignored in silence);
rendering options are command-line flags only.

This module only reads and checks the document's shape; each layer parses its
own table, so a layer's options live beside the code that uses them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from virja import tomlconf
from virja.errors import ConfigError, InputFileError
from virja.tomlconf import Schema


class ConfigFile(Schema):
    """The document: each layer's table, converted by that layer to its own schema
    (``RoutingTable``, ``PlanTable``, ``JamTable``)."""

    routing: dict[str, Any] = {}
    plan: dict[str, Any] = {}
    jam: dict[str, Any] = {}


KNOWN_TABLES = frozenset(ConfigFile.__struct_fields__)


def _input_error(where: str, reason: str) -> Exception:
    return InputFileError(where, reason)


def load_config(path: str | Path | None) -> dict[str, Any]:
    """The parsed TOML document at ``path`` ({} for None); unknown tables are an error."""
    if path is None:
        return {}
    doc = tomlconf.read(path, noun="config file", error=_input_error)
    try:
        tomlconf.convert(doc, ConfigFile, str(path), finite=False)
    except tomlconf.SchemaError as exc:
        if exc.key in doc and exc.key not in KNOWN_TABLES:
            raise ConfigError(
                f"{path}: unknown table(s) {', '.join(sorted(set(doc) - KNOWN_TABLES))}; "
                f"known: {', '.join(sorted(KNOWN_TABLES))}"
            ) from None
        raise
    return doc


def section(doc: dict[str, Any], name: str) -> dict[str, Any]:
    """One table of the document ({} when absent)."""
    table = doc.get(name, {})
    assert isinstance(table, dict)
    return table
