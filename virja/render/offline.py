"""Offline rendering: the replay timer steps exactly 1/fps and frames go to files.

A file or a recording is known whole, so by default the whole input is played
through the performance first (each event fed when it becomes known, each
motion committed when it starts: the same planner calls, the same plan and plan
log as live) and the band is then posed 30 frames at a time: every motion is
drawn knowing every note, as ``motion-report``, ``export`` and ``--bvh`` see it
(the drummer's hand leaves for a note as soon as it is known and free, not
only once its stroke has started).  With ``RenderSettings.as_live`` (``render
--as-live``) the loop is the live loop with a different clock instead: at each
frame time ``t`` the events known by ``t`` are fed, started motions are
committed, and the pose at ``t`` is drawn knowing only those (what the live
window shows).  Output is a folder of PNG frames, numbered PNGs beside a
``NAME.png``, or a video (``.mp4``, ``.mkv``, ``.mov``) through ffmpeg.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from virja.errors import ConfigError
from virja.render.camera import PRESETS, Camera
from virja.render.chunks import FrameChunks
from virja.render.glflush import flush
from virja.render.hosts import OffscreenTarget, create_headless_context
from virja.render.hud import HudOverlay
from virja.render.images import write_png
from virja.render.renderer import DrawList, Renderer
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
CameraAt = Callable[[float], Camera]  # a camera that moves (render.director.FollowCamera)
TextAt = Callable[[float], str]  # the heads-up display's line at a frame time


@dataclass(frozen=True)
class RenderSettings:
    """How frames are drawn and where they go: built once from a command's options
    (``render``, ``replay --out``, ``dance --render``, a batch's mp4).

    ``out``: the files; ``camera``: a preset or one that moves with the time;
    ``samples``: multisampling; ``hud``: draw the heads-up display; ``audio``: the
    sound track of a video, starting ``audio_offset_s`` into it; ``progress(done,
    total, elapsed_s)`` after each frame; ``as_live``: each frame drawn knowing only
    what the live window would know at its time (default: the whole input known).
    """

    out: OutputSpec
    size: tuple[int, int] = (1280, 720)
    fps: float = 30.0
    camera: Camera | CameraAt = field(default_factory=lambda: PRESETS["front"])
    samples: int = 1
    hud: bool = False
    audio: Path | None = None
    audio_offset_s: float = 0.0
    progress: Progress | None = None
    as_live: bool = False

    def with_audio(self, audio: Path | None, offset_s: float) -> RenderSettings:
        """The same settings with a sound track (made once the span is known)."""
        return replace(self, audio=audio, audio_offset_s=offset_s)


@dataclass
class RenderResult:
    frames: int
    seconds: float
    first_frame_s: float
    outputs: list[Path]


SceneAt = Callable[[float], list[DrawList]]


def render_frames(
    times: list[float],
    scene_at: SceneAt,
    settings: RenderSettings,
    *,
    hud: TextAt | None = None,
) -> tuple[float, list[Path]]:
    """Draw ``scene_at(t)`` for each frame time and write it to ``settings.out``
    (``hud(t)``: the heads-up display's line, when ``settings.hud``).

    The one frame loop of every offline render (band, band and dancer, dancer
    alone).  Returns the seconds it took and the files written.
    """
    out, size, fps = settings.out, settings.size, settings.fps
    camera, progress = settings.camera, settings.progress
    hud = hud if settings.hud else None
    if out.kind == "video" and (size[0] % 2 or size[1] % 2):
        raise ConfigError(f"video needs an even frame size, got {size[0]}x{size[1]}")
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=settings.samples)
    overlay = HudOverlay(ctx) if hud is not None else None
    writer: VideoWriter | None = None
    outputs: list[Path] = []
    folder = out.path if out.kind == "folder" else out.path.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(
            f"--out {out.path}: cannot make {folder}: {exc.strerror or exc}"
        ) from None
    if not os.access(folder, os.W_OK):
        raise ConfigError(f"--out {out.path}: the folder {folder} is not writable")
    if out.kind == "video":
        writer = VideoWriter(
            out.path,
            size,
            fps,
            audio=settings.audio,
            audio_offset_s=settings.audio_offset_s,
            bottom_up=True,
            queue_frames=3,
        )
        outputs.append(out.path)
    started = time.perf_counter()
    try:
        # Pipelined: frame i is drawn and flushed (llvmpipe's threads rasterise
        # it), then frame i+1's scene is built on this thread while they work,
        # and only then is frame i read back; the writer thread feeds ffmpeg.
        layers = scene_at(times[0]) if times else []
        for i, t in enumerate(times):
            cam = camera if isinstance(camera, Camera) else camera(t)
            renderer.draw(layers, cam, target.fbo)
            if overlay is not None and hud is not None:
                overlay.draw(target.fbo, hud(t))
            flush()  # the rasteriser starts; we build the next scene meanwhile
            if i + 1 < len(times):
                layers = scene_at(times[i + 1])
            if writer is not None:
                writer.write_raw(target.read_raw_rgb())  # GL row order; ffmpeg flips
            else:
                path = out.path if out.kind == "png" and len(times) == 1 else out.frame_path(i)
                write_png(path, target.read_rgb())
                outputs.append(path)
            if progress is not None:
                progress(i + 1, len(times), time.perf_counter() - started)
    except KeyboardInterrupt:
        if writer is not None:
            writer.abort()
            writer = None
            log.warning("interrupted: the unfinished video %s was removed", out.path)
        raise
    finally:
        if writer is not None:
            writer.close()
        target.release()
        if overlay is not None:
            overlay.release()
        renderer.release()
        ctx.release()
    return time.perf_counter() - started, outputs


def render_offline(
    perf: Performance,
    feeder: RevealFeeder,
    span: tuple[float, float],
    settings: RenderSettings,
    *,
    extra: SceneAt | None = None,
) -> RenderResult:
    """Drive ``perf`` over ``span`` (session seconds, both ends drawn) at
    ``settings.fps`` and write each frame to ``settings.out``.

    ``extra(t)`` adds instances to each frame (the dancer, for one).
    """
    t0_s, t1_s = span
    times = list(frame_times(t0_s, t1_s, settings.fps))
    static = static_scene()
    animator = perf.animator
    batched = hasattr(animator, "pose_batch")
    ahead = _Ahead(perf, feeder, times, CHUNK_FRAMES) if batched and settings.as_live else None
    whole = _Whole(perf, feeder, times, WHOLE_CHUNK_FRAMES) if batched and ahead is None else None

    def scene_at(t: float) -> list[DrawList]:
        if whole is not None:
            band = whole.scene(t)
        elif ahead is not None:
            band = ahead.scene(t)
        else:
            feeder.until(perf, t)
            perf.advance(t)
            band = band_scene(perf.pose(t))
        layers = [static, band]
        return layers if extra is None else layers + extra(t)

    try:
        seconds, outputs = render_frames(
            times, scene_at, settings, hud=lambda t: perf.hud.at(t).text()
        )
    finally:
        if ahead is not None:
            ahead.close()
    if ahead is not None:
        log.debug(
            "%d frames posed in %d chunks (%.1f frames a chunk)",
            ahead.chunks.frames,
            ahead.chunks.chunks,
            ahead.chunks.frames / max(ahead.chunks.chunks, 1),
        )
    feeder.until(perf, math.inf)
    perf.finish()
    return RenderResult(len(times), seconds, t0_s, outputs)


CHUNK_FRAMES = 30  # --as-live: the timer (and the poses) run up to this many frames ahead
# the whole input known: frames posed at a time (4 s at 30 fps; the fixed cost of a
# chunk is paid once for them; 30 frames cost 0.71 ms a frame, 60 0.43, 120 0.37 here)
WHOLE_CHUNK_FRAMES = 120


class _Whole:
    """The whole input played through the performance first (fed and committed on its
    own clock, as live), then the band posed :data:`WHOLE_CHUNK_FRAMES` frames at a
    time knowing every note."""

    def __init__(
        self, perf: Performance, feeder: RevealFeeder, times: list[float], chunk: int
    ) -> None:
        feeder.finish(perf)
        self.times = times
        self.chunk = max(chunk, 1)
        self.next = 0
        self.chunks = FrameChunks(perf.animator)  # type: ignore[arg-type]

    def scene(self, t: float) -> DrawList:
        i = self.next
        if i >= len(self.times) or self.times[i] != t:
            raise ValueError("the offline frames are drawn once each, in order")
        self.next += 1
        if not self.chunks.has(t):
            self.chunks.prepare(self.times[i : i + self.chunk])
        return self.chunks.scene(t)


_Call = tuple[str, tuple[object, ...]]


class _Deferred:
    """Stands in for the animator while the timer runs ahead of the frame drawn: keeps
    what the performance tells it (``take`` hands it over frame by frame)."""

    def __init__(self) -> None:
        self.calls: list[_Call] = []

    def take(self) -> list[_Call]:
        calls, self.calls = self.calls, []
        return calls

    def add_planned(self, p: object) -> None:
        self.calls.append(("add_planned", (p,)))

    def add_beat(self, beat: object) -> None:
        self.calls.append(("add_beat", (beat,)))

    def note_off(self, performer: object, event: object) -> None:
        self.calls.append(("note_off", (performer, event)))

    def note_known(self, performer: object, note: object, at_s: float) -> None:
        self.calls.append(("note_known", (performer, note, at_s)))

    def note_provisional(self, notes: object) -> None:
        self.calls.append(("note_provisional", (notes,)))

    def set_articulations(self, articulations: object) -> None:
        self.calls.append(("set_articulations", (articulations,)))

    def use_bass_strings(self, strings: object) -> None:
        self.calls.append(("use_bass_strings", (strings,)))


class _Ahead:
    """The offline timer run up to :data:`CHUNK_FRAMES` frames ahead of the frame drawn,
    so that the band is posed a chunk of frames at a time (:class:`FrameChunks`).

    The events are fed and the motions committed at each frame's time exactly as
    frame by frame (the planner sees the same calls in the same order), but what
    the animator is told at frame ``j`` is held back until frame ``j`` is drawn: a
    frame shows the animator as it was at its own time, and a chunk runs from
    one frame with news for the animator to the next.
    """

    def __init__(
        self, perf: Performance, feeder: RevealFeeder, times: list[float], ahead: int
    ) -> None:
        self.perf = perf
        self.feeder = feeder
        self.times = times
        self.ahead = max(ahead, 1)
        self.animator = perf.animator
        self.deferred = _Deferred()
        perf.animator = self.deferred
        self.deferred.take()  # the kit map and tuning, which the animator has already
        self.news: list[list[_Call]] = []
        self.next = 0
        self.chunks = FrameChunks(self.animator)  # type: ignore[arg-type]

    def _run_to(self, end: int) -> None:
        """Feed and commit frames up to ``end`` (exclusive), keeping each one's news."""
        for t in self.times[len(self.news) : end]:
            self.feeder.until(self.perf, t)
            self.perf.advance(t)
            calls = self.deferred.take()
            if calls and not any(self._changes_pose(c) for c in calls):
                self._tell(calls)  # told now: nothing of the pose depends on it
                calls = []
            self.news.append(calls)

    def _changes_pose(self, call: _Call) -> bool:
        """Whether a call may change the animator's poses (a note's arrival before its
        plan and a drum's note-off do not: ``BandAnimator.NOTE_OFF_PERFORMERS``)."""
        name, args = call
        if name == "note_known":
            return False
        if name != "note_off":
            return True
        return args[0] in getattr(self.animator, "NOTE_OFF_PERFORMERS", (args[0],))

    def _tell(self, calls: list[_Call]) -> None:
        for name, args in calls:
            getattr(self.animator, name)(*args)

    def scene(self, t: float) -> DrawList:
        i = self.next
        if i >= len(self.times) or self.times[i] != t:
            raise ValueError("the offline frames are drawn once each, in order")
        self.next += 1
        if i >= len(self.news):
            self._run_to(i + self.ahead)
        news, self.news[i] = self.news[i], []
        if news:
            self._tell(news)
            self.chunks.invalidate()
        if not self.chunks.has(t):
            j = i + 1
            while j < len(self.news) and not self.news[j]:
                j += 1
            self.chunks.prepare(self.times[i:j])
        mark = getattr(self.animator, "mark_drawn", None)
        if mark is not None:  # drawn: news told later changes nothing up to here
            mark(t)
        return self.chunks.scene(t)

    def close(self) -> None:
        """Give the performance its animator back, told everything it was told so far."""
        self.perf.animator = self.animator
        for calls in self.news[self.next :]:
            self._tell(calls)
        self._tell(self.deferred.take())
        self.news = []
