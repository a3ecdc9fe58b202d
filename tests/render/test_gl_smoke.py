"""GL smoke tests through headless EGL: the program compiles, primitives land where projected."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from virja.render.camera import Camera, project
from virja.render.hosts import OffscreenTarget
from virja.render.images import decode_png_rgb, encode_png
from virja.render.meshes import box_transforms, sphere_transforms
from virja.render.renderer import BACKGROUND, DrawList, Renderer
from virja.render.shaders import ShaderError, load_program


def test_sphere_is_drawn_where_the_camera_projects_it(gl_ctx: Any) -> None:
    assert gl_ctx.error == "GL_NO_ERROR"
    r = Renderer(gl_ctx)
    target = OffscreenTarget(gl_ctx, (96, 64), samples=1)
    cam = Camera(target=(0.0, 1.0, 0.0), pitch_deg=0.0, distance_m=3.0)
    dl = DrawList()
    dl.add("sphere", sphere_transforms([[0.4, 1.2, 0.0]], 0.15), (0.9, 0.1, 0.1, 0.0))
    r.draw(dl, cam, target.fbo)
    img = target.read_rgb()
    assert gl_ctx.error == "GL_NO_ERROR"
    ((x, y),) = (
        project(cam.view_proj(96 / 64), np.array([[0.4, 1.2, 0.0]]), (96, 64)).round().astype(int)
    )
    red = img[y, x]
    assert red[0] > 120 and int(red[0]) > int(red[1]) + 30, red
    bg = np.round(np.array(BACKGROUND) * 255)  # the clear colour is written as is
    corner = img[2, 2].astype(float)
    assert np.all(np.abs(corner - bg) <= 3), corner  # background, not geometry
    target.release()
    r.release()


def test_same_draw_list_gives_the_same_pixels(gl_ctx: Any) -> None:
    r = Renderer(gl_ctx)
    target = OffscreenTarget(gl_ctx, (64, 48), samples=4)
    dl = DrawList()
    dl.add("box", box_transforms([[0, 0.5, 0]], [[1, 1, 1]]), (0.2, 0.6, 0.9, 0.3))
    frames = []
    for _ in range(2):
        r.draw(dl, Camera(), target.fbo)
        frames.append(target.read_rgb().copy())
    assert np.array_equal(frames[0], frames[1])
    assert gl_ctx.error == "GL_NO_ERROR"
    target.release()
    r.release()


def test_many_instances_grow_the_buffer(gl_ctx: Any) -> None:
    r = Renderer(gl_ctx, initial_instances=4)
    target = OffscreenTarget(gl_ctx, (32, 32), samples=1)
    dl = DrawList()
    centers = np.c_[np.linspace(-1, 1, 50), np.full(50, 1.0), np.zeros(50)]
    dl.add("sphere", sphere_transforms(centers, 0.02), (1, 1, 1, 0))
    r.draw(dl, Camera(), target.fbo)
    assert dl.count() == 50
    assert gl_ctx.error == "GL_NO_ERROR"


def test_shader_compile_error_names_the_file_and_line(gl_ctx: Any, tmp_path: Any) -> None:
    (tmp_path / "broken.glsl").write_text(
        "#if defined VERTEX_SHADER\nvoid main() { gl_Position = vec4(0.0); }\n"
        "#elif defined FRAGMENT_SHADER\nout vec4 c;\nvoid main() { c = undefined_thing; }\n#endif\n"
    )
    with pytest.raises(ShaderError, match=r"(?s)broken\.glsl.*broken\.glsl:5"):
        load_program(gl_ctx, "broken", folder=tmp_path)


def test_png_round_trip() -> None:
    img = (np.arange(5 * 7 * 3) % 256).astype(np.uint8).reshape(5, 7, 3)
    assert np.array_equal(decode_png_rgb(encode_png(img)), img)
