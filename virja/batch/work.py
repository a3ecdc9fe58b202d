"""One input to its outputs: the work a worker process or a Ray task does.

:func:`run_job` takes the input's bytes (so a worker on another machine needs
no shared filesystem), plans and animates it through the same pipeline as a
performance (``virja.input`` reveal schedule -> ``pipeline.build_performance``), and
returns every output as bytes.  It never raises: a failure is a result with
status ``error`` and a one-line message naming the input.
"""

from __future__ import annotations

import json
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from virja.batch.jobs import Job, OutputKind
from virja.batch.manifest import JobResult, Status
from virja.errors import VirjaError
from virja.input import PerformanceInput, load_performance_input, nothing_for_the_band
from virja.pipeline import PerformanceSettings, build_performance
from virja.plan.config import PlanConfig
from virja.routing import RoutingConfig
from virja.session import RevealFeeder, run_schedule


@dataclass(frozen=True)
class BatchSettings:
    """Everything a job needs besides its input, parsed once by the driver
    (plain data: it travels to worker processes and Ray tasks by pickle)."""

    plan: PlanConfig
    routing: RoutingConfig
    lookahead_beats: float = 1.0
    fps: float = 30.0
    size: tuple[int, int] = (1280, 720)
    soundfont: str | None = None

    @property
    def performance(self) -> PerformanceSettings:
        """What :func:`virja.pipeline.build_performance` builds each job's performance from."""
        return PerformanceSettings(self.plan, self.routing)


def _make_plan(src: PerformanceInput, out: Path, settings: BatchSettings) -> list[Path]:
    perf = build_performance(settings.performance, src)
    planned = run_schedule(perf, src.schedule)
    path = out / "plan.jsonl"
    path.write_text(
        "".join(json.dumps(p.to_json(src.start_s)) + "\n" for p in planned), encoding="utf-8"
    )
    return [path]


def _make_mp4(src: PerformanceInput, out: Path, settings: BatchSettings) -> list[Path]:
    from virja.render.offline import OutputSpec, RenderSettings, render_offline
    from virja.render.video import make_audio_track

    perf = build_performance(settings.performance, src, animate=True)
    t0, t1 = src.default_span()
    video = out / "take.mp4"
    audio, _why_not = make_audio_track(
        src.sound_events, src.sound_origin_s, out, settings.soundfont
    )
    frames = RenderSettings(
        OutputSpec("video", video),
        size=settings.size,
        fps=settings.fps,
        audio=audio,
        audio_offset_s=src.sound_origin_s - t0,
    )
    render_offline(perf, RevealFeeder(src.schedule), (t0, t1), frames)
    return [video]


Producer = Callable[[PerformanceInput, Path, BatchSettings], list[Path]]

# each producer returns its files in the order of jobs.OUTPUT_NAMES[kind]
PRODUCERS: dict[OutputKind, Producer] = {
    OutputKind.PLAN: _make_plan,
    OutputKind.MP4: _make_mp4,
}
EXPORTED = (OutputKind.BVH, OutputKind.GLTF, OutputKind.MUSICXML)  # one `virja export` pass


def _export(
    src_path: Path, kinds: list[OutputKind], out: Path, settings: BatchSettings
) -> dict[OutputKind, list[Path]]:
    """BVH, glTF and MusicXML in one pass of :func:`virja.export.export_performance`
    (one plan and one sampling of the band for all three)."""
    from virja.export.driver import export_performance

    paths = {
        OutputKind.BVH: out / "take.bvh",
        OutputKind.GLTF: out / "take.glb",
        OutputKind.MUSICXML: out / "take.musicxml",
    }
    done = export_performance(
        src_path,
        bvh=paths[OutputKind.BVH] if OutputKind.BVH in kinds else None,
        gltf=paths[OutputKind.GLTF] if OutputKind.GLTF in kinds else None,
        musicxml=paths[OutputKind.MUSICXML] if OutputKind.MUSICXML in kinds else None,
        fps=settings.fps,
        routing=settings.routing,
        plan_config=settings.plan,
        lookahead_beats=settings.lookahead_beats,
    )
    written = set(done.outputs)
    made: dict[OutputKind, list[Path]] = {}
    for kind in kinds:
        if kind is OutputKind.BVH:
            made[kind] = [
                p for p in (out / "take_drums.bvh", out / "take_bass.bvh") if p in written
            ]
        else:
            made[kind] = [paths[kind]]
    return made


def _message(exc: BaseException, tmp_input: Path, rel: str) -> str:
    text = str(exc) if isinstance(exc, VirjaError) else f"{type(exc).__name__}: {exc}"
    return " ".join(text.replace(str(tmp_input), rel).split()) or type(exc).__name__


def run_job(job: Job, data: bytes, settings: BatchSettings) -> JobResult:
    """Make every output of ``job`` from the input's bytes ``data``; never raises."""
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="virja-batch-") as tmp:
        src_path = Path(tmp) / PurePosixPath(job.rel).name
        try:
            src_path.write_bytes(data)
            src = load_performance_input(
                src_path, settings.routing, lookahead_beats=settings.lookahead_beats
            )
            if src.note_count == 0:
                raise nothing_for_the_band(src_path, src.report)
            made: dict[OutputKind, list[Path]] = {}
            exported = [k for k in job.kinds if k in EXPORTED]
            if exported:
                out = Path(tmp) / "export"
                out.mkdir()
                made.update(_export(src_path, exported, out, settings))
            for kind in job.kinds:
                if kind not in EXPORTED:
                    out = Path(tmp) / kind.value
                    out.mkdir()
                    made[kind] = PRODUCERS[kind](src, out, settings)
            files: dict[str, bytes] = {}
            for kind in job.kinds:
                for name, path in zip(job.output_names(kind), made[kind], strict=True):
                    files[name] = path.read_bytes()
        except Exception as exc:  # one bad file never stops the batch
            return JobResult(
                job.rel,
                Status.ERROR,
                time.perf_counter() - started,
                error=_message(exc, src_path, job.rel),
            )
    return JobResult(job.rel, Status.OK, time.perf_counter() - started, files=files)
