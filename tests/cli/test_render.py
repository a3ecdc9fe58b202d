"""`virja render`: frames in which the figures move on the notes; video with sound."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import mido
import numpy as np

from tests.conftest import save_midi
from virja.cli.main import main
from virja.render.images import decode_png_rgb

M = mido.Message
Meta = mido.MetaMessage


def one_beat(path: Path) -> Path:
    """120 bpm: a snare stroke at 1.0 s and a bass note at 1.0 s, nothing else."""
    conductor = [Meta("set_tempo", tempo=500_000, time=0)]
    drums = [
        M("note_on", channel=9, note=38, velocity=110, time=960),
        M("note_off", channel=9, note=38, time=240),
    ]
    bass = [
        M("program_change", channel=1, program=32, time=0),
        M("note_on", channel=1, note=45, velocity=100, time=960),
        M("note_off", channel=1, note=45, time=480),
    ]
    return save_midi(path, [conductor, drums, bass])


def test_render_frames_move_on_the_note_and_rest_elsewhere(tmp_path: Path, capsys: object) -> None:
    mid = one_beat(tmp_path / "one.mid")
    out = tmp_path / "frames"
    plan = tmp_path / "plan.jsonl"
    rc = main(
        [
            "render",
            str(mid),
            "--out",
            str(out),
            "--size",
            "160x96",
            "--fps",
            "20",
            "--samples",
            "1",
            "--start",
            "0",
            "--end",
            "2.0",
            "--plan-log",
            str(plan),
        ]
    )
    assert rc == 0
    frames = sorted(out.glob("frame_*.png"))
    assert len(frames) == 41  # 0.0 .. 2.0 s at exactly 1/20 s
    imgs = [decode_png_rgb(f.read_bytes()).astype(int) for f in frames]
    planned = [json.loads(line) for line in plan.read_text().splitlines()]
    starts = min(p["start"] for p in planned)
    first_moving = int(np.ceil(starts * 20))
    # before any motion starts, nothing changes between frames (idle breathing aside: small)
    still = np.abs(imgs[2] - imgs[0]).sum()
    moving = np.abs(imgs[20] - imgs[first_moving - 1]).sum()
    assert moving > 5 * max(still, 1), (still, moving)


def test_render_mp4_has_video_and_audio_tracks(tmp_path: Path) -> None:
    mid = one_beat(tmp_path / "one.mid")
    out = tmp_path / "one.mp4"
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "virja",
            "render",
            str(mid),
            "--out",
            str(out),
            "--size",
            "128x72",
            "--fps",
            "10",
            "--samples",
            "1",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    data = out.read_bytes()
    assert b"avc1" in data  # H.264 video
    assert b"mp4a" in data  # AAC audio from fluidsynth
    assert "wrote" in res.stdout


def test_render_single_png_at_a_time(tmp_path: Path) -> None:
    mid = one_beat(tmp_path / "one.mid")
    out = tmp_path / "at.png"
    assert (
        main(
            [
                "render",
                str(mid),
                "--out",
                str(out),
                "--at",
                "1.0",
                "--size",
                "64x48",
                "--samples",
                "1",
            ]
        )
        == 0
    )
    assert decode_png_rgb(out.read_bytes()).shape == (48, 64, 3)


def test_render_same_input_same_pixels(tmp_path: Path) -> None:
    mid = one_beat(tmp_path / "one.mid")
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    for out in (a, b):
        assert main(["render", str(mid), "--out", str(out), "--at", "0.95", "--size", "96x64"]) == 0
    assert a.read_bytes() == b.read_bytes()


def test_a_file_without_band_notes_is_refused(tmp_path: Path, capsys: object) -> None:
    mid = save_midi(
        tmp_path / "piano.mid",
        [
            [
                M("program_change", channel=0, program=0, time=0),
                M("note_on", channel=0, note=60, velocity=90, time=0),
                M("note_off", channel=0, note=60, time=480),
            ]
        ],
    )
    assert main(["render", str(mid), "--out", str(tmp_path / "x.mp4")]) == 1


def test_audio_onset_lines_up_with_the_note_in_the_video(tmp_path: Path) -> None:
    """The snare at 1.0 s sounds 1.0 s after the video's session-time zero."""
    import wave

    from virja.render.video import ffmpeg_exe

    mid = one_beat(tmp_path / "one.mid")
    out = tmp_path / "sync.mp4"
    # the video starts at -0.5 s: session time 1.0 s is 1.5 s into the file
    assert (
        main(
            [
                "render",
                str(mid),
                "--out",
                str(out),
                "--size",
                "64x48",
                "--fps",
                "10",
                "--start",
                "-0.5",
                "--end",
                "2.0",
            ]
        )
        == 0
    )
    wav = tmp_path / "sync.wav"
    subprocess.run(
        [
            ffmpeg_exe(),
            "-loglevel",
            "error",
            "-y",
            "-i",
            str(out),
            "-vn",
            "-ac",
            "1",
            "-ar",
            "8000",
            str(wav),
        ],
        check=True,
        timeout=60,
    )
    with wave.open(str(wav)) as w:
        pcm = np.frombuffer(w.readframes(w.getnframes()), dtype=np.int16).astype(float)
        rate = w.getframerate()
    onset = int(np.argmax(np.abs(pcm) > 0.05 * np.abs(pcm).max())) / rate
    assert abs(onset - 1.5) < 0.04, onset  # the soundfont's snare attack takes ~25 ms


def test_a_bass_known_only_by_its_program_is_rendered(tmp_path: Path) -> None:
    """Regression: the render's routing report skipped program changes, so a bass part
    on an unnamed track (GM program 32 only) was reported as nobody's and refused."""
    mid = save_midi(
        tmp_path / "p.mid",
        [
            [
                M("program_change", channel=2, program=32, time=0),
                M("note_on", channel=2, note=40, velocity=90, time=0),
                M("note_off", channel=2, note=40, time=480),
            ]
        ],
    )
    assert (
        main(
            ["render", str(mid), "--out", str(tmp_path / "p.png"), "--at", "0.0", "--size", "32x32"]
        )
        == 0
    )
