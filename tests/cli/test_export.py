"""`virja export` from the command line: outputs, one-line errors before any work, no GL."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import DEMO_MID
from tests.export.conftest import record_demo_pcap
from tests.export.test_gltf import validate
from virja.cli.main import main


def test_export_writes_every_format_and_says_how_fast(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["export", str(DEMO_MID), "--gltf", str(tmp_path / "b.glb")]
    args += ["--bvh", str(tmp_path / "b.bvh"), "--musicxml", str(tmp_path / "b.musicxml")]
    assert main([*args, "--fps", "10", "--start", "2", "--end", "6"]) == 0
    out = capsys.readouterr().out
    for name in ("b.glb", "b_drums.bvh", "b_bass.bvh", "b.musicxml"):
        assert f"wrote {tmp_path / name}" in out
    assert "exported 4.00 s (41 samples at 10 fps" in out and "x real time" in out
    assert validate(tmp_path / "b.glb")["issues"]["numErrors"] == 0


def test_export_of_a_recording(tmp_path: Path) -> None:
    demo_pcap = record_demo_pcap(tmp_path / "demo.pcap")
    out = tmp_path / "rec.glb"
    assert (
        main(
            [
                "export",
                str(demo_pcap),
                "--gltf",
                str(out),
                "--musicxml",
                str(tmp_path / "r.musicxml"),
            ]
        )
        == 0
    )
    assert validate(out)["issues"]["numErrors"] == 0
    import music21

    score = music21.converter.parse(tmp_path / "r.musicxml")
    # the recording's BEAT messages give the tempo and the bar
    assert round(score.metronomeMarkBoundaries()[0][2].number) == 132
    assert len(score.parts[0].flatten().notes) == 49


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--gltf", "{d}/x.obj"], "--gltf {d}/x.obj: the file name must end in .glb or .gltf"),
        (["--bvh", "{d}/no/x.bvh"], "--bvh {d}/no/x.bvh: the folder {d}/no does not exist"),
        (["--musicxml", "{d}"], "--musicxml {d}: the file name must end in .musicxml or .xml"),
        (["--gltf", "{d}/a.glb", "--fps", "0"], "--fps must be in (0, 240], got 0.0"),
        (["--gltf", "{d}/a.glb", "--start", "5", "--end", "1"], "--end 1.0 is before --start 5.0"),
        ([], "nothing to export: give --gltf, --bvh and/or --musicxml"),
    ],
)
def test_bad_requests_are_one_line_errors_before_any_work(
    args: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["export", str(DEMO_MID), *(a.format(d=tmp_path) for a in args)]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip()
    assert err == f"virja export: error: {message.format(d=tmp_path)}"
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_bad_input_is_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    junk = tmp_path / "junk.mid"
    junk.write_bytes(b"not midi at all")
    for src in (tmp_path / "missing.mid", junk):
        assert main(["export", str(src), "--gltf", str(tmp_path / "o.glb")]) == 1
        err = capsys.readouterr().err
        assert err.startswith("virja export: error: ") and err.count("\n") == 1
        assert str(src) in err
    assert not (tmp_path / "o.glb").exists()


def test_export_imports_no_gl(tmp_path: Path) -> None:
    code = (
        "import sys; from virja.cli.main import main; "
        f"rc = main(['export', {str(DEMO_MID)!r}, '--gltf', {str(tmp_path / 'a.glb')!r}, "
        "'--end', '1']); "
        "assert rc == 0; bad = [m for m in ('moderngl', 'glfw', 'virja.render.renderer') if m in sys.modules]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120, capture_output=True)
