"""Where frames go: an offscreen EGL target (servers, CI, video) or a glfw window.

Both hosts give the renderer a framebuffer; the window also turns mouse and
keys into camera moves.  Rendering never depends on which host is used, so a
frame drawn headless is the frame the window shows.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import moderngl
import numpy as np
from numpy.typing import NDArray

from virja.errors import NotAvailableError
from virja.render.camera import PRESETS, Camera

log = logging.getLogger(__name__)


def create_headless_context() -> moderngl.Context:
    """A standalone OpenGL 3.3 context through EGL (Mesa llvmpipe without a GPU)."""
    try:
        return moderngl.create_standalone_context(backend="egl", require=330)  # type: ignore[arg-type]
    except Exception as exc:  # moderngl raises plain Exception subclasses from the loader
        raise NotAvailableError(
            "no headless OpenGL: EGL could not create a context "
            f"({exc}); install Mesa's EGL (apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)"
        ) from exc


def parking_framebuffer(ctx: moderngl.Context) -> moderngl.Framebuffer:
    """A 1x1 framebuffer kept for the context's life, bound while others are deleted."""
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    ctx.extra = extra
    if "virja_parking" not in extra:
        extra["virja_parking"] = ctx.simple_framebuffer((1, 1))
    fb: moderngl.Framebuffer = extra["virja_parking"]
    return fb


class OffscreenTarget:
    """A multisampled framebuffer resolved into a plain one for readback."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int = 4) -> None:
        w, h = size
        if w <= 0 or h <= 0 or w > 8192 or h > 8192:
            raise ValueError(f"frame size must be 1..8192 each way, got {w}x{h}")
        self.ctx = ctx
        self.size = (w, h)
        samples = min(samples, ctx.max_samples)
        self.samples = samples
        self.resolved = ctx.framebuffer(
            color_attachments=[ctx.renderbuffer((w, h))],
            depth_attachment=ctx.depth_renderbuffer((w, h)),
        )
        if samples > 1:
            self.fbo = ctx.framebuffer(
                color_attachments=[ctx.renderbuffer((w, h), samples=samples)],
                depth_attachment=ctx.depth_renderbuffer((w, h), samples=samples),
            )
        else:
            self.fbo = self.resolved

    def read_rgb(self) -> NDArray[np.uint8]:
        """The frame as (height, width, 3) uint8, top row first."""
        if self.fbo is not self.resolved:
            self.ctx.copy_framebuffer(self.resolved, self.fbo)
        w, h = self.size
        data = self.resolved.read(components=3, alignment=1)
        return np.frombuffer(data, dtype=np.uint8).reshape(h, w, 3)[::-1]

    def read_raw_rgb(self) -> bytes:
        """The frame as packed RGB bytes, bottom row first (as GL stores it): no copies
        beyond the read itself; the video writer flips it on the encoder's side."""
        if self.fbo is not self.resolved:
            self.ctx.copy_framebuffer(self.resolved, self.fbo)
        data: bytes = self.resolved.read(components=3, alignment=1)
        return data

    def finish(self) -> None:
        """Wait for the GPU (llvmpipe) to finish the frame, without reading it back."""
        if self.fbo is not self.resolved:
            self.ctx.copy_framebuffer(self.resolved, self.fbo)
        self.ctx.finish()

    def release(self) -> None:
        # Deleting the bound framebuffer leaves GL pointing at nothing, and the next
        # framebuffer made fails with GL_INVALID_OPERATION: bind a parked 1x1 one first.
        parking_framebuffer(self.ctx).use()
        for fb in {id(self.fbo): self.fbo, id(self.resolved): self.resolved}.values():
            for att in fb.color_attachments:
                att.release()
            if fb.depth_attachment is not None:
                fb.depth_attachment.release()
            fb.release()


@dataclass
class WindowState:
    camera: Camera = field(default_factory=lambda: PRESETS["front"])
    dragging: bool = False
    last_cursor: tuple[float, float] = (0.0, 0.0)
    screenshot_requested: bool = False
    fullscreen: bool = False
    hud: bool = False  # the heads-up display (tempo, bar.beat, chord), key H
    windowed_rect: tuple[int, int, int, int] = (100, 100, 1280, 720)


class WindowHost:
    """A resizable glfw window: drag to orbit, scroll to zoom, keys for the rest.

    Keys: 1-4 camera presets (front, drums, bass, top), H heads-up display, F fullscreen, S
    screenshot (PNG in the working folder), Esc or Q close.
    """

    def __init__(
        self, size: tuple[int, int] = (1280, 720), title: str = "virja", *, vsync: bool = True
    ) -> None:
        import glfw

        if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            raise NotAvailableError(
                "no display for a window (DISPLAY is not set); use --headless, or run under Xvfb"
            )
        if not glfw.init():
            raise NotAvailableError("glfw could not initialise (no usable display)")
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
        glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
        glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
        glfw.window_hint(glfw.SAMPLES, 0)  # we draw offscreen (multisampled) and blit
        self.glfw = glfw
        self.title = title
        self.window = glfw.create_window(size[0], size[1], title, None, None)
        if not self.window:
            glfw.terminate()
            raise NotAvailableError("glfw could not open an OpenGL 3.3 window")
        glfw.make_context_current(self.window)
        # vsync where the display has it (a swap then waits for the refresh); Xvfb and
        # llvmpipe have none and return at once: the frame loop paces itself then
        glfw.swap_interval(1 if vsync else 0)
        # GLX (glcontext can attach to a current context only through GLX).  Mesa
        # refuses a GLX context in a process that already made an EGL one (X
        # BadAccess), so a process draws either to a window or headless, not both.
        self.ctx = moderngl.create_context(require=330)
        self._screen: moderngl.Framebuffer | None = None
        self._screen_size = (0, 0)
        self.last_swap_s = 0.0  # how long the last swap waited (vsync: up to a refresh)
        self.state = WindowState()
        self.on_screenshot: Callable[[NDArray[np.uint8]], None] | None = None
        glfw.set_key_callback(self.window, self._on_key)
        glfw.set_mouse_button_callback(self.window, self._on_button)
        glfw.set_cursor_pos_callback(self.window, self._on_cursor)
        glfw.set_scroll_callback(self.window, self._on_scroll)

    # --- input -------------------------------------------------------------
    def _on_key(self, window: object, key: int, scancode: int, action: int, mods: int) -> None:
        g = self.glfw
        if action != g.PRESS:
            return
        presets = {g.KEY_1: "front", g.KEY_2: "drums", g.KEY_3: "bass", g.KEY_4: "top"}
        if key in (g.KEY_ESCAPE, g.KEY_Q):
            g.set_window_should_close(self.window, True)
        elif key in presets:
            self.state.camera = PRESETS[presets[key]]
        elif key == g.KEY_S:
            self.state.screenshot_requested = True
        elif key == g.KEY_H:
            self.state.hud = not self.state.hud
        elif key == g.KEY_F:
            self.toggle_fullscreen()

    def _on_button(self, window: object, button: int, action: int, mods: int) -> None:
        g = self.glfw
        if button == g.MOUSE_BUTTON_LEFT:
            self.state.dragging = action == g.PRESS
            self.state.last_cursor = g.get_cursor_pos(self.window)

    def _on_cursor(self, window: object, x: float, y: float) -> None:
        if self.state.dragging:
            lx, ly = self.state.last_cursor
            self.state.camera = self.state.camera.orbit(-(x - lx) * 0.3, (y - ly) * 0.3)
        self.state.last_cursor = (x, y)

    def _on_scroll(self, window: object, dx: float, dy: float) -> None:
        self.state.camera = self.state.camera.zoom(0.9**dy)

    def toggle_fullscreen(self) -> None:
        g = self.glfw
        if not self.state.fullscreen:
            x, y = g.get_window_pos(self.window)
            w, h = g.get_window_size(self.window)
            self.state.windowed_rect = (x, y, w, h)
            monitor = g.get_primary_monitor()
            mode = g.get_video_mode(monitor) if monitor else None
            if monitor and mode:
                g.set_window_monitor(
                    self.window, monitor, 0, 0, mode.size.width, mode.size.height, mode.refresh_rate
                )
                self.state.fullscreen = True
        else:
            x, y, w, h = self.state.windowed_rect
            g.set_window_monitor(self.window, None, x, y, w, h, 0)
            self.state.fullscreen = False

    # --- frames ------------------------------------------------------------
    @property
    def should_close(self) -> bool:
        return bool(self.glfw.window_should_close(self.window))

    def framebuffer(self) -> moderngl.Framebuffer:
        """The window's own framebuffer (GL name 0) at the window's current size.

        Always framebuffer 0: ``detect_framebuffer()`` without a name returns
        whatever is bound, which after the first frame is the offscreen target
        (the bug that froze the window after one frame).
        """
        size = tuple(self.glfw.get_framebuffer_size(self.window))
        if self._screen is None or size != self._screen_size:
            w, h = max(1, size[0]), max(1, size[1])
            self.ctx.screen.use()
            self.ctx.viewport = (0, 0, w, h)  # framebuffer 0 reports the viewport as its size
            self._screen = self.ctx.detect_framebuffer(0)
            self._screen_size = (size[0], size[1])
        return self._screen

    def read_window_rgb(self) -> NDArray[np.uint8]:
        """The window's own pixels (its back buffer as last drawn), (h, w, 3), top row first."""
        fb = self.framebuffer()
        w, h = fb.size
        data = fb.read(components=3, alignment=1)
        # moderngl selects GL_COLOR_ATTACHMENT0 to read from, which framebuffer 0 does
        # not have: GL_INVALID_OPERATION, and the read buffer stays GL_BACK (the one
        # wanted).  Take that error off the queue so it is not blamed on the next frame.
        _ = self.ctx.error
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1]

    def present(self, fps: float | None = None) -> None:
        if self.state.screenshot_requested and self.on_screenshot is not None:
            self.state.screenshot_requested = False
            self.on_screenshot(self.read_window_rgb())
        started = time.perf_counter()
        self.glfw.swap_buffers(self.window)
        self.last_swap_s = time.perf_counter() - started
        self.glfw.poll_events()
        if fps is not None:
            self.glfw.set_window_title(self.window, f"{self.title} — {fps:.0f} fps")

    def refresh_rate(self) -> float | None:
        """The primary monitor's refresh rate in Hz, when the display reports one."""
        monitor = self.glfw.get_primary_monitor()
        mode = self.glfw.get_video_mode(monitor) if monitor else None
        return float(mode.refresh_rate) if mode and mode.refresh_rate > 0 else None

    def close(self) -> None:
        self.glfw.destroy_window(self.window)
        self.glfw.terminate()
