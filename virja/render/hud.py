"""The heads-up display: one line of text (tempo, bar.beat, chord) drawn over a frame.

The text is set in an image by Pillow (its bundled font: no system font needed),
uploaded as a texture only when it changes (a few times a second at most), and
drawn as one alpha-blended quad at the top-left corner by ``shaders/overlay.glsl``.
Used by offline renders (``--hud``) and the live window (``--hud``, key ``H``).
"""

from __future__ import annotations

import moderngl
import numpy as np
from numpy.typing import NDArray

from virja.render.shaders import load_program

MARGIN_PX = 12


def text_image(text: str, height_px: int) -> NDArray[np.uint8]:
    """``text`` in white on a translucent dark box: (h, w, 4) premultiplied RGBA, top row first."""
    from PIL import Image, ImageDraw, ImageFont

    font = ImageFont.load_default(size=max(8, int(height_px * 0.62)))
    left, top, right, bottom = font.getbbox(text or " ")
    pad = max(4, height_px // 5)
    w, h = int(right - left) + 2 * pad, height_px
    img = Image.new("RGBA", (w, h), (0, 0, 0, 0))
    draw = ImageDraw.Draw(img)
    draw.rounded_rectangle((0, 0, w - 1, h - 1), radius=pad, fill=(10, 12, 18, 150))
    draw.text(
        (pad - left, (h - (bottom - top)) // 2 - top), text, font=font, fill=(240, 240, 230, 255)
    )
    rgba = np.asarray(img, dtype=np.float32)
    rgba[..., :3] *= rgba[..., 3:4] / 255.0  # premultiplied, for the blend below
    return rgba.round().astype(np.uint8)


class HudOverlay:
    """Draws a line of text over whatever the framebuffer holds."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.prog = load_program(ctx, "overlay")
        corners = np.array([0, 0, 1, 0, 0, 1, 1, 1], dtype="f4")
        self.vbo = ctx.buffer(corners.tobytes())
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "2f", "in_corner")])
        self.texture: moderngl.Texture | None = None
        self._key: tuple[str, int] | None = None

    def draw(self, fbo: moderngl.Framebuffer, text: str) -> None:
        """Draw ``text`` at the top-left of ``fbo`` (nothing for an empty text)."""
        if not text:
            return
        w, h = fbo.size
        line_px = max(14, h // 24)
        if self._key != (text, line_px):
            img = text_image(text, line_px)
            if self.texture is not None:
                self.texture.release()
            # texture row 0 is the image's top row, and the quad's v = 0 is its top edge
            self.texture = self.ctx.texture((img.shape[1], img.shape[0]), 4, img.tobytes())
            self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._key = (text, line_px)
        assert self.texture is not None
        tw, th = self.texture.size
        fbo.use()
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = (moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)
        self.prog["u_rect"].value = (MARGIN_PX, MARGIN_PX, tw, th)  # type: ignore[union-attr]
        self.prog["u_viewport"].value = (w, h)  # type: ignore[union-attr]
        self.texture.use(0)
        self.prog["u_image"].value = 0  # type: ignore[union-attr]
        self.vao.render(moderngl.TRIANGLE_STRIP)
        self.ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        if self.texture is not None:
            self.texture.release()
        self.vao.release()
        self.vbo.release()
        self.prog.release()
