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

import tomllib
from pathlib import Path
from typing import Any

from virja.errors import ConfigError, InputFileError

KNOWN_TABLES = frozenset({"routing", "plan", "jam"})


def load_config(path: str | Path | None) -> dict[str, Any]:
    """The parsed TOML document at ``path`` ({} for None); unknown tables are an error."""
    if path is None:
        return {}
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputFileError(p, f"cannot read config file: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise InputFileError(p, f"config file is not UTF-8 text: {exc.reason}") from exc
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputFileError(p, f"invalid TOML: {exc}") from exc
    unknown = sorted(set(doc) - KNOWN_TABLES)
    if unknown:
        raise ConfigError(
            f"{p}: unknown table(s) {', '.join(unknown)}; known: {', '.join(sorted(KNOWN_TABLES))}"
        )
    for name, table in doc.items():
        if not isinstance(table, dict):
            raise ConfigError(f"{p}: [{name}] must be a table")
    return doc


def section(doc: dict[str, Any], name: str) -> dict[str, Any]:
    """One table of the document ({} when absent)."""
    table = doc.get(name, {})
    assert isinstance(table, dict)
    return table
