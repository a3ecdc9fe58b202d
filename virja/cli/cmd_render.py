"""Render a MIDI file or a pcap recording to PNG frames or a video with sound.

The notes are revealed to the scheduler a beat ahead (--lookahead-beats), as a
performance generator would send them, and the same code as the live daemon
plans and animates them; frames step exactly 1/fps.  OUT is a folder (PNG
frames), a NAME.png (numbered PNGs beside it, or one frame with --at), or a
video (.mp4, .mkv, .mov: H.264, with an AAC track rendered by fluidsynth from
the same notes unless --no-audio).

examples:
  virja render virja/demo/blues.mid --out out/demo.mp4
  virja render song.mid --out frames/ --size 640x360 --fps 20
  virja render song.mid --out snare.png --at 3.2 --camera drums
"""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from virja.cli.common import (
    SAMPLE_CHOICES,
    ProgressBar,
    add_routing_arguments,
    check_writable,
    finite_float,
    open_plan_log,
    performance_settings,
)
from virja.errors import ConfigError
from virja.render.camera import PRESETS

if TYPE_CHECKING:
    from virja.dance.stage import DancerTrack
    from virja.input import PerformanceInput
    from virja.pipeline import PerformanceSettings
    from virja.render.camera import Camera
    from virja.render.director import FollowCamera
    from virja.render.offline import RenderSettings
    from virja.render.renderer import DrawList

log = logging.getLogger(__name__)


MAX_FRAMES = 1_000_000  # about 9 hours at 30 fps: a longer span is a mistake, not a song


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "input", metavar="INPUT", help="a MIDI file (.mid) or an RMCP recording (.pcap, .pcapng)"
    )
    p.add_argument(
        "--out",
        required=True,
        metavar="OUT",
        help="folder, NAME.png, or video file (.mp4/.mkv/.mov)",
    )
    p.add_argument(
        "--size", default="1280x720", metavar="WxH", help="frame size (default 1280x720)"
    )
    p.add_argument("--fps", type=finite_float, default=30.0, help="frames per second (default 30)")
    p.add_argument(
        "--camera",
        choices=[*sorted(PRESETS), "follow"],
        default="front",
        help="camera preset (default front); follow: cuts and moves between the players as "
        "they play (a drum fill to the drummer, a bass feature to the bassist)",
    )
    p.add_argument(
        "--lookahead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="notes are known B beats ahead (default 1)",
    )
    p.add_argument("--no-audio", action="store_true", help="make a silent video")
    p.add_argument(
        "--hud",
        action="store_true",
        help="draw a heads-up display: tempo, bar.beat and chord (from BEAT and CHORD "
        "messages, a file's tempo map, and chord symbols in its lyrics or markers)",
    )
    p.add_argument(
        "--soundfont", metavar="FILE.sf2", help="General MIDI soundfont for the audio track"
    )
    p.add_argument(
        "--at",
        type=finite_float,
        metavar="SECONDS",
        help="render only the frame at this time, seconds from the input's start "
        "(a recording's first packet; with a .png OUT)",
    )
    p.add_argument(
        "--start",
        type=finite_float,
        metavar="SECONDS",
        help="first frame, seconds from the input's start (default: early enough for "
        "the first motion)",
    )
    p.add_argument(
        "--end",
        type=finite_float,
        metavar="SECONDS",
        help="last frame, seconds from the input's start (default: the end plus 1.5 s)",
    )
    p.add_argument(
        "--samples",
        type=int,
        default=1,
        choices=SAMPLE_CHOICES,
        help="multisample anti-aliasing, 1 (off, default) to 8; 4 looks smoother and renders about 2.5x slower here",
    )
    p.add_argument(
        "--plan-log", metavar="FILE.jsonl", help="also write the plan, one JSON object per note"
    )
    p.add_argument(
        "--as-live",
        action="store_true",
        help="draw each frame knowing only what the live window would know at its time "
        "(motions learned as they start); default: the whole input known, as motion-report "
        "and export see it",
    )
    p.add_argument(
        "--bvh",
        metavar="OUT.bvh",
        help="also write the band's performed motion as OUT_drums.bvh and OUT_bass.bvh "
        "(one per figure; `virja export` does it without rendering)",
    )
    add_dancer_argument(p)
    add_routing_arguments(p)


def add_dancer_argument(p: argparse.ArgumentParser) -> None:
    """--dancer DB (shared with `virja replay`)."""
    p.add_argument(
        "--dancer",
        metavar="DB",
        help="also draw a dancer, front centre, whose motion method B generates from the "
        "session's audio with this database (`virja teach`); needs fluidsynth and a soundfont",
    )


@dataclass(frozen=True)
class RenderRequest:
    """What `render` and `replay --out` take from their options, parsed once: the
    performance's settings, the frames' settings (camera still by name: "follow" is
    planned from the input), the span (``at``/``start``/``end``: seconds from the
    input's start) and the other files to write."""

    performance: PerformanceSettings
    frames: RenderSettings
    camera: str = "front"
    audio: bool = True
    soundfont: str | None = None
    at: float | None = None
    start: float | None = None
    end: float | None = None
    plan_log: str | None = None
    bvh: str | None = None
    dancer: str | None = None


def render_request(
    args: argparse.Namespace, performance: PerformanceSettings, *, span: bool = True
) -> RenderRequest:
    """The request of `render` (``span``: it has --at, --start, --end and --bvh) or of
    `replay --out`; the frame size and the output kind checked."""
    from virja.render.offline import OutputSpec, RenderSettings, parse_size

    size = parse_size(args.size)
    out = OutputSpec.from_path(args.out)
    at = args.at if span else None
    if at is not None and out.kind != "png":
        raise ConfigError("--at renders one frame: give --out NAME.png")
    frames = RenderSettings(
        out,
        size=size,
        fps=args.fps,
        samples=args.samples,
        hud=bool(getattr(args, "hud", False)),
        as_live=bool(getattr(args, "as_live", False)),
        progress=ProgressBar("rendering") if out.kind != "png" or at is None else None,
    )
    return RenderRequest(
        performance=performance,
        frames=frames,
        camera=args.camera,
        audio=not args.no_audio,
        soundfont=args.soundfont,
        at=at,
        start=args.start if span else None,
        end=args.end if span else None,
        plan_log=args.plan_log,
        bvh=args.bvh if span else None,
        dancer=getattr(args, "dancer", None),
    )


def run(args: argparse.Namespace) -> int:
    from virja.input import load_performance_input, nothing_for_the_band

    if args.fps <= 0 or args.fps > 240:
        raise ConfigError(f"--fps must be in (0, 240], got {args.fps}")
    if args.lookahead_beats < 0:
        raise ConfigError("--lookahead-beats must be >= 0")
    request = render_request(args, performance_settings(args))
    check_outputs(request)
    src = load_performance_input(
        Path(args.input), request.performance.routing, lookahead_beats=args.lookahead_beats
    )
    for line in src.report:
        print(line)
    if src.note_count == 0:
        raise nothing_for_the_band(Path(args.input), src.report)
    return render_input(src, request)


def check_outputs(request: RenderRequest) -> None:
    """Every file the render will write is writable, and the soundfont is one: checked
    before the (long) work, each a one-line error.  Shared by `render` and `replay --out`."""
    from virja.motion.export import bvh_paths
    from virja.render.video import check_soundfont

    out = request.frames.out
    one_file = out.kind == "video" or (out.kind == "png" and request.at is not None)
    check_writable(out.path if one_file else out.frame_path(0), "--out")
    if request.bvh:
        for path in bvh_paths(Path(request.bvh)):
            check_writable(path, "--bvh")
    if request.soundfont and out.kind == "video" and request.audio:
        check_soundfont(Path(request.soundfont), "--soundfont")


def render_span(src: PerformanceInput, request: RenderRequest) -> tuple[float, float]:
    """The session times of the first and last frames: the input's span, or --at,
    --start, --end (seconds from the input's start); ConfigError when it is empty or huge."""
    t0, t1 = src.default_span()
    base = src.start_s  # --at, --start, --end: from the input's start (MIDI files and recordings)
    if request.start is not None:
        t0 = base + request.start
    if request.end is not None:
        t1 = base + request.end
    if request.at is not None:
        t0 = t1 = base + request.at
        # everything known before the frame must have been fed: start the feeder there
    if t1 < t0:
        raise ConfigError(
            f"nothing to render: end {t1 - base:.3f} s is before start {t0 - base:.3f} s"
        )
    first_s, last_s = src.default_span()
    if request.at is not None and not first_s <= base + request.at <= last_s:
        log.warning(
            "--at %.3f s is outside the performance (%.3f to %.3f s from the start of the "
            "input): the band is idle there",
            request.at,
            first_s - base,
            last_s - base,
        )
    fps = request.frames.fps
    if (t1 - t0) * fps > MAX_FRAMES:  # e.g. a recording with datagrams years apart
        raise ConfigError(
            f"the span {t0 - base:.3f} .. {t1 - base:.3f} s is {(t1 - t0) * fps:.0f} "
            f"frames, more than "
            f"{MAX_FRAMES:,}; pick a part with --start and --end"
        )
    return t0, t1


def render_input(src: PerformanceInput, request: RenderRequest) -> int:
    """Shared by `render` and `replay --out`: plan, animate, draw, encode."""
    from virja.pipeline import build_performance
    from virja.render.offline import render_offline
    from virja.render.video import make_audio_track, temp_workdir
    from virja.session import RevealFeeder

    plan_log = open_plan_log(request.plan_log)
    perf = build_performance(request.performance, src, animate=True, plan_log=plan_log)
    animator = perf.animator
    feeder = RevealFeeder(src.schedule)
    t0, t1 = render_span(src, request)
    out = request.frames.out
    with temp_workdir() as tmp:
        audio = None
        if out.kind == "video" and request.audio:
            audio, why_not = make_audio_track(
                src.sound_events, src.sound_origin_s, Path(tmp), request.soundfont
            )
            if why_not:
                print(f"virja: {why_not}", file=sys.stderr)
        extra = None
        if request.dancer is not None:
            from virja.render.scene import figure_scene

            track = session_dancer(src, request.dancer, audio, Path(tmp), request.soundfont)

            def extra(t: float) -> list[DrawList]:
                return [figure_scene(track.pose(t))]

        frames = replace(
            request.frames.with_audio(audio, src.sound_origin_s - t0),
            camera=choose_camera(request.camera, src, perf),
        )
        result = render_offline(perf, feeder, (t0, t1), frames, extra=extra)
    if plan_log is not None:
        plan_log.close()
    if request.bvh:
        from virja.motion.band import BandAnimator
        from virja.motion.export import performance_to_bvh

        assert isinstance(animator, BandAnimator)
        for path in performance_to_bvh(animator, t0, t1, frames.fps, Path(request.bvh)):
            print(f"wrote {path}")
    rate = result.frames / result.seconds if result.seconds > 0 else float("inf")
    where: object = out.path
    if out.kind != "video" and len(result.outputs) == 1:
        where = result.outputs[0]
    elif out.kind != "video" and result.outputs:
        where = f"{result.outputs[0]} ... {result.outputs[-1].name}"
    print(
        f"wrote {result.frames} frame{'' if result.frames == 1 else 's'} "
        f"({t1 - t0:.2f} s at {frames.fps:g} fps from {t0 - src.start_s:.2f} s) to {where} "
        f"in {result.seconds:.1f} s ({rate:.1f} frames/s); "
        f"planned {perf.counts['planned']} notes ({perf.counts['planned_late']} late)"
    )
    return 0


def choose_camera(name: str, src: object, perf: object) -> Camera | FollowCamera:
    """A preset, or for "follow" the shots planned from the input's band notes (over
    the whole input, so a single frame with --at shows the shot of that moment)."""
    from virja.events import NoteOn
    from virja.input import PerformanceInput
    from virja.render.director import FollowCamera, plan_shots
    from virja.routing import Router
    from virja.session import Performance

    if name != "follow":
        return PRESETS[name]
    assert isinstance(src, PerformanceInput) and isinstance(perf, Performance)
    dry = Router(perf.router.config, perf.router.track_names)  # its own program memory
    notes = []
    for reveal in sorted(src.schedule, key=lambda r: r.event.time_s):
        ev = reveal.event
        who = dry.route(ev)
        if who is not None and isinstance(ev, NoteOn):
            notes.append((ev.time_s, who, ev.note))
    shots = plan_shots(notes, *src.default_span())
    print(
        f"follow camera: {len(shots)} shots: "
        + ", ".join(  # seconds from the input's start, as --at counts
            f"{s.name} {s.start_s - src.start_s:.1f}-{s.end_s - src.start_s:.1f} s"
            for s in shots[:8]
        )
        + (" ..." if len(shots) > 8 else "")
    )
    return FollowCamera(shots)


def session_dancer(
    src: object, db_path: str, wav: Path | None, workdir: Path, soundfont: str | None
) -> DancerTrack:
    """The dancer for `--dancer DB`: the session's audio (``wav`` if already rendered),
    method B generation, placed front centre; frame 0 at the audio's t = 0."""
    from virja.dance.audio import read_audio_8k
    from virja.dance.database import load_database
    from virja.dance.stage import dance_to_audio
    from virja.errors import NotAvailableError
    from virja.input import PerformanceInput
    from virja.render.video import make_audio_track

    assert isinstance(src, PerformanceInput)
    db = load_database(db_path)
    if wav is None:
        wav, why_not = make_audio_track(src.sound_events, src.sound_origin_s, workdir, soundfont)
        if wav is None:
            raise NotAvailableError(f"--dancer needs the session's audio: {why_not}")
    track, g = dance_to_audio(db, read_audio_8k(wav), t0_s=src.sound_origin_s)
    print(f"dancer: {len(g.beats_s)} beats, {len(g.intervals)} segments from {db_path}")
    return track
