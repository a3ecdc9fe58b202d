"""``export_file``: one input (MIDI file or pcap) to glTF, BVH and MusicXML, no GL.

The input goes through the same path as a performance (:mod:`virja.input`
reveal schedule, :class:`virja.session.Performance`: router, online planner,
animator); the clock jumps from reveal to reveal (:func:`virja.session.run_schedule`)
since nothing is drawn, and the band is then sampled at exact ``1/fps`` steps
in one batch (:meth:`virja.motion.band.BandAnimator.local_rotations_many`).
Every output is checked (its type, its folder writable) before the input is read.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from virja.config import load_config, section
from virja.errors import ConfigError, InputFileError
from virja.events import Beat
from virja.export.gltf import Sampled, write_gltf
from virja.export.musicxml import Score, write_musicxml
from virja.geometry import GEOMETRY
from virja.input import PerformanceInput, load_performance_input, nothing_for_the_band
from virja.motion.band import FIGURES, BandAnimator
from virja.motion.export import performance_to_bvh
from virja.pipeline import PerformanceSettings, build_performance
from virja.plan.config import PlanConfig, load_plan_config
from virja.plan.types import PlannedNote
from virja.routing import RoutingConfig
from virja.session import run_schedule
from virja.vocab import CYMBAL_PIECES

GLTF_SUFFIXES = (".glb", ".gltf")
MAX_FPS = 240.0


@dataclass
class Export:
    """What :func:`export_file` did: the files written and what was planned."""

    outputs: list[Path]
    planned: list[PlannedNote]
    t0_s: float
    t1_s: float
    frames: int
    report: list[str]


def _check_out(path: Path, flag: str, suffixes: tuple[str, ...]) -> Path:
    if path.suffix.lower() not in suffixes:
        raise ConfigError(f"{flag} {path}: the file name must end in {' or '.join(suffixes)}")
    if path.is_dir():
        raise ConfigError(f"{flag} {path}: is a folder; give a file name")
    folder = path.parent
    if not folder.is_dir():
        raise ConfigError(f"{flag} {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise ConfigError(f"{flag} {path}: the folder {folder} is not writable")
    if path.exists() and not os.access(path, os.W_OK):
        raise ConfigError(f"{flag} {path}: the file exists and is not writable")
    return path


def check_request(
    input_path: Path,
    gltf: Path | None,
    bvh: Path | None,
    musicxml: Path | None,
    fps: float,
    start_s: float | None,
    end_s: float | None,
) -> None:
    """Refuse a bad request with a one-line error, before any work."""
    if gltf is None and bvh is None and musicxml is None:
        raise ConfigError("nothing to export: give --gltf, --bvh and/or --musicxml")
    if not (np.isfinite(fps) and 0 < fps <= MAX_FPS):
        raise ConfigError(f"--fps must be in (0, {MAX_FPS:g}], got {fps}")
    if start_s is not None and end_s is not None and end_s < start_s:
        raise ConfigError(f"--end {end_s} is before --start {start_s}")
    if not input_path.exists():
        raise InputFileError(input_path, "no such file")
    if not input_path.is_file():
        raise InputFileError(input_path, "not a file")
    if not os.access(input_path, os.R_OK):
        raise InputFileError(input_path, "not readable")
    if gltf is not None:
        _check_out(gltf, "--gltf", GLTF_SUFFIXES)
    if bvh is not None:
        _check_out(bvh, "--bvh", (".bvh",))
        stem = bvh.with_suffix("")
        for fig in FIGURES:
            _check_out(stem.parent / f"{stem.name}_{fig}.bvh", "--bvh", (".bvh",))
    if musicxml is not None:
        _check_out(musicxml, "--musicxml", (".musicxml", ".xml"))


def sample(
    animator: BandAnimator,
    times: np.ndarray,
    local: np.ndarray | None = None,
    origin_s: float = 0.0,
) -> Sampled:
    """The band at ``times`` (sorted), as arrays for the glTF writer (``local``: the
    animator's ``local_rotations_many(times)`` if the caller has it; ``origin_s``: the
    session time of the input's start)."""
    if local is None:
        local = animator.local_rotations_many(times)
    poses = animator.poses(times, local)
    kick = GEOMETRY.kit.kick_pedal
    up_y, down_y = float(kick.toe_point(False)[1]), float(kick.toe_point(True)[1])
    toe = np.array([p.drums.position("RightToe")[1] for p in poses])
    hh = GEOMETRY.kit.hihat_pedal  # its footboard follows the left foot; the cymbals the notes
    hh_up, hh_dn = float(hh.toe_point(False)[1]), float(hh.toe_point(True)[1])
    ltoe = np.array([p.drums.position("LeftToe")[1] for p in poses])
    return Sampled(
        times=np.asarray(times, dtype=np.float64),
        local=local,
        roots=np.stack([animator.idle[f].root_positions[0] for f in FIGURES]),
        cymbal_swing={
            c: np.array([p.cymbal_swing.get(c, 0.0) for p in poses]) for c in CYMBAL_PIECES
        },
        hihat_open=np.array([p.hihat_open for p in poses]),
        kick_down=np.clip((up_y - toe) / max(up_y - down_y, 1e-6), 0.0, 1.0),
        hihat_down=np.clip((hh_up - ltoe) / max(hh_up - hh_dn, 1e-6), 0.0, 1.0),
        string_vibration={
            s: np.array([p.string_vibration.get(s, 0.0) for p in poses])
            for s in animator.bass_strings  # the tuning's strings, drawn and vibrating
        },
        origin_s=origin_s,
        bass_transform=np.array([p.bass_transform for p in poses]),
    )


def export_file(
    input_path: str | Path,
    *,
    gltf: str | Path | None = None,
    bvh: str | Path | None = None,
    musicxml: str | Path | None = None,
    fps: float = 30.0,
    start_s: float | None = None,
    end_s: float | None = None,
    config: str | Path | None = None,
    routing: RoutingConfig | None = None,
    lookahead_beats: float = 1.0,
) -> list[Path]:
    """Export one input; returns the files written.  See :func:`export_performance`."""
    return export_performance(
        input_path,
        gltf=gltf,
        bvh=bvh,
        musicxml=musicxml,
        fps=fps,
        start_s=start_s,
        end_s=end_s,
        config=config,
        routing=routing,
        lookahead_beats=lookahead_beats,
    ).outputs


def export_performance(
    input_path: str | Path,
    *,
    gltf: str | Path | None = None,
    bvh: str | Path | None = None,
    musicxml: str | Path | None = None,
    fps: float = 30.0,
    start_s: float | None = None,
    end_s: float | None = None,
    config: str | Path | None = None,
    routing: RoutingConfig | None = None,
    lookahead_beats: float = 1.0,
    plan_config: PlanConfig | None = None,
) -> Export:
    """Plan and animate a MIDI file or pcap recording and write the requested formats.

    - ``gltf``: ``.glb`` or ``.gltf`` (+ ``.bin``), both figures and the instruments animated;
    - ``bvh``: ``NAME.bvh`` writes ``NAME_drums.bvh`` and ``NAME_bass.bvh``;
    - ``musicxml``: ``.musicxml`` (MusicXML 4.0, uncompressed);
    - ``fps``: motion sampling rate; ``start_s``/``end_s``: the span in seconds from
      the input's start, a recording's first packet (default: from the first motion to
      the last note plus 1.5 s);
    - ``config``: a virja TOML file ([routing], [plan]); ``routing`` overrides its [routing]
      and ``plan_config`` (already parsed, as `virja batch` hands it to its workers) its [plan].

    Raises :class:`~virja.errors.ConfigError` / :class:`~virja.errors.InputFileError`
    (one-line messages) for a bad request before any work is done.
    """
    src_path = Path(input_path)
    g = Path(gltf) if gltf is not None else None
    b = Path(bvh) if bvh is not None else None
    m = Path(musicxml) if musicxml is not None else None
    check_request(src_path, g, b, m, fps, start_s, end_s)
    doc = load_config(str(config)) if config is not None else {}
    if routing is None:
        routing = RoutingConfig.from_dict(section(doc, "routing"), f"{config} [routing]")
    if plan_config is None:
        plan_config = load_plan_config(config)
    src = load_performance_input(src_path, routing, lookahead_beats=lookahead_beats)
    if src.note_count == 0:
        raise nothing_for_the_band(src_path, src.report)
    # notation needs only the plan: MusicXML alone skips the animator (so a tuning the
    # bassist's clips do not cover yet still gets its tablature); a recording's RTP-MIDI
    # notes were played at once, as live: the pipeline gives them the shortest strokes
    perf = build_performance(PerformanceSettings(plan_config, routing), src, animate=bool(g or b))
    plan_config = perf.planner.config  # the tables it planned with (the score's too)
    animator = perf.animator
    assert animator is None or isinstance(animator, BandAnimator)
    planned = run_schedule(perf, src.schedule)
    t0, t1 = src.default_span()
    # start_s/end_s count from the input's start (a recording's first packet), as render's
    t0 = t0 if start_s is None else src.start_s + start_s
    t1 = t1 if end_s is None else src.start_s + end_s
    if t1 < t0:
        raise ConfigError(
            f"nothing to export: end {t1 - src.start_s:.3f} s is before start "
            f"{t0 - src.start_s:.3f} s"
        )
    n = int(np.floor((t1 - t0) * fps + 1e-9)) + 1
    times = t0 + np.arange(n) / fps
    outputs: list[Path] = []
    if animator is not None:
        local = animator.local_rotations_many(times)
        if g is not None:
            outputs += write_gltf(sample(animator, times, local, src.start_s), g)
        if b is not None:
            outputs += performance_to_bvh(animator, t0, t1, fps, b, local)
    if m is not None:
        outputs.append(write_musicxml(score_of(src, planned, plan_config, t0, t1), m))
    return Export(outputs, planned, t0, t1, n, list(src.report))


def score_of(
    src: PerformanceInput, planned: list[PlannedNote], config: PlanConfig, t0: float, t1: float
) -> Score:
    """The notes sounding in [t0, t1] with what the input says of tempo and metre."""
    beats = [r.event for r in src.schedule if isinstance(r.event, Beat)]
    notes = [p for p in planned if t0 <= p.time <= t1]
    return Score.build(
        notes,
        config,
        tempo=src.tempo,
        beats=beats,
        time_signatures=list(src.midi.time_signatures) if src.midi is not None else [],
        title=src.path.stem,
        origin_s=src.start_s,  # no BEATs in a recording: its beats count from its start
    )
