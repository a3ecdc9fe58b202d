"""Offline rendering with a third figure on stage: a dancer whose pose is given per frame.

Same replay timer and outputs as :mod:`virja.render.offline` (frames at exactly
``t0 + i / fps``; a folder of PNGs, numbered PNGs beside ``NAME.png``, or a
video with an audio track), with one more :class:`~virja.motion.pose.FigurePose`
drawn each frame by :func:`~virja.render.scene.figure_scene`.  The dancer's
pose comes from a callable (session time -> FigurePose), so this module knows
nothing of how the dance was made (``virja.dance.stage.DancerTrack.pose``).

:func:`render_with_dancer` draws the band and the dancer;
:func:`render_dancer_alone` draws only the stage floor and the dancer.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path

from virja.errors import ConfigError
from virja.motion.pose import FigurePose
from virja.render.camera import Camera
from virja.render.hosts import OffscreenTarget, create_headless_context
from virja.render.images import write_png
from virja.render.meshes import box_transforms
from virja.render.offline import OutputSpec, Progress, RenderResult
from virja.render.renderer import DrawList, Renderer
from virja.render.scene import FLOOR, band_scene, figure_scene, static_scene
from virja.render.video import VideoWriter
from virja.session import Performance, RevealFeeder, frame_times

DancerPose = Callable[[float], FigurePose]


def floor_scene(size_m: tuple[float, float] = (6.0, 4.0)) -> DrawList:
    """Just the stage floor (for a dancer alone)."""
    dl = DrawList()
    w, d = size_m
    dl.add("box", box_transforms([[0, -0.05, 0]], [[w, 0.1, d]]), FLOOR)
    return dl.freeze()


def _render(
    times: list[float],
    scene_at: Callable[[float], list[DrawList]],
    *,
    fps: float,
    size: tuple[int, int],
    out: OutputSpec,
    camera: Camera,
    audio: Path | None,
    audio_offset_s: float,
    samples: int,
    progress: Progress | None,
) -> tuple[float, list[Path]]:
    if out.kind == "video" and (size[0] % 2 or size[1] % 2):
        raise ConfigError(f"video needs an even frame size, got {size[0]}x{size[1]}")
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=samples)
    writer: VideoWriter | None = None
    outputs: list[Path] = []
    if out.kind == "video":
        out.path.parent.mkdir(parents=True, exist_ok=True)
        writer = VideoWriter(out.path, size, fps, audio=audio, audio_offset_s=audio_offset_s)
        outputs.append(out.path)
    elif out.kind == "folder":
        out.path.mkdir(parents=True, exist_ok=True)
    else:
        out.path.parent.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    try:
        for i, t in enumerate(times):
            renderer.draw(scene_at(t), camera, target.fbo)
            frame = target.read_rgb()
            if writer is not None:
                writer.write(frame)
            else:
                path = out.path if out.kind == "png" and len(times) == 1 else out.frame_path(i)
                write_png(path, frame)
                outputs.append(path)
            if progress is not None:
                progress(i + 1, len(times), time.perf_counter() - started)
    finally:
        if writer is not None:
            writer.close()
        target.release()
        renderer.release()
        ctx.release()
    return time.perf_counter() - started, outputs


def render_with_dancer(
    perf: Performance,
    feeder: RevealFeeder,
    *,
    dancer: DancerPose,
    t0_s: float,
    t1_s: float,
    fps: float,
    size: tuple[int, int],
    out: OutputSpec,
    camera: Camera,
    audio: Path | None = None,
    audio_offset_s: float = 0.0,
    samples: int = 1,
    progress: Progress | None = None,
) -> RenderResult:
    """As :func:`virja.render.offline.render_offline`, with ``dancer(t)`` drawn each frame."""
    times = list(frame_times(t0_s, t1_s, fps))
    static = static_scene()

    def scene_at(t: float) -> list[DrawList]:
        feeder.until(perf, t)
        perf.advance(t)
        return [static, band_scene(perf.pose(t)), figure_scene(dancer(t))]

    seconds, outputs = _render(
        times,
        scene_at,
        fps=fps,
        size=size,
        out=out,
        camera=camera,
        audio=audio,
        audio_offset_s=audio_offset_s,
        samples=samples,
        progress=progress,
    )
    feeder.until(perf, math.inf)
    perf.finish()
    return RenderResult(len(times), seconds, t0_s, outputs)


def render_dancer_alone(
    dancer: DancerPose,
    *,
    t0_s: float,
    t1_s: float,
    fps: float,
    size: tuple[int, int],
    out: OutputSpec,
    camera: Camera,
    audio: Path | None = None,
    audio_offset_s: float = 0.0,
    samples: int = 1,
    progress: Progress | None = None,
) -> RenderResult:
    """The stage floor and ``dancer(t)`` from ``t0_s`` to ``t1_s``; ``audio`` starts at
    ``audio_offset_s`` into the video."""
    times = list(frame_times(t0_s, t1_s, fps))
    floor = floor_scene()
    seconds, outputs = _render(
        times,
        lambda t: [floor, figure_scene(dancer(t))],
        fps=fps,
        size=size,
        out=out,
        camera=camera,
        audio=audio,
        audio_offset_s=audio_offset_s,
        samples=samples,
        progress=progress,
    )
    return RenderResult(len(times), seconds, t0_s, outputs)
