"""Offline rendering: the replay timer steps exactly 1/fps and frames go to files.

The loop is the live loop with a different clock: at each frame time ``t`` the
events known by ``t`` are fed, started motions are committed, and the pose at
``t`` is drawn.  Output is a folder of PNG frames, numbered PNGs beside a
``NAME.png``, or a video (``.mp4``, ``.mkv``, ``.mov``) through ffmpeg.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from virja.errors import ConfigError
from virja.render.camera import Camera
from virja.render.hosts import OffscreenTarget, create_headless_context
from virja.render.images import write_png
from virja.render.renderer import Renderer
from virja.render.scene import band_scene, static_scene
from virja.render.video import VideoWriter
from virja.session import Performance, RevealFeeder, frame_times

log = logging.getLogger(__name__)

VIDEO_SUFFIXES = frozenset({".mp4", ".mkv", ".mov"})


def parse_size(text: str) -> tuple[int, int]:
    """ "1280x720" -> (1280, 720)."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError as exc:
        raise ConfigError(f"size must look like 1280x720, got {text!r}") from exc
    if not (16 <= w <= 7680 and 16 <= h <= 4320):
        raise ConfigError(f"size {w}x{h} out of range (16x16 to 7680x4320)")
    return w, h


@dataclass(frozen=True)
class OutputSpec:
    kind: str  # "video", "folder", "png"
    path: Path

    @classmethod
    def from_path(cls, out: str | Path) -> OutputSpec:
        p = Path(out)
        suffix = p.suffix.lower()
        if suffix in VIDEO_SUFFIXES:
            return cls("video", p)
        if suffix == ".png":
            return cls("png", p)
        if suffix:
            raise ConfigError(
                f"--out {p}: unknown output type {suffix!r}; use a folder, a .png or a video "
                f"({', '.join(sorted(VIDEO_SUFFIXES))})"
            )
        return cls("folder", p)

    def frame_path(self, index: int) -> Path:
        if self.kind == "folder":
            return self.path / f"frame_{index:05d}.png"
        return self.path.with_name(f"{self.path.stem}_{index:05d}.png")


Progress = Callable[[int, int, float], None]


@dataclass
class RenderResult:
    frames: int
    seconds: float
    first_frame_s: float
    outputs: list[Path]


def render_offline(
    perf: Performance,
    feeder: RevealFeeder,
    *,
    t0_s: float,
    t1_s: float,
    fps: float,
    size: tuple[int, int],
    out: OutputSpec,
    camera: Camera,
    audio: Path | None = None,
    audio_offset_s: float = 0.0,
    samples: int = 4,
    progress: Progress | None = None,
) -> RenderResult:
    """Drive ``perf`` from t0 to t1 at ``fps`` and write each frame to ``out``."""
    times = list(frame_times(t0_s, t1_s, fps))
    if out.kind == "video" and (size[0] % 2 or size[1] % 2):
        raise ConfigError(f"video needs an even frame size, got {size[0]}x{size[1]}")
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=samples)
    static = static_scene()
    writer: VideoWriter | None = None
    outputs: list[Path] = []
    if out.kind == "video":
        out.path.parent.mkdir(parents=True, exist_ok=True)
        writer = VideoWriter(
            out.path, size, fps, audio=audio, audio_offset_s=audio_offset_s, bottom_up=True
        )
        outputs.append(out.path)
    elif out.kind == "folder":
        out.path.mkdir(parents=True, exist_ok=True)
    else:
        out.path.parent.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    try:
        for i, t in enumerate(times):
            feeder.until(perf, t)
            perf.advance(t)
            renderer.draw([static, band_scene(perf.pose(t))], camera, target.fbo)
            if writer is not None:
                writer.write_raw(target.read_raw_rgb())
            else:
                frame = target.read_rgb()
                path = out.path if out.kind == "png" and len(times) == 1 else out.frame_path(i)
                write_png(path, frame)
                outputs.append(path)
            if progress is not None:
                progress(i + 1, len(times), time.perf_counter() - started)
        feeder.until(perf, math.inf)
        perf.finish()
    finally:
        if writer is not None:
            writer.close()
        target.release()
        renderer.release()
        ctx.release()
    return RenderResult(len(times), time.perf_counter() - started, t0_s, outputs)
