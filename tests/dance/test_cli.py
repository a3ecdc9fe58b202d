"""Tests of `virja beats`, `virja teach` and `virja dance` (through virja.cli.main.main)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import soundfile

from virja.cli.main import main
from virja.dance.synth_capture import Teacher
from virja.dance.synth_music import music
from virja.motion.bvh import read_bvh, write_bvh
from virja.motion.skeleton import SKELETON


@pytest.fixture()
def files(tmp_path: Path, bounce: Teacher, bounce_music: np.ndarray) -> dict[str, Path]:
    cap = tmp_path / "cap.bvh"
    write_bvh(bounce.bvh, cap)
    wav = tmp_path / "cap.wav"
    soundfile.write(str(wav), bounce_music * 0.5, 8000, subtype="FLOAT")
    beats = 0.4 + np.cumsum(np.random.default_rng(8).uniform(0.3, 1.0, 12))
    new = tmp_path / "new.flac"
    soundfile.write(str(new), music(beats, beats[-1] + 0.5, seed=8) * 0.5, 8000)
    return {"cap": cap, "wav": wav, "new": new}


def test_beats_json_prints_one_object(
    files: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["beats", str(files["new"]), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out) == ["beats"] and len(out["beats"]) == 12


def test_beats_prints_one_time_per_line(
    files: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["beats", str(files["new"])]) == 0
    lines = capsys.readouterr().out.split()
    assert len(lines) == 12 and all(float(x) > 0 for x in lines)


def test_unreadable_audio_is_a_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "x.wav"
    bad.write_text("hello")
    assert main(["beats", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "x.wav" in err and "Traceback" not in err and err.count("\n") == 1


@pytest.mark.parametrize("keep", [False, True])
def test_teach_then_dance_writes_a_bvh_on_the_figure_or_the_teachers_skeleton(
    files: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str], keep: bool
) -> None:
    db = tmp_path / "db"
    args = ["teach", str(files["cap"]), str(files["wav"]), "--parts", "legs", "--out", str(db)]
    assert main(args + (["--keep-skeleton"] if keep else [])) == 0
    assert (db / "manifest.json").is_file()
    assert ("retargeted" in capsys.readouterr().out) is not keep
    out = tmp_path / "out.bvh"
    assert main(["dance", str(files["new"]), "--db", str(db), "--out", str(out)]) == 0
    motion = read_bvh(out)
    want = read_bvh(files["cap"]).names if keep else list(SKELETON.names)
    assert motion.names == want
    assert motion.n_frames > 100
    assert "segments" in capsys.readouterr().out


def test_dance_with_missing_database_is_a_one_line_error(
    files: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(
            [
                "dance",
                str(files["new"]),
                "--db",
                str(tmp_path / "nodb"),
                "--out",
                str(tmp_path / "o.bvh"),
            ]
        )
        == 1
    )
    assert "no manifest.json" in capsys.readouterr().err


def test_beats_of_silence_says_so_and_fails(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    quiet = tmp_path / "silence.wav"
    soundfile.write(str(quiet), np.zeros(8000 * 3, dtype=np.float32), 8000)
    assert main(["beats", str(quiet)]) == 1
    out, err = capsys.readouterr()
    assert out == "" and "no beats found" in err and "--k" in err


def test_teach_never_overwrites_a_database_unasked(
    files: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    db = tmp_path / "db"
    args = ["teach", str(files["cap"]), str(files["wav"]), "--parts", "legs", "--out", str(db)]
    assert main(args) == 0
    before = (db / "manifest.json").read_bytes()
    capsys.readouterr()
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "exists" in err and "--append" in err and "--force" in err
    assert (db / "manifest.json").read_bytes() == before
    assert main([*args, "--force"]) == 0
