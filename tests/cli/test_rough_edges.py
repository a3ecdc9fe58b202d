"""Rough edges a new user hits: each a one-line error or warning before any long work."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from virja.cli.main import main

DEMO = str(Path(__file__).resolve().parents[2] / "virja" / "demo" / "blues.mid")


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def one_line_error(err: str, *words: str) -> None:
    lines = [ln for ln in err.splitlines() if "error:" in ln]
    assert len(lines) == 1, err
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture
def readonly(tmp_path: Path) -> Path:
    """A folder nobody may write (root too: /proc refuses new files)."""
    return Path("/proc/virja-no-such-dir")


def test_plan_log_to_an_unwritable_path(
    capsys: pytest.CaptureFixture[str], readonly: Path, tmp_path: Path
) -> None:
    code, _, err = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "x.png"),
        "--at",
        "1",
        "--plan-log",
        str(readonly / "p.jsonl"),
    )
    assert code == 1
    one_line_error(err, "--plan-log", "cannot write")


def test_out_to_an_unwritable_path(capsys: pytest.CaptureFixture[str], readonly: Path) -> None:
    code, _, err = run(capsys, "render", DEMO, "--out", str(readonly / "x.png"), "--at", "1")
    assert code == 1
    one_line_error(err, "--out", "cannot write")


def test_bvh_to_an_unwritable_path_fails_before_the_render(
    capsys: pytest.CaptureFixture[str], readonly: Path, tmp_path: Path
) -> None:
    code, out, err = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "x.png"),
        "--at",
        "1",
        "--bvh",
        str(readonly / "band.bvh"),
    )
    assert code == 1
    one_line_error(err, "--bvh", "band_drums.bvh")
    assert "wrote" not in out and not (tmp_path / "x.png").exists()


def test_a_missing_soundfont_is_an_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, _, err = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "x.mp4"),
        "--end",
        "0.1",
        "--soundfont",
        "/nonexistent.sf2",
    )
    assert code == 1
    one_line_error(err, "--soundfont", "/nonexistent.sf2")


def test_a_soundfont_that_is_not_one_is_an_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    text = tmp_path / "notes.sf2"
    text.write_text("not a soundfont")
    code, _, err = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "x.mp4"),
        "--end",
        "0.1",
        "--soundfont",
        str(text),
    )
    assert code == 1
    one_line_error(err, "not a SoundFont 2 file")


def test_virja_soundfont_not_a_soundfont_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    from virja.render.video import find_soundfont

    text = tmp_path / "notes.txt"
    text.write_text("not a soundfont")
    monkeypatch.setenv("VIRJA_SOUNDFONT", str(text))
    assert find_soundfont(None) != text
    assert "VIRJA_SOUNDFONT" in caplog.text and "not a SoundFont 2 file" in caplog.text


def test_at_past_the_end_warns(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    code, _, _ = run(capsys, "render", DEMO, "--out", str(tmp_path / "x.png"), "--at", "99")
    assert code == 0
    assert "--at 99.000 s is outside the performance" in caplog.text


def test_numbered_frames_are_named_as_written(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, out, _ = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "seq.png"),
        "--start",
        "1",
        "--end",
        "1.1",
        "--size",
        "64x36",
    )
    assert code == 0
    assert f"to {tmp_path / 'seq_00000.png'} ... seq_00003.png" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"seq_{i:05d}.png" for i in range(4)]


def test_one_track_is_one_track(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    import mido

    mid = mido.MidiFile(type=0)
    track = mido.MidiTrack()
    track += [mido.Message("note_on", channel=9, note=38, velocity=90, time=0),
              mido.Message("note_off", channel=9, note=38, velocity=0, time=240)]  # fmt: skip
    mid.tracks.append(track)
    path = tmp_path / "one.mid"
    mid.save(path)
    code, out, _ = run(
        capsys,
        "render",
        str(path),
        "--out",
        str(tmp_path / "x.png"),
        "--at",
        "0",
        "--size",
        "64x36",
    )
    assert code == 0 and ": 1 track, " in out


def test_an_interrupted_video_is_removed_and_said(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from virja.render.camera import PRESETS
    from virja.render.offline import OutputSpec, RenderSettings, render_frames
    from virja.render.scene import static_scene

    video = tmp_path / "x.mp4"

    def stop_at_three(done: int, total: int, elapsed_s: float) -> None:
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        render_frames(
            [i / 30 for i in range(30)],
            lambda t: [static_scene()],
            RenderSettings(
                OutputSpec("video", video),
                size=(64, 36),
                fps=30,
                camera=PRESETS["front"],
                progress=stop_at_three,
            ),
        )
    assert not video.exists()
    assert "interrupted: the unfinished video" in caplog.text


def test_render_docs_state_the_samples_default() -> None:
    from virja.cli.main import build_parser

    parser = build_parser("render")
    sub = next(a for a in parser._actions if a.dest == "command")
    render = sub.choices["render"]  # type: ignore[attr-defined]
    default = next(a.default for a in render._actions if a.dest == "samples")
    docs = (Path(__file__).resolve().parents[2] / "docs" / "rendering.md").read_text()
    assert default == 1
    assert "offline renders default to\n`--samples 4`" not in docs
    assert "use no multisampling by default" in " ".join(docs.split())
    assert os.path.exists(DEMO)


def test_render_with_the_follow_camera(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(
        capsys,
        "render",
        DEMO,
        "--out",
        str(tmp_path / "x.png"),
        "--at",
        "9.0",
        "--size",
        "64x36",
        "--camera",
        "follow",
    )
    assert code == 0 and "follow camera:" in out and (tmp_path / "x.png").is_file()


@pytest.mark.parametrize("frets", ["1", "3"])
def test_too_few_frets_is_a_config_error_naming_the_minimum(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, frets: str
) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text(f"[plan]\nbass_frets = {frets}\n")
    for cmd in (["plan", DEMO], ["render", DEMO, "--out", str(tmp_path / "x.png"), "--at", "1"]):
        code, _, err = run(capsys, *cmd, "--config", str(cfg))
        assert code == 1
        one_line_error(err, f"bass frets = {frets}", "at least 4")
