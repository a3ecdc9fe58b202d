"""The heads-up display is drawn over the frame, at the top-left, and nowhere else."""

from __future__ import annotations

from typing import Any

import numpy as np

from virja.render.camera import PRESETS
from virja.render.hosts import OffscreenTarget
from virja.render.hud import MARGIN_PX, HudOverlay, text_image
from virja.render.renderer import Renderer
from virja.render.scene import static_scene


def test_text_image_is_light_text_on_a_dark_box() -> None:
    img = text_image("132 bpm   bar 5.3   F7", 30)
    assert img.shape[0] == 30 and img.shape[1] > 100 and img.shape[2] == 4
    assert img[15, 5:-5, 3].min() > 0  # the box is translucent, not transparent
    assert img[..., 0].max() > 200  # the letters are bright


def test_overlay_draws_top_left_only(gl_ctx: Any) -> None:
    size = (320, 180)
    renderer = Renderer(gl_ctx)
    target = OffscreenTarget(gl_ctx, size, samples=1)
    renderer.draw([static_scene()], PRESETS["front"], target.fbo)
    plain = target.read_rgb().astype(int)
    hud = HudOverlay(gl_ctx)
    renderer.draw([static_scene()], PRESETS["front"], target.fbo)
    hud.draw(target.fbo, "120 bpm   bar 1.1   F7")
    assert gl_ctx.error == "GL_NO_ERROR"
    over = target.read_rgb().astype(int)
    changed = np.argwhere(np.abs(over - plain).sum(axis=2) > 12)
    assert changed.size
    (y0, x0), (y1, x1) = changed.min(axis=0), changed.max(axis=0)
    assert y0 >= MARGIN_PX - 1 and x0 >= MARGIN_PX - 1  # from the margin, top row first
    assert y1 < MARGIN_PX + 20 and x1 < size[0] - 20  # one line high, within the frame
    assert over[y0 : y1 + 1, x0 : x1 + 1].max() > 150  # light letters
    hud.draw(target.fbo, "")  # nothing to say: nothing drawn
    hud.release()
    target.release()
    renderer.release()
