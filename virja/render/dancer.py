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

from virja.motion.pose import FigurePose
from virja.render.offline import RenderResult, RenderSettings, render_frames
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
    dancer: DancerPose, span: tuple[float, float], settings: RenderSettings
) -> RenderResult:
    """The stage floor and ``dancer(t)`` over ``span`` (seconds, both ends drawn); the
    settings' audio starts ``audio_offset_s`` into the video."""
    t0_s, t1_s = span
    times = list(frame_times(t0_s, t1_s, settings.fps))
    floor = floor_scene()
    seconds, outputs = render_frames(times, lambda t: [floor, figure_scene(dancer(t))], settings)
    return RenderResult(len(times), seconds, t0_s, outputs)
