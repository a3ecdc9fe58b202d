"""Offline rendering with a third figure on stage: a dancer whose pose is given per frame.

Same replay timer and outputs as :mod:`virja.render.offline` (frames at exactly
``t0 + i / fps``; a folder of PNGs, numbered PNGs beside ``NAME.png``, or a
video with an audio track), with one more :class:`~virja.motion.pose.FigurePose`
drawn each frame by :func:`~virja.render.scene.figure_scene`.  The dancer's
pose comes from a callable (session time -> FigurePose), so this module knows
nothing of how the dance was made (``virja.dance.stage.DancerTrack.pose``).

:func:`render_dancer_alone` draws only the stage floor and the dancer; with
the band, ``virja render --dancer`` passes the dancer to
:func:`virja.render.offline.render_offline` as its ``extra`` layer.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from virja.motion.pose import FigurePose
from virja.render.camera import Camera
from virja.render.offline import OutputSpec, Progress, RenderResult, render_frames
from virja.render.renderer import DrawList
from virja.render.scene import add_floor, figure_scene
from virja.session import frame_times

DancerPose = Callable[[float], FigurePose]


def floor_scene(size_m: tuple[float, float] = (6.0, 4.0)) -> DrawList:
    """Just the stage floor (for a dancer alone)."""
    dl = DrawList()
    add_floor(dl, size_m)
    return dl.freeze()


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
    seconds, outputs = render_frames(
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
