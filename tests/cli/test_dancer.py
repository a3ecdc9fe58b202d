"""`--dancer DB` draws a third figure from the session's audio; `virja dance --render` makes a video."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from virja.cli.main import main
from virja.dance.audio import read_audio_8k
from virja.dance.band_capture import capture_session, write_session_midi
from virja.dance.database import save_database, teach
from virja.motion.bvh import read_bvh
from virja.render.images import decode_png_rgb
from virja.render.video import find_soundfont

pytestmark = pytest.mark.skipif(
    find_soundfont() is None or shutil.which("fluidsynth") is None,
    reason="the dancer dances to the session's audio: fluidsynth and a GM soundfont are needed",
)


@pytest.fixture(scope="module")
def band(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """(session.mid, its WAV, a database taught from the drummer's capture of it)."""
    folder = tmp_path_factory.mktemp("dancer")
    mid = write_session_midi(folder / "s.mid", bpm=150, bars=2, groove="straight", seed=1)
    cap = capture_session(mid, folder / "s")
    db = teach(read_bvh(cap.drums), read_audio_8k(cap.wav), "arms", source="drums")
    save_database(db, folder / "db")
    return mid, cap.wav, folder / "db"


def frames(folder: Path) -> list[np.ndarray]:
    return [decode_png_rgb(f.read_bytes()).astype(int) for f in sorted(folder.glob("frame_*.png"))]


def test_render_with_dancer_draws_a_figure_that_moves(
    band: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    mid, _, db = band
    common = ["--size", "96x64", "--fps", "4", "--start", "0.5", "--end", "2.5"]
    assert (
        main(["render", str(mid), "--out", str(tmp_path / "with"), "--dancer", str(db), *common])
        == 0
    )
    assert main(["render", str(mid), "--out", str(tmp_path / "without"), *common]) == 0
    with_, without = frames(tmp_path / "with"), frames(tmp_path / "without")
    assert len(with_) == len(without) == 9
    masks = [np.abs(a - b).sum(axis=2) > 30 for a, b in zip(with_, without, strict=True)]
    assert all(m.sum() > 20 for m in masks)  # the dancer is on every frame
    changed = [int((masks[0] ^ m).sum()) for m in masks[1:]]
    assert max(changed) > 10, changed  # and its pixels move over time


def test_replay_refuses_dancer_without_out(
    band: tuple[Path, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pcap = tmp_path / "x.pcap"
    pcap.write_bytes(b"")
    assert main(["replay", str(pcap), "--dancer", str(band[2])]) == 1
    assert "--dancer draws into a rendering: give --out too" in capsys.readouterr().err


def test_dance_render_writes_a_video_with_the_music(
    band: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    _, wav, db = band
    out = tmp_path / "dance.mp4"
    rc = main(
        ["dance", str(wav), "--db", str(db), "--out", str(tmp_path / "d.bvh"),
         "--render", str(out), "--size", "64x48", "--fps", "5"]
    )  # fmt: skip
    assert rc == 0
    data = out.read_bytes()
    assert b"avc1" in data and b"mp4a" in data
