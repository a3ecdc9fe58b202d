"""The options of a jam: the ``[jam]`` table of the config file, overridden by flags.

```toml
[jam]
api = "jack"          # "jack" | "alsa"; absent: the first that works here
port = "Keystation"   # connect to the first source whose name contains this
split = "C3"          # lowest key of the pianist's part (or 48); below it: the bassist
upper = "ignore"      # "ignore" | "drums": the upper keys play the drummer
delay_ms = 0          # put sound (thru) and picture off by this much
thru = "fluidsynth"   # forward notes to the first synth port whose name contains this
send = "host:50500"   # also stream the band's notes as RMCP/1 to a `virja serve`
fps = 60              # frames per second of the loop (headless: the planner's tick)
```
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from virja import tomlconf
from virja.errors import ConfigError
from virja.jam.keyboard import DEFAULT_SPLIT, UPPER_MODES, KeyboardLayout, UpperMode
from virja.jam.ports import API_NAMES
from virja.tomlconf import Schema

MAX_DELAY_MS = 2000.0  # more than two seconds is not a jam any more; a typo, most likely

_KEY_NAME = re.compile(r"^([A-Ga-g])([#b]?)(-?\d)$")
_PITCH = {"c": 0, "d": 2, "e": 4, "f": 5, "g": 7, "a": 9, "b": 11}


def parse_key(value: object) -> int:
    """A key as a MIDI number (48) or a name with its octave, middle C being C4 ("C3" is
    48, "Bb2" 46, "F#3" 54); a ConfigError for anything else or outside 0-127."""
    if isinstance(value, int) and not isinstance(value, bool):
        key = value
    elif isinstance(value, str) and value.strip().lstrip("-").isdigit():
        key = int(value)
    elif isinstance(value, str) and (m := _KEY_NAME.match(value.strip())):
        letter, accidental, octave = m.groups()
        key = 12 * (int(octave) + 1) + _PITCH[letter.lower()] + {"#": 1, "b": -1, "": 0}[accidental]
    else:
        raise ConfigError(f"split: {value!r} is not a key; give a MIDI number (48) or a name (C3)")
    if not 0 <= key <= 127:
        raise ConfigError(f"split: {value!r} is outside the MIDI keys 0-127")
    return key


class JamTable(Schema):
    """The ``[jam]`` table (the module's docstring shows each key); absent: the default."""

    api: str | None = None
    port: str | None = None
    split: int | str | None = None
    upper: str | None = None
    delay_ms: float | None = None
    thru: str | None = None
    send: str | None = None
    fps: float | None = None


_KEYS = tuple(JamTable.__struct_fields__)


@dataclass(frozen=True, slots=True)
class JamOptions:
    api: str | None = None
    port: str | None = None
    split: int = DEFAULT_SPLIT
    upper: UpperMode = "ignore"
    delay_ms: float = 0.0
    thru: str | None = None
    send: str | None = None
    fps: float = 60.0

    def __post_init__(self) -> None:
        if self.api is not None and self.api not in API_NAMES:
            raise ConfigError(f"api must be one of {', '.join(API_NAMES)}, got {self.api!r}")
        if not 0.0 <= self.delay_ms <= MAX_DELAY_MS:
            raise ConfigError(f"delay_ms must be 0-{MAX_DELAY_MS:g}, got {self.delay_ms:g}")
        if not 1.0 <= self.fps <= 1000.0:
            raise ConfigError(f"fps must be 1-1000, got {self.fps:g}")
        if self.upper not in UPPER_MODES:
            raise ConfigError(f"upper must be one of {', '.join(UPPER_MODES)}, got {self.upper!r}")
        self.layout  # noqa: B018 - validates the split

    @property
    def layout(self) -> KeyboardLayout:
        return KeyboardLayout(split=self.split, upper=self.upper)

    @property
    def delay_s(self) -> float:
        return self.delay_ms / 1000.0

    @classmethod
    def merge(
        cls, table: Mapping[str, Any], overrides: Mapping[str, Any], *, where: str = "[jam]"
    ) -> JamOptions:
        """The ``[jam]`` table (``where`` names it in errors) with the flags given (None:
        not given) on top."""
        tomlconf.convert(table, JamTable, where)  # unknown keys, types: the file's own
        merged = {**table, **{k: v for k, v in overrides.items() if k in _KEYS and v is not None}}
        given = tomlconf.fields(tomlconf.convert(merged, JamTable, "[jam]"))
        values: dict[str, Any] = {k: v for k, v in given.items() if v is not None}
        if "split" in values:
            values["split"] = parse_key(values["split"])
        return cls(**values)
