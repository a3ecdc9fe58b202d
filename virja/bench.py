"""Benchmarks: figures printed by ``virja bench``, never asserted in tests.

Each function measures one thing on this machine and returns plain numbers;
:func:`run_all` gathers them with the targets of the issues, so each figure
can be shown as a ratio to its target (machines here are noisy; ratios and
medians travel better than single times).
"""

from __future__ import annotations

import asyncio
import os
import platform
import socket
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from virja.events import NoteOn
from virja.midifile import read_midi


@dataclass(frozen=True)
class Figure:
    key: str
    value: float
    unit: str
    target: float
    higher_is_better: bool
    note: str = ""
    load: float | None = None  # the reference workload's wall over CPU time, near the figure

    @property
    def ref_ratio(self) -> float | None:
        """The ratio to the target with the figure corrected for the machine's load: a
        CPU figure scaled by how much of its wall time the reference workload spent
        waiting for a core in this run (None for figures not corrected)."""
        if self.load is None or self.value <= 0:
            return None
        load = max(self.load, 1.0)  # a faster machine is not credited
        value = self.value * load if self.higher_is_better else self.value / load
        return value / self.target if self.higher_is_better else self.target / value

    @property
    def ratio(self) -> float:
        """Figure over target when higher is better, target over figure otherwise (>= 1 meets it)."""
        if self.value <= 0:
            return 0.0 if self.higher_is_better else float("inf")
        return self.value / self.target if self.higher_is_better else self.target / self.value


def demo_path() -> str:
    """The bundled demo session (inside the package, so installed copies have it)."""
    return str(Path(__file__).resolve().parent / "demo" / "blues.mid")


def machine() -> dict[str, Any]:
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "system": f"{platform.system()} {platform.release()}",
    }


# -- the reference: how loaded the machine is now ----------------------------------


def reference_load(repeats: int = 7) -> tuple[float, float]:
    """A fixed single-thread workload of small numpy calls and Python (the kind of work
    the per-frame path does): (median wall ms, load).  The load is its wall time over
    the CPU time this thread got for it: 1.0 on an idle machine, 3.0 when the thread
    waited for a core two thirds of the time (other jobs sharing the cores)."""
    rng = np.random.default_rng(0)
    a = rng.standard_normal((64, 3))
    b = rng.standard_normal((64, 3))
    m = rng.standard_normal((48, 4, 4))
    walls, loads = [], []
    for _ in range(repeats):
        start, cpu = time.perf_counter(), time.thread_time()
        acc = 0.0
        for _ in range(400):
            c = np.cross(a, b)
            n = np.sqrt(np.einsum("ij,ij->i", c, c))
            acc += float((m @ m).sum()) + float(n.sum())
            acc += sum(x * 0.5 for x in range(40))
        wall, used = time.perf_counter() - start, time.thread_time() - cpu
        walls.append(wall)
        loads.append(wall / max(used, 1e-9))
    return float(np.median(walls)) * 1000, max(float(np.median(loads)), 1.0)


# -- RMCP ---------------------------------------------------------------------


def _datagrams(n: int, senders: int = 4) -> list[bytes]:
    from virja.rmcp import wire

    base_us = 1_700_000_000_000_000
    out = []
    for i in range(n):
        sender = 1 + i % senders
        seq = i // senders
        out.append(bytes(wire.midi(sender, seq, base_us + i * 1000, bytes([0x99, 38, 100]))))
    return out


def rmcp_decode_rate(n: int = 40_000) -> float:
    """Datagrams decoded, validated and queued per second (one core, no sockets)."""
    from virja.rmcp.receiver import Receiver, ReceiverConfig

    data = _datagrams(n)
    receiver = Receiver(ReceiverConfig(horizon_s=1e9, lateness_s=1e9))
    now_us = 1_700_000_000_000_000
    addr = ("127.0.0.1", 50501)
    start = time.perf_counter()
    for d in data:
        receiver.receive_datagram(d, addr, now_us=now_us)
        receiver.drain_events()
    elapsed = time.perf_counter() - start
    return n / elapsed


def rmcp_latency_ms(n: int = 1500, rate_hz: float = 1000.0) -> tuple[float, float]:
    """Loopback send -> received -> routed -> planned, p50 and p99 in ms.

    A client socket sends note datagrams (a beat ahead on the session clock) to
    the daemon's protocol on 127.0.0.1; the time from ``sendto`` to the planner
    holding the note in its plan is measured in one process on one clock.
    """
    return asyncio.run(_latency(n, rate_hz))


async def _latency(n: int, rate_hz: float) -> tuple[float, float]:
    from virja.clock import SessionClock
    from virja.plan.planner import OnlinePlanner
    from virja.rmcp import wire
    from virja.rmcp.receiver import Receiver
    from virja.rmcp.transport import RmcpProtocol, open_listener
    from virja.routing import Router
    from virja.session import Performance

    clock = SessionClock()
    perf = Performance(router=Router(), planner=OnlinePlanner())
    perf.keep_planned = False
    sent_at: dict[int, float] = {}
    lat: list[float] = []

    def on_events(received: list[Any], now_s: float) -> None:
        for rec in received:
            perf.feed(rec.event, now_s=rec.arrival_s)
        perf.advance(now_s)
        done = time.perf_counter()
        for rec in received:
            ev = rec.event
            if isinstance(ev, NoteOn):
                key = round(ev.time_s * 1e6)
                if key in sent_at:
                    lat.append(done - sent_at.pop(key))

    protocol = RmcpProtocol(Receiver(), clock, on_events)
    transport = await open_listener("127.0.0.1", 0, protocol)
    port = transport.get_extra_info("sockname")[1]
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.setblocking(False)
    notes = [38, 42, 36, 51]
    try:
        for i in range(n):
            t_us = clock.now_us() + 500_000  # a beat ahead at 120 bpm
            data = bytes(wire.midi(2, i, t_us, bytes([0x99, notes[i % 4], 90])))
            sent_at[t_us] = time.perf_counter()
            client.sendto(data, ("127.0.0.1", port))
            await asyncio.sleep(1 / rate_hz)
        await asyncio.sleep(0.05)
    finally:
        client.close()
        transport.close()
    if not lat:
        return (float("nan"), float("nan"))
    arr = np.array(lat) * 1000
    return float(np.percentile(arr, 50)), float(np.percentile(arr, 99))


# -- planning -----------------------------------------------------------------


def plan_path() -> str:
    """Which path the planner's DPs take here: "compiled", or "pure" and why (not built,
    a stale build, ``VIRJA_PLAN_PURE=1``): :func:`virja.plan.fastdp.path`."""
    from virja.plan import fastdp

    return fastdp.path()


# The beats a fresh process plans before the measured ones (other seeds): a planner
# compiles each stroke signature the first time it meets it (virja.plan.drums._compiled,
# 40-120 us each, kept for the process), which a daemon does in its first seconds; the
# bench's 300 beats meet 34 signatures, most in their first six beats, which were the
# figure's p99 before (issue 17, seventh round).  Their cost is reported beside it.
PLAN_WARM_BEATS = 30


def plan_beat_ms(beats: int = 300, warm_beats: int = PLAN_WARM_BEATS) -> tuple[float, float, float]:
    """Planning one beat of 16 notes per performer known at once, p50 and p99 in ms,
    measured after ``warm_beats`` beats of other seeds (a running daemon's state); and
    the slowest of those first beats (the cold start), in ms."""
    from virja.plan.bench import beat_workload, plan_one_beat
    from virja.plan.config import default_config

    config = default_config()
    workloads = [beat_workload(seed, 16) for seed in range(beats)]
    cold = 0.0
    for seed in range(10_000, 10_000 + max(1, warm_beats)):
        w = beat_workload(seed, 16)
        start = time.perf_counter()
        plan_one_beat(w, config)
        cold = max(cold, time.perf_counter() - start)
    times = []
    for w in workloads:
        start = time.perf_counter()
        plan_one_beat(w, config)
        times.append(time.perf_counter() - start)
    arr = np.array(times) * 1000
    return float(np.percentile(arr, 50)), float(np.percentile(arr, 99)), cold * 1000


def plan_streamed_ms(beats: int = 200) -> tuple[float, float]:
    """The live case: each note of a beat (16 per performer) arrives in its own
    datagram a beat ahead and the planner re-plans on each; per-beat p50, p99 ms."""
    from virja.plan.planner import OnlinePlanner

    rng = np.random.default_rng(7)
    spb = 0.5
    planner = OnlinePlanner()
    drum_notes = [38, 42, 36, 51, 46, 45, 49]
    times = []
    for b in range(beats):
        t_beat = b * spb
        now = t_beat - spb
        bass = [NoteOn(t_beat + k * spb / 16, 1, int(rng.integers(28, 60)), 90) for k in range(16)]
        drums = [
            NoteOn(t_beat + k * spb / 16, 9, drum_notes[int(rng.integers(0, 7))], 90)
            for k in range(16)
        ]
        start = time.perf_counter()
        for note in bass:
            planner.add_note("bass", note, now_s=now)
        for note in drums:
            planner.add_note("drums", note, now_s=now)
        planner.poll(now)
        times.append(time.perf_counter() - start)
    arr = np.array(times[10:]) * 1000
    return float(np.percentile(arr, 50)), float(np.percentile(arr, 99))


# -- motion and drawing -------------------------------------------------------


def _demo_animator() -> tuple[Any, float, float]:
    from virja.motion.band import BandAnimator
    from virja.plan.planner import plan_notes
    from virja.routing import Router, route_all

    session = read_midi(demo_path())
    routed = [
        (p, e)
        for p, e in route_all(session.events, Router.for_session(session))
        if isinstance(e, NoteOn)
    ]
    animator = BandAnimator()
    for b in session.beats:
        animator.add_beat(b)
    for p in plan_notes(routed, session.tempo_map):
        animator.add_planned(p)
    return animator, 0.0, session.duration_s


def pose_ms(frames: int = 600) -> float:
    """Sampling, blending and forward kinematics of both players one frame at a time
    (``BandAnimator.pose(t)``, for callers that need one time), mean ms per frame."""
    animator, t0, t1 = _demo_animator()
    times = np.linspace(t0, t1, frames)
    animator.pose(times[0])
    start = time.perf_counter()
    for t in times:
        animator.pose(float(t))
    return (time.perf_counter() - start) / frames * 1000


@dataclass(frozen=True)
class PoseSceneFigures:
    """What :func:`pose_scene_ms` measured (ms per frame unless said)."""

    pose: float  # the render loops' path: posed in chunks, amortised per frame
    scene: float
    frames_per_chunk: float
    single_pose: float  # one frame at a time (pose(t) + band_scene), as before the chunks
    single_scene: float
    live_pose: float  # render --as-live: chunks end where the animator learns something
    live_scene: float
    live_frames_per_chunk: float


def demo_frames(frames: int | None = None, *, as_live: bool = False) -> Iterator[tuple[Any, Any]]:
    """The offline render's frame path over the demo without GL: (scene, chunks) per
    frame, as ``render_offline`` builds them (:class:`virja.render.chunks.FrameChunks`):
    the whole demo played through first, then 120 frames posed at a time; ``as_live``
    (``render --as-live``): the timer run ahead and each stretch of frames until the
    animator's next news posed at once."""
    from virja.input import load_performance_input
    from virja.pipeline import PerformanceSettings, build_performance
    from virja.render.offline import CHUNK_FRAMES, WHOLE_CHUNK_FRAMES, _Ahead, _Whole
    from virja.session import RevealFeeder, frame_times

    settings = PerformanceSettings()
    src = load_performance_input(Path(demo_path()), settings.routing)
    t0, t1 = src.default_span()
    times = list(frame_times(t0, t1, 30.0))[:frames]
    perf = build_performance(settings, src, animate=True)
    if not as_live:
        whole = _Whole(perf, RevealFeeder(src.schedule), times, WHOLE_CHUNK_FRAMES)
        for t in times:
            yield whole.scene(t), whole.chunks
        return
    ahead = _Ahead(perf, RevealFeeder(src.schedule), times, CHUNK_FRAMES)
    try:
        for t in times:
            yield ahead.scene(t), ahead.chunks
    finally:
        ahead.close()


def pose_scene_ms(frames: int = 600) -> PoseSceneFigures:
    """Pose (sampling, blending, FK) and scene building (instance tables) of the demo,
    mean ms per frame each: the CPU part of a frame before GL.

    As the render loop does it: ``virja render``'s loop over the demo, the whole demo
    played through first and 120 frames posed and built at a time (:func:`demo_frames`);
    the planning is not counted.  Beside it, one frame at a time (``pose(t)`` then
    ``band_scene``) and ``render --as-live``'s loop (each stretch of frames until the
    animator's next news at once)."""
    from virja.render.scene import band_scene

    def chunked(as_live: bool) -> Any:
        loop = demo_frames(frames, as_live=as_live)
        _scene, chunks = next(loop)
        for _scene, _chunks in loop:
            pass
        return chunks

    chunks = chunked(False)
    live = chunked(True)
    n = max(chunks.frames, 1)
    animator, t0, t1 = _demo_animator()
    times = np.linspace(t0, t1, frames).tolist()
    band_scene(animator.pose(times[0])).packed("cylinder")
    pose_s = scene_s = 0.0
    for t in times[:: max(len(times) // 150, 1)]:
        a = time.perf_counter()
        pose = animator.pose(t)
        b = time.perf_counter()
        band_scene(pose).packed("cylinder")
        scene_s += time.perf_counter() - b
        pose_s += b - a
    single = len(times[:: max(len(times) // 150, 1)])
    return PoseSceneFigures(
        pose=chunks.pose_s / n * 1000,
        scene=chunks.scene_s / n * 1000,
        frames_per_chunk=chunks.frames / max(chunks.chunks, 1),
        single_pose=pose_s / single * 1000,
        single_scene=scene_s / single * 1000,
        live_pose=live.pose_s / max(live.frames, 1) * 1000,
        live_scene=live.scene_s / max(live.frames, 1) * 1000,
        live_frames_per_chunk=live.frames / max(live.chunks, 1),
    )


def gl_draw_ms(frames: int = 90, size: tuple[int, int] = (1280, 720)) -> float:
    """GL time of one frame of the band (scenes built beforehand): draw until finished,
    median ms."""
    from virja.render.camera import PRESETS
    from virja.render.hosts import OffscreenTarget, create_headless_context
    from virja.render.renderer import Renderer
    from virja.render.scene import band_scene, static_scene

    animator, t0, t1 = _demo_animator()
    scenes = [
        band_scene(animator.pose(float(t))) for t in np.linspace(t0, min(t1, t0 + 8.0), frames)
    ]
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=1)
    static = static_scene()
    cam = PRESETS["front"]
    times = []
    try:
        renderer.draw([static, scenes[0]], cam, target.fbo)
        target.finish()
        for dl in scenes:
            start = time.perf_counter()
            renderer.draw([static, dl], cam, target.fbo)
            target.finish()
            times.append(time.perf_counter() - start)
    finally:
        target.release()
        renderer.release()
        ctx.release()
    return float(np.median(times)) * 1000


def offline_realtime_factor(
    seconds: float | None = None, size: str = "1280x720", audio: bool = True
) -> tuple[float, float]:
    """``virja render`` of the demo to an H.264 video with its sound, as a user runs it:
    (music seconds / wall seconds, music seconds).  ``seconds`` renders only the first
    part of the demo; ``size`` the frame size; ``audio=False`` a silent video."""
    import contextlib
    import io
    import tempfile

    from virja.cli.main import main

    duration = read_midi(demo_path()).duration_s
    end = duration + 1.5 if seconds is None else min(seconds, duration + 1.5)
    with tempfile.TemporaryDirectory(prefix="virja-bench-") as tmp:
        argv = ["render", demo_path(), "--out", str(Path(tmp) / "demo.mp4"), "--end", f"{end}"]
        argv += ["--size", size] + ([] if audio else ["--no-audio"])
        start = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            rc = main(argv)
        wall = time.perf_counter() - start
    if rc != 0:
        return 0.0, end
    return end / wall, end


def export_realtime_factor() -> tuple[float, float]:
    """``virja export`` of the demo to glTF, BVH and MusicXML in this process, as a user
    runs it (reading, planning, animating, writing; the motion library already loaded):
    (music seconds / wall seconds, music seconds)."""
    import contextlib
    import io
    import re
    import tempfile

    from virja.cli.main import main

    with tempfile.TemporaryDirectory(prefix="virja-bench-") as tmp:
        out = Path(tmp)
        argv = ["export", demo_path(), "--gltf", str(out / "b.glb"), "--bvh", str(out / "b.bvh")]
        argv += ["--musicxml", str(out / "b.musicxml")]
        said = io.StringIO()
        start = time.perf_counter()
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(io.StringIO()):
            rc = main(argv)
        wall = time.perf_counter() - start
    found = re.search(r"exported ([0-9.]+) s", said.getvalue())
    if rc != 0 or found is None:
        return 0.0, 0.0
    music = float(found.group(1))
    return music / wall, music


def jam_key_to_impact_ms(notes: int = 60) -> tuple[float, str]:
    """Median key-to-impact of ``virja jam`` through JACK (tools/jack_latency.py
    --impact, a checkout's tool with its own dummy JACK server): (ms, note);
    NaN and why where it cannot run here."""
    import re
    import shutil
    import subprocess
    import sys

    tool = Path(__file__).resolve().parent.parent / "tools" / "jack_latency.py"
    if not tool.is_file():
        return float("nan"), "not measured: tools/jack_latency.py is in a checkout only"
    if shutil.which("jackd") is None:
        return float("nan"), "not measured: no jackd (apt-get install jackd2)"
    cmd = [sys.executable, str(tool), "--impact", "--notes", str(notes), "--gap-ms", "120"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
    except subprocess.TimeoutExpired:
        return float("nan"), "not measured: the JACK run took over 120 s"
    found = re.search(r"median ([0-9.]+) ms\s+p95 ([0-9.]+) ms\s+worst ([0-9.]+) ms", proc.stdout)
    if proc.returncode != 0 or not found:
        why = (proc.stderr.strip().splitlines() or ["no figure printed"])[-1][:200]
        return float("nan"), f"not measured: {why}"
    return float(found.group(1)), f"p95 {found.group(2)} ms, worst {found.group(3)} ms"


def render_fps(
    seconds: float = 3.0,
    readback: bool = False,
    size: tuple[int, int] = (1280, 720),
    samples: int = 1,
) -> tuple[float, str]:
    """Frames per second drawing the full band headless, posed and built as the offline
    render does (:func:`demo_frames`; the planning of its loop included); and the GL
    renderer."""
    from virja.render.camera import PRESETS
    from virja.render.hosts import OffscreenTarget, create_headless_context
    from virja.render.renderer import Renderer
    from virja.render.scene import static_scene

    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = OffscreenTarget(ctx, size, samples=samples)
    static = static_scene()
    cam = PRESETS["front"]
    gl_name = str(ctx.info.get("GL_RENDERER", "?"))
    frames = 0
    start = time.perf_counter()
    try:
        while time.perf_counter() - start < seconds:  # the demo again if it ends before
            for scene, _chunks in demo_frames():
                renderer.draw([static, scene], cam, target.fbo)
                if readback:
                    target.read_rgb()
                else:
                    target.finish()
                frames += 1
                if time.perf_counter() - start >= seconds:
                    break
        elapsed = time.perf_counter() - start
    finally:
        target.release()
        renderer.release()
        ctx.release()
    return frames / elapsed, gl_name


# render_fps at 1280x720 before the speed work (docs/performance.md, quiet median)
RENDER_FPS_BEFORE = 78.1


def run_all(
    quick: bool = False,
    progress: Callable[[str], None] | None = None,
    jam: bool = True,
    offline: bool = True,
) -> tuple[dict[str, Any], list[Figure]]:
    say = progress or (lambda _msg: None)
    scale = 0.4 if quick else 1.0
    figs: list[Figure] = []
    say("reference workload")
    refs = [reference_load()]

    def load() -> float:
        """The machine's load now (the reference measured again before each figure)."""
        refs.append(reference_load(3))
        return refs[-1][1]

    say("rmcp decode")
    lf = load()
    figs.append(
        Figure(
            "rmcp_datagrams_per_s",
            rmcp_decode_rate(int(40_000 * scale)),
            "datagrams/s",
            50_000,
            True,
            load=lf,
        )
    )
    say("rmcp latency")
    p50, p99 = rmcp_latency_ms(int(1500 * scale))
    figs.append(Figure("rmcp_latency_ms_p99", p99, "ms", 2.0, False, f"p50 {p50:.3f} ms"))
    say("planning")
    lf = load()
    pp50, pp99, cold = plan_beat_ms(int(300 * scale))
    s50, s99 = plan_streamed_ms(int(200 * scale))
    note = (
        f"p50 {pp50:.3f} ms after {PLAN_WARM_BEATS} beats; a fresh process's first beats: "
        f"slowest {cold:.2f} ms; streamed note by note: p50 {s50:.2f} ms, p99 {s99:.2f} ms "
        f"per beat; DP path: {plan_path()}"
    )
    figs.append(Figure("plan_ms_p99", pp99, "ms", 1.0, False, note, load=lf))
    say("pose and scene")
    lf = load()
    ps = pose_scene_ms(int(600 * scale))
    chunked = f"in chunks of {ps.frames_per_chunk:.1f} frames (render's loop)"
    figs.append(
        Figure(
            "pose_ms",
            ps.pose,
            "ms/frame",
            1.0,
            False,
            f"{chunked}; one frame at a time {ps.single_pose:.3f} ms",
            load=lf,
        )
    )
    figs.append(
        Figure(
            "pose_scene_ms",
            ps.pose + ps.scene,
            "ms/frame",
            0.5,
            False,
            f"pose {ps.pose:.3f} + scene {ps.scene:.3f} ms {chunked}; one frame at a time "
            f"{ps.single_pose + ps.single_scene:.3f} ms; render --as-live "
            f"{ps.live_pose + ps.live_scene:.3f} ms in chunks of "
            f"{ps.live_frames_per_chunk:.1f} frames",
            load=lf,
        )
    )
    say("GL draw")
    figs.append(
        Figure(
            "gl_draw_ms",
            gl_draw_ms(int(90 * scale)),
            "ms/frame",
            1000 / (1.5 * RENDER_FPS_BEFORE),
            False,
            "1280x720, drawn until finished, scenes built before",
            load=load(),
        )
    )
    say("render")
    fps, gl_name = render_fps(3.0 * scale)
    target_fps = 1.5 * RENDER_FPS_BEFORE
    figs.append(
        Figure(
            "render_fps",
            fps,
            "frames/s",
            target_fps,
            True,
            f"1280x720, no MSAA, no readback; 1.5x the {RENDER_FPS_BEFORE:g} fps before",
            load=load(),
        )
    )
    say("render with readback")
    fps_rb, _ = render_fps(3.0 * scale, readback=True)
    figs.append(
        Figure(
            "render_fps_readback",
            fps_rb,
            "frames/s",
            target_fps,
            True,
            "1280x720, no MSAA, with readback as for video",
            load=load(),
        )
    )
    if offline:
        say("offline render of the demo with encoding")
        lf = load()
        rtf, music_s = offline_realtime_factor(8.0 if quick else None)
        figs.append(
            Figure(
                "offline_realtime_factor",
                rtf,
                "x real time",
                2.0,
                True,
                f"virja render of {music_s:.1f} s of the demo to .mp4 with sound, 1280x720, 30 fps",
                load=lf,
            )
        )
    say("export of the demo")
    lf = load()
    export_realtime_factor()  # the first run loads the motion library
    xrt, music_s = export_realtime_factor()
    figs.append(
        Figure(
            "export_realtime_factor",
            xrt,
            "x real time",
            20.0,
            True,
            f"virja export of {music_s:.1f} s of the demo to glTF, BVH and MusicXML",
            load=lf,
        )
    )
    if jam:
        say("jam key to impact (JACK)")
        k2i, why = jam_key_to_impact_ms(30 if quick else 60)
        figs.append(Figure("jam_key_to_impact_ms", k2i, "ms", 35.0, False, why))
    info = machine() | {
        "gl_renderer": gl_name,
        "reference_ms": round(float(np.median([r[0] for r in refs])), 3),
        "load": round(float(np.median([r[1] for r in refs])), 2),
    }
    return info, figs
