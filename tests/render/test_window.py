"""The window host under Xvfb: opens, draws the band, reads back, closes cleanly."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest


@pytest.fixture(scope="module")
def xvfb_display() -> Iterator[str]:
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (apt-get install xvfb); CI installs it")
    for n in range(90, 140):
        if not Path(f"/tmp/.X{n}-lock").exists():
            break
    display = f":{n}"
    proc = subprocess.Popen(
        ["Xvfb", display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 10
    while not Path(f"/tmp/.X11-unix/X{n}").exists():
        if time.monotonic() > deadline or proc.poll() is not None:
            proc.kill()
            pytest.fail("Xvfb did not start")
        time.sleep(0.05)
    old = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = display
    try:
        yield display
    finally:
        if old is None:
            os.environ.pop("DISPLAY", None)
        else:
            os.environ["DISPLAY"] = old
        proc.terminate()
        proc.wait(timeout=10)


WINDOW_SCRIPT = """
import numpy as np
from virja.motion.band import BandAnimator
from virja.plan.planner import OnlinePlanner
from virja.render.live import LiveView
from virja.routing import Router
from virja.session import Performance

view = LiveView((320, 200), title="virja test")
perf = Performance(router=Router(), planner=OnlinePlanner(), animator=BandAnimator())
for _ in range(3):
    view.frame(perf, 0.0)
assert view.host.ctx.error == "GL_NO_ERROR", view.host.ctx.error
shots = []
view.host.on_screenshot = shots.append
view.host.state.screenshot_requested = True
view.frame(perf, 0.0)
assert len(shots) == 1
img = shots[0]
assert img.shape == (200, 320, 3), img.shape
assert img.std() > 5, img.std()
assert not view.closed
view.close()
print("window ok")
"""


def test_window_draws_the_band_and_closes(xvfb_display: str) -> None:
    """In its own process: Mesa allows GLX (the window) or EGL (this suite's
    headless context) in one process, not both."""
    res = subprocess.run(
        [sys.executable, "-c", WINDOW_SCRIPT],
        capture_output=True,
        text=True,
        timeout=120,
        env=dict(os.environ, DISPLAY=xvfb_display),
    )
    assert res.returncode == 0, res.stderr
    assert "window ok" in res.stdout


def test_window_without_display_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    from virja.errors import NotAvailableError
    from virja.render.hosts import WindowHost

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(NotAvailableError, match="--headless"):
        WindowHost((64, 64))
