"""The pipelined frame loop (next scene built while the frame rasterises, frames
read after) writes each frame as drawn alone: no frame shows its neighbour's scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from virja.render.camera import PRESETS
from virja.render.images import decode_png_rgb
from virja.render.meshes import sphere_transforms
from virja.render.offline import OutputSpec, RenderSettings, render_frames
from virja.render.renderer import DrawList
from virja.render.scene import static_scene

STATIC = static_scene()


def scene_at(t: float) -> list[DrawList]:
    """A ball that moves across the stage with the time (each frame different)."""
    dl = DrawList()
    dl.add("sphere", sphere_transforms([[-1.0 + 0.5 * t, 1.0, 0.5]], 0.15), (1.0, 0.2, 0.2, 0.3))
    return [STATIC, dl]


def test_each_frame_is_its_own_scene(tmp_path: Path) -> None:
    times = [i * 0.4 for i in range(5)]
    calls: list[float] = []

    def logged(t: float) -> list[DrawList]:
        calls.append(t)
        return scene_at(t)

    common = {"fps": 2.5, "size": (96, 54), "camera": PRESETS["front"]}
    render_frames(times, logged, RenderSettings(OutputSpec("folder", tmp_path / "all"), **common))  # type: ignore[arg-type]
    assert calls == times  # every scene built once, in order
    frames = [decode_png_rgb(p.read_bytes()) for p in sorted((tmp_path / "all").glob("*.png"))]
    assert len(frames) == len(times)
    for i, t in enumerate(times):
        one = tmp_path / f"one_{i}.png"
        render_frames([t], scene_at, RenderSettings(OutputSpec("png", one), **common))  # type: ignore[arg-type]
        assert np.array_equal(frames[i], decode_png_rgb(one.read_bytes())), f"frame {i}"
    assert not np.array_equal(frames[0], frames[1])  # the ball moved: a swap would show
