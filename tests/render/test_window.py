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
from virja.input import midi_input
from virja.plan.planner import OnlinePlanner
from virja.render.live import LiveView
from virja.render.camera import PRESETS
from virja.routing import Router, RoutingConfig
from virja.session import Performance, run_schedule
import virja, pathlib

view = LiveView((320, 200), title="virja test")
animator = BandAnimator()
demo = pathlib.Path(virja.__file__).parent / "demo" / "blues.mid"
src = midi_input(demo, RoutingConfig(), 1.0)
perf = Performance(router=Router(), planner=OnlinePlanner(), animator=animator)
run_schedule(perf, src.schedule)
frames = []
for i in range(6):  # the window's own framebuffer (GL name 0), frame after frame
    view.show(animator.pose(6.0 + 0.1 * i))
    assert view.host.ctx.error == "GL_NO_ERROR", view.host.ctx.error
    frames.append(view.host.read_window_rgb())
assert frames[0].shape == (200, 320, 3), frames[0].shape
assert frames[0].std() > 5, frames[0].std()
changed = sum(np.abs(a.astype(int) - b).mean() > 0.2 for a, b in zip(frames, frames[1:]))
assert changed >= 4, changed
still = animator.pose(6.0)
view.show(still)
before = view.host.read_window_rgb()
view.host.state.camera = PRESETS["top"]
view.show(still)
assert np.abs(view.host.read_window_rgb().astype(int) - before).mean() > 5
shots = []
view.host.on_screenshot = shots.append
view.host.state.screenshot_requested = True
view.show(still)
assert len(shots) == 1 and shots[0].shape == (200, 320, 3)
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
