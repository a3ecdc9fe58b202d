"""The one builder of a performance: what it gives each kind of input, and that the
commands' settings are parsed once and not written back."""

from __future__ import annotations

import dataclasses
import io
import json
import pickle
from pathlib import Path

import pytest

from virja.input import load_performance_input
from virja.motion.band import BandAnimator
from virja.pipeline import PerformanceSettings, build_performance, perform
from virja.plan.config import load_plan_config
from virja.plan.immediate import immediate_strokes
from virja.plan.planner import plan_notes
from virja.routing import RoutingConfig
from virja.session import run_schedule

DEMO = Path(__file__).resolve().parents[1] / "virja" / "demo" / "blues.mid"


def test_a_file_gets_its_track_names_tempo_map_and_the_tables_as_they_are() -> None:
    settings = PerformanceSettings()
    src = load_performance_input(DEMO, settings.routing)
    log = io.StringIO()
    perf = build_performance(settings, src, plan_log=log)
    assert perf.router.track_names == {t.index: t.name for t in src.midi.tracks}  # type: ignore[union-attr]
    assert perf.planner.config is settings.plan
    assert perf.animator is None
    planned = run_schedule(perf, src.schedule)
    assert len(planned) == src.note_count == 219
    logged = [json.loads(line) for line in log.getvalue().splitlines()]
    assert logged == [p.to_log_json(0.0) for p in planned]  # the plan log is the plan


def test_a_file_plays_every_note_the_offline_planner_plays() -> None:
    """The same notes, to the same players, as `virja plan` plans the file."""
    settings = PerformanceSettings()
    src = load_performance_input(DEMO, settings.routing)
    perf = build_performance(settings, src)
    planned = run_schedule(perf, src.schedule)
    from virja.midifile import read_midi
    from virja.routing import Router, route_all

    session = read_midi(DEMO)
    notes = [
        (who, ev)
        for who, ev in route_all(session.events, Router.for_session(session))
        if type(ev).__name__ == "NoteOn"
    ]
    offline = plan_notes(notes, session.tempo_map)  # type: ignore[arg-type]
    key = lambda p: (p.time, p.performer, p.note)  # noqa: E731
    assert sorted(map(key, planned)) == sorted(map(key, offline))


def test_perform_plays_a_whole_input_and_until_leaves_out_the_later_notes() -> None:
    """`plan`, `motion-report` and the capture tools plan here: the notes render plans,
    an animator that has them all, and with ``until_s`` only the notes up to it."""
    settings = PerformanceSettings()
    src = load_performance_input(DEMO, settings.routing)
    perf, planned = perform(settings, src, animate=True)
    assert isinstance(perf.animator, BandAnimator)
    expected = run_schedule(build_performance(settings, src), src.schedule)
    assert planned == expected and len(planned) == 219
    assert perf.planned == []  # the caller has them; the performance keeps none twice
    _perf, first = perform(settings, src, until_s=4.0)
    assert first and max(p.time for p in first) <= 4.0
    # the same notes (their motions may differ where a later note would have changed them)
    assert [(p.time, p.note) for p in first] == [(p.time, p.note) for p in planned if p.time <= 4.0]


def test_immediate_notes_get_the_shortest_strokes_and_an_animator_when_asked() -> None:
    plan = load_plan_config(None)
    perf = build_performance(PerformanceSettings(plan, immediate=True), animate=True)
    assert perf.planner.config == immediate_strokes(plan)
    assert perf.planner.config != plan
    assert isinstance(perf.animator, BandAnimator)
    assert perf.router.track_names == {}


def test_an_animator_is_one_or_the_other() -> None:
    with pytest.raises(ValueError, match="not both"):
        build_performance(PerformanceSettings(), animate=True, animator=BandAnimator())


def test_the_settings_travel_to_a_worker_whole() -> None:
    routing = RoutingConfig.from_dict({"channels": {"1": "bass"}}, "[routing]")
    settings = PerformanceSettings(load_plan_config(None), routing, immediate=True)
    again = pickle.loads(pickle.dumps(settings))
    assert again == settings and again.tables() == settings.tables()


def test_replay_out_reads_its_options_and_writes_none_back() -> None:
    """Replay renders through render's request without setting render-only options
    (--at, --start, --end, --bvh) on its own namespace."""
    from virja.cli.cmd_render import render_request
    from virja.cli.main import build_parser

    args = build_parser().parse_args(["replay", "x.pcap", "--out", "v.mp4", "--hud"])
    before = dict(vars(args))
    request = render_request(args, PerformanceSettings(), span=False)
    assert vars(args) == before
    assert (request.at, request.start, request.end, request.bvh) == (None, None, None, None)
    assert request.frames.out.kind == "video" and request.frames.hud
    assert request.frames.progress is not None
    assert dataclasses.replace(request.frames, fps=12.0).fps == 12.0


def test_render_reads_its_span_options() -> None:
    from virja.cli.cmd_render import render_request
    from virja.cli.main import build_parser

    args = build_parser().parse_args(["render", "x.mid", "--out", "f.png", "--at", "2.5"])
    request = render_request(args, PerformanceSettings())
    assert request.at == 2.5 and request.frames.out.kind == "png"
    assert request.frames.progress is None  # one frame: no progress bar
    args = build_parser().parse_args(["render", "x.mid", "--out", "v.mp4", "--at", "1"])
    with pytest.raises(Exception, match="--at renders one frame"):
        render_request(args, PerformanceSettings())
