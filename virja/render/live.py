"""Live drawing in a window: one frame of a performance at the current time.

Used by ``serve``, ``replay`` (without --out) and ``jam``: the host is a glfw
window, the timer the session clock (or a replay clock), the drawing the same
:class:`~virja.render.renderer.Renderer` as offline.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

from virja.render.hosts import OffscreenTarget, WindowHost
from virja.render.images import write_png
from virja.render.renderer import DrawList, Renderer
from virja.render.scene import band_scene, static_scene
from virja.session import Performance

log = logging.getLogger(__name__)


class LiveView:
    """A window showing a performance; call :meth:`frame` as often as you like."""

    def __init__(
        self, size: tuple[int, int] = (1280, 720), title: str = "virja", samples: int = 1
    ) -> None:
        self.host = WindowHost(size, title)
        self.samples = samples
        self.target: OffscreenTarget | None = None
        self.lead_s = 0.0  # running estimate of one frame's drawing time
        self.renderer = Renderer(self.host.ctx)
        self.static: DrawList = static_scene()
        self.host.on_screenshot = self._save_screenshot
        self._fps_frames = 0
        self._fps_since = time.perf_counter()
        self.fps = 0.0

    def _save_screenshot(self, rgb: object) -> None:
        import numpy as np

        path = Path(f"virja-{time.strftime('%Y%m%d-%H%M%S')}.png")
        assert isinstance(rgb, np.ndarray)
        write_png(path, rgb)
        log.warning("screenshot saved to %s", path)

    @property
    def closed(self) -> bool:
        return self.host.should_close

    def frame(self, perf: Performance, time_s: float) -> None:
        """Draw the band offscreen, copy it to the window, show it.

        The pose drawn is the one at ``time_s`` plus the time a frame takes to draw
        (a running estimate): the picture shows the moment at which it appears,
        so an impact is on screen when its sound is due, not a frame later.
        """
        started = time.perf_counter()
        fb = self.host.framebuffer()
        if self.target is None or self.target.size != fb.size:
            if self.target is not None:
                self.target.release()
            self.target = OffscreenTarget(self.host.ctx, fb.size, samples=self.samples)
        pose = perf.pose(time_s + self.lead_s)
        self.renderer.draw([self.static, band_scene(pose)], self.host.state.camera, self.target.fbo)
        self.host.ctx.copy_framebuffer(fb, self.target.fbo)
        self.host.ctx.finish()
        cost = time.perf_counter() - started
        self.lead_s = min(0.1, 0.8 * self.lead_s + 0.2 * cost)
        self._fps_frames += 1
        now = time.perf_counter()
        if now - self._fps_since >= 1.0:
            self.fps = self._fps_frames / (now - self._fps_since)
            self._fps_frames = 0
            self._fps_since = now
        self.host.present(self.fps if self.fps else None)

    def close(self) -> None:
        if self.target is not None:
            self.target.release()
        self.renderer.release()
        self.host.close()
