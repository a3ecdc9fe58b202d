"""Live drawing in a window: one pose of the band per call, on the window's thread.

The window of ``serve``, ``replay`` and ``jam`` (driven from the viewer process,
:mod:`virja.live.viewer`): a glfw window, the same
:class:`~virja.render.renderer.Renderer` as offline, drawn offscreen and copied
to the window's own framebuffer, then swapped.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from virja.motion.pose import BandPose
from virja.render.hosts import OffscreenTarget, WindowHost
from virja.render.hud import HudOverlay
from virja.render.images import write_png
from virja.render.renderer import DrawList, Renderer
from virja.render.scene import band_scene, static_scene

log = logging.getLogger(__name__)

VSYNC_SWAP_FRACTION = 0.3  # swaps that wait this much of a refresh on average: vsync is on


class LiveView:
    """A window showing the band: :meth:`show` draws one pose and presents it."""

    def __init__(
        self,
        size: tuple[int, int] = (1280, 720),
        title: str = "virja",
        samples: int = 1,
        *,
        vsync: bool = True,
        hud: bool = False,
    ) -> None:
        self.host = WindowHost(size, title, vsync=vsync)
        self.host.state.hud = hud
        self.hud_text = ""  # set before each frame by the frame loop (set_hud)
        self._overlay: HudOverlay | None = None
        self.samples = samples
        self.target: OffscreenTarget | None = None
        self.renderer = Renderer(self.host.ctx)
        self.static: DrawList = static_scene()
        self.host.on_screenshot = self._save_screenshot
        self._fps_frames = 0
        self._fps_since = time.perf_counter()
        self.fps = 0.0
        self._swap_s: list[float] = []
        self.frames = 0

    def _save_screenshot(self, rgb: object) -> None:
        path = Path(f"virja-{time.strftime('%Y%m%d-%H%M%S')}.png")
        assert isinstance(rgb, np.ndarray)
        write_png(path, rgb)
        log.warning("screenshot saved to %s", path)

    @property
    def closed(self) -> bool:
        return self.host.should_close

    def set_hud(self, text: str) -> None:
        """The heads-up display's line for the next frame (shown while H is on)."""
        self.hud_text = text

    def refresh_s(self) -> float | None:
        """The display's refresh period if swaps wait for it (vsync), else None."""
        if len(self._swap_s) < 10:
            return None
        swaps = sorted(self._swap_s)
        median = swaps[len(swaps) // 2]
        rate = self.host.refresh_rate()
        if rate is None:  # no refresh rate (Xvfb): no display to wait for
            return None
        period = 1.0 / rate
        return period if median >= VSYNC_SWAP_FRACTION * period else None

    def show(self, pose: BandPose, extra: Sequence[DrawList] = ()) -> None:
        """Draw ``pose`` (and ``extra`` layers) offscreen, copy it to the window, swap."""
        self.show_frame(pose, band_scene(pose), extra)

    def show_frame(self, pose: BandPose, scene: DrawList, extra: Sequence[DrawList] = ()) -> None:
        """:meth:`show` with the pose's instances already built (``scene``: the frame
        loop's chunk, :class:`virja.render.chunks.FrameChunks`)."""
        fb = self.host.framebuffer()
        if self.target is None or self.target.size != fb.size:
            if self.target is not None:
                self.target.release()
            self.target = OffscreenTarget(self.host.ctx, fb.size, samples=self.samples)
        layers = [self.static, scene, *extra]
        self.renderer.draw(layers, self.host.state.camera, self.target.fbo)
        if self.host.state.hud and self.hud_text:
            if self._overlay is None:
                self._overlay = HudOverlay(self.host.ctx)
            self._overlay.draw(self.target.fbo, self.hud_text)
        self.host.ctx.copy_framebuffer(fb, self.target.fbo)
        self.host.ctx.finish()  # the drawing is done: what the swap waits for is the display
        self._fps_frames += 1
        now = time.perf_counter()
        if now - self._fps_since >= 1.0:
            self.fps = self._fps_frames / (now - self._fps_since)
            self._fps_frames = 0
            self._fps_since = now
        self.host.present(self.fps if self.fps else None)
        if len(self._swap_s) < 30:
            self._swap_s.append(self.host.last_swap_s)
        self.frames += 1

    def poll(self) -> None:
        """Handle window events (keys, mouse, close) between frames."""
        self.host.glfw.poll_events()

    def close(self) -> None:
        if self.target is not None:
            self.target.release()
        self.renderer.release()
        self.host.close()
