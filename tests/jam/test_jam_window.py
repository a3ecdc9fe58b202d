"""`virja jam` in a window under Xvfb: keys played move the band on screen (pixels read
from the X screen, not from any GL buffer)."""

from __future__ import annotations

import re
import subprocess
import sys
import time
from collections.abc import Iterator

import numpy as np
import pytest
from numpy.typing import NDArray

from tests.jam.conftest import JackKeyboard
from tests.live.xdisplay import XDisplay, env_for, start_xvfb

W, H = 1280, 720  # the jam window's size


@pytest.fixture(scope="module")
def display() -> Iterator[str]:
    yield from start_xvfb("1400x900x24")  # the jam window is 1280x720


def _changed(a: NDArray[np.uint8], b: NDArray[np.uint8]) -> float:
    """The fraction of pixels that changed visibly."""
    return float((np.abs(a.astype(np.int16) - b.astype(np.int16)).sum(axis=2) > 30).mean())


def _wait_drawn(x: XDisplay, timeout_s: float = 30.0) -> bool:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if x.screenshot(W, H).std() > 5:
            return True
        time.sleep(0.3)
    return False


@pytest.mark.jack
def test_keys_played_move_the_band_in_the_jam_window(keyboard: JackKeyboard, display: str) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "virja", "jam", "--port", "kbd-sender", "--duration", "40"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env_for(display),
    )
    x = XDisplay(display)
    try:
        assert proc.stdout is not None
        assert "virja jam:" in proc.stdout.readline()
        assert _wait_drawn(x), "the window never drew"
        time.sleep(0.5)
        still = x.screenshot(W, H)
        time.sleep(0.5)
        assert _changed(still, x.screenshot(W, H)) < 0.001  # nothing played: the band is still
        moved = 0
        for _ in range(8):
            keyboard.send(0x99, 38, 120)  # snare
            keyboard.send(0x90, 40, 100)  # E2: bass
            time.sleep(0.1)
            moved += _changed(still, x.screenshot(W, H)) > 0.002
            time.sleep(0.3)
        x.move(W // 2, H // 2)
        x.key("q")  # closing the window ends the jam
        out, err = proc.communicate(timeout=30)
    finally:
        x.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert moved >= 3, moved
    m = re.search(r"(\d+) messages, .* (\d+) motions planned", out)
    assert m, out
    assert int(m.group(1)) >= 12 and int(m.group(2)) == int(m.group(1)), out  # each key planned
