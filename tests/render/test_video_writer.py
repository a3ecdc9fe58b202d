"""The video writer fed from its own thread: every frame in order, failures said."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from virja.errors import NotAvailableError
from virja.render.video import VideoWriter, ffmpeg_exe

W, H = 64, 48


def _decode(path: Path) -> np.ndarray:
    raw = subprocess.run(
        [
            ffmpeg_exe(),
            "-loglevel",
            "error",
            "-i",
            str(path),
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb24",
            "-",
        ],
        capture_output=True,
        check=True,
    ).stdout
    return np.frombuffer(raw, dtype=np.uint8).reshape(-1, H, W, 3)


@pytest.mark.parametrize("queue_frames", [0, 2])
def test_queued_frames_arrive_all_and_in_order(tmp_path: Path, queue_frames: int) -> None:
    out = tmp_path / "grey.mp4"
    writer = VideoWriter(out, (W, H), 25.0, queue_frames=queue_frames)
    levels = [(i * 37) % 250 for i in range(20)]
    for level in levels:
        writer.write_raw(bytes([level]) * (W * H * 3))
    writer.close()
    frames = _decode(out)
    assert len(frames) == len(levels)
    got = frames.reshape(len(levels), -1).mean(axis=1)
    assert np.all(np.abs(got - np.array(levels)) < 4), got


def test_a_failing_encoder_is_said_not_hung(tmp_path: Path) -> None:
    out = tmp_path / "no-such-folder" / "x.mp4"  # ffmpeg cannot open it and stops
    writer = VideoWriter(out, (W, H), 25.0, queue_frames=2)
    with pytest.raises(NotAvailableError, match="ffmpeg"):
        for _ in range(200):
            writer.write_raw(bytes(W * H * 3))
        writer.close()
