"""One time base for users: seconds from the start of the input, for recordings too."""

from __future__ import annotations

from pathlib import Path

import pytest

from virja.cli.main import main
from virja.rmcp import wire
from virja.rmcp.pcap import PcapWriter

T0_US = 1_795_393_538_000_000  # a recording made in 2026: Unix time inside


def recording(path: Path) -> Path:
    """Snare sixteenths sent half a second ahead, the first packet at T0."""
    with PcapWriter.open(path, local=("127.0.0.1", 50500)) as w:
        for i in range(8):
            sound = T0_US + 500_000 + i * 125_000
            w.write(
                bytes(wire.midi(2, i, sound, bytes([0x99, 38, 100]))),
                ("127.0.0.1", 4000),
                time_us=sound - 500_000,
            )
    return path


def test_plan_of_a_recording_prints_seconds_from_its_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", str(recording(tmp_path / "s.pcap"))]) == 0
    out = capsys.readouterr().out
    assert "seconds from the recording's start" in out
    rows = [
        line.split()
        for line in out.splitlines()
        if line.split()[:2] and line.split()[1:2] == ["drums"]
    ]
    assert [float(r[0]) for r in rows[:2]] == [0.5, 0.625]
    others = [line for line in out.splitlines() if not line.startswith("times:")]
    assert "1795393538" not in "".join(others)  # only the header names session time


def test_render_at_is_seconds_from_the_recordings_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    rec = recording(tmp_path / "s.pcap")
    out_png = tmp_path / "x.png"
    assert main(["render", str(rec), "--out", str(out_png), "--at", "0.6", "--size", "64x36"]) == 0
    out = capsys.readouterr().out
    assert "from 0.60 s" in out and out_png.is_file()
    assert "outside the performance" not in caplog.text  # 0.6 s is in the middle of it
    assert main(["render", str(rec), "--out", str(out_png), "--at", "99", "--size", "64x36"]) == 0
    assert "--at 99.000 s is outside the performance" in caplog.text
