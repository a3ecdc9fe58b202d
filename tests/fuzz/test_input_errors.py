"""D5, D6, D8 (docs/reliability.md): a bad key signature, a bad animation.toml and bad
key files give one clear error (or a warning), never a traceback or a hang."""

from __future__ import annotations

import logging
import os
import struct
from pathlib import Path

import pytest

from tests.fuzz.mutate import time_limit
from virja.errors import ConfigError, InputFileError
from virja.motion.band import AnimationSettings
from virja.resources import motions_dir
from virja.rmcp.signing import key_bytes, load_key


def _midi_with_key_signature(mode: int) -> bytes:
    trk = bytes([0x00, 0xFF, 0x59, 0x02, 0x00, mode, 0x00, 0x99, 38, 100, 0x60, 0x89, 38, 0])
    trk += bytes([0x00, 0xFF, 0x2F, 0x00])
    return b"MThd" + struct.pack(">IHHH", 6, 0, 1, 96) + b"MTrk" + struct.pack(">I", len(trk)) + trk


@pytest.mark.parametrize("command", ["plan", "render"])
def test_key_signature_mode_2_is_a_one_line_error(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from virja.cli.main import main

    p = tmp_path / "k.mid"
    p.write_bytes(_midi_with_key_signature(2))
    args = [command, str(p)] + (["--out", str(tmp_path / "o")] if command == "render" else [])
    assert main(args) != 0
    err = capsys.readouterr().err
    assert "bad key signature" in err and "Traceback" not in err


def _animation(tmp_path: Path, text: str | bytes) -> Path:
    p = tmp_path / "animation.toml"
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    return p


def test_animation_toml_faults_are_config_errors(tmp_path: Path) -> None:
    good = (motions_dir() / "animation.toml").read_text(encoding="utf-8")
    assert AnimationSettings.load(_animation(tmp_path, good)).sway_period_s > 0
    cases = {
        "not UTF-8": b"\xff\xfe[idle]\n",
        "invalid TOML": "[idle\n",
        "idle.sway_period_x: unknown key": good.replace("sway_period_s", "sway_period_x"),
        "missing idle.sway_period_s": "\n".join(
            ln for ln in good.splitlines() if not ln.strip().startswith("sway_period_s")
        ),
        "sway_period_s must be": good.replace(
            f"sway_period_s = {_value(good, 'sway_period_s')}", "sway_period_s = 0"
        ),
    }
    for why, text in cases.items():
        with pytest.raises(ConfigError, match=why):
            AnimationSettings.load(_animation(tmp_path, text))


def _value(text: str, key: str) -> str:
    line = next(ln for ln in text.splitlines() if ln.strip().startswith(key))
    return line.split("=", 1)[1].split("#")[0].strip()


def test_key_file_fifo_and_device_are_refused_without_hanging(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with time_limit(5), pytest.raises(InputFileError, match="not a regular file"):
        load_key(fifo)
    if os.path.exists("/dev/zero"):
        with time_limit(5), pytest.raises(InputFileError, match="not a regular file"):
            load_key("/dev/zero")
    big = tmp_path / "big"
    big.write_bytes(b"k" * 5000)
    with pytest.raises(InputFileError, match="at most"):
        load_key(big)


def test_weak_and_world_readable_keys_warn(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    p = tmp_path / "k"
    p.write_bytes(b"x")
    p.chmod(0o644)
    with caplog.at_level(logging.WARNING):
        assert load_key(p) == b"x"
    text = caplog.text
    assert "weak" in text and "readable by others" in text
    caplog.clear()
    p.write_bytes(os.urandom(32).replace(b"\n", b"n"))
    p.chmod(0o600)
    with caplog.at_level(logging.WARNING):
        load_key(p)
    assert caplog.text == ""


def test_key_bytes_are_exact_except_a_text_keys_line_end() -> None:
    assert key_bytes(b"secret\n") == b"secret"
    assert key_bytes(b"secret\r\n") == b"secret"
    assert key_bytes(b" spaced key ") == b" spaced key "
    binary = bytes([0x20, 0x00, 0x09, 0xFF, 0x0A])  # whitespace at both ends, kept
    assert key_bytes(binary) == binary
    # every 32-byte key with a non-printable byte is used exactly (the 4.5 % that changed)
    import random

    rng = random.Random(3)
    for _ in range(2000):
        k = bytes(rng.randrange(256) for _ in range(32))
        if any(not 0x20 <= c < 0x7F for c in k[:-1]):
            assert key_bytes(k) == k
