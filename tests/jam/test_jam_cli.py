"""`virja jam` end to end: options, errors as one line, a headless jam with a plan log."""

from __future__ import annotations

import json
import os
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from virja.cli.main import main
from virja.errors import ConfigError
from virja.jam.options import JamOptions
from virja.jam.ports import list_ports

if TYPE_CHECKING:
    from tests.jam.conftest import JackKeyboard

from tests.jam.conftest import wait_until  # noqa: E402


def test_flags_override_the_config_table() -> None:
    opts = JamOptions.merge({"split": 60, "delay_ms": 100}, {"split": 40, "delay_ms": None})
    assert (opts.split, opts.delay_s, opts.upper) == (40, 0.1, "ignore")


def test_unknown_config_keys_are_refused() -> None:
    with pytest.raises(ConfigError, match="unknown key"):
        JamOptions.merge({"splt": 60}, {})


@pytest.mark.parametrize(
    ("table", "match"),
    [({"delay_ms": -5}, "delay_ms"), ({"split": "H3"}, "split"), ({"split": 128}, "split"),
     ({"split": True}, "split"), ({"api": "coreaudio"}, "api")],
)  # fmt: skip
def test_bad_option_values_are_config_errors(table: dict[str, object], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        JamOptions.merge(table, {})


@pytest.mark.parametrize(
    ("value", "key"), [("C3", 48), ("48", 48), (48, 48), ("Bb2", 46), ("F#3", 54), ("c4", 60)]
)
def test_the_split_is_a_key_name_or_number(value: object, key: int) -> None:
    """The help and the docs name the split as C3: the flag and the config take it so."""
    assert JamOptions.merge({}, {"split": value}).split == key
    assert JamOptions.merge({"split": value}, {}).split == key


def test_help_names_the_latency_option(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["jam", "--help"])
    assert "--delay-ms" in capsys.readouterr().out


@pytest.mark.skipif(os.path.exists("/dev/snd/seq"), reason="this machine has an ALSA sequencer")
def test_missing_alsa_is_one_clear_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["jam", "--api", "alsa", "--headless", "--duration", "1"]) == 1
    err = capsys.readouterr().err
    assert "ALSA sequencer" in err and "Traceback" not in err


@pytest.mark.jack
def test_list_ports_prints_the_keyboard(
    keyboard: JackKeyboard, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["jam", "--api", "jack", "--list-ports"]) == 0
    assert "kbd-sender:keys" in capsys.readouterr().out


@pytest.mark.jack
def test_missing_port_exits_non_zero_without_traceback(
    keyboard: JackKeyboard, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["jam", "--port", "no-such-thing", "--headless", "--duration", "1"]) == 1
    err = capsys.readouterr().err
    assert "no MIDI source (keyboard) port matches 'no-such-thing'" in err
    assert "Traceback" not in err


@pytest.mark.jack
def test_headless_jam_plans_the_keys_played(keyboard: JackKeyboard, tmp_path: Path) -> None:
    """Bass keys and channel 10 become planned motions; their time counts from the jam's
    start, their session_time is Unix time on arrival."""
    log = tmp_path / "jam.jsonl"
    argv = [
        "jam",
        "--port",
        "kbd-sender",
        "--headless",
        "--duration",
        "1.5",
        "--plan-log",
        str(log),
    ]
    result: list[int] = []
    thread = threading.Thread(target=lambda: result.append(main(argv)))
    thread.start()
    try:
        assert wait_until(lambda: "virja:virja" in list_ports("jack", "output"))
        before = time.time()
        keyboard.send(0x90, 40, 100)  # E2: bass
        keyboard.send(0x99, 38, 100)  # snare
        keyboard.send(0x90, 72, 100)  # C5: the pianist's
        after = time.time()
    finally:
        thread.join(timeout=10)
    assert result == [0]
    planned = [json.loads(line) for line in log.read_text().splitlines()]
    assert sorted((p["performer"], p["note"]) for p in planned) == [("bass", 40), ("drums", 38)]
    for p in planned:
        assert before - 1.0 <= p["session_time"] <= after + 1.0  # Unix seconds
        assert 0.0 <= p["time"] <= 1.5 + 1.0  # seconds from the jam's start
