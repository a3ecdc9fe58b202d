"""tools/jack_latency.py --stages: a key's stages add up to its latency, each printed."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

TOOL = Path(__file__).resolve().parents[2] / "tools" / "jack_latency.py"


@pytest.fixture(scope="module")
def tool() -> Iterator[ModuleType]:
    spec = importlib.util.spec_from_file_location("jack_latency_tool", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules[spec.name]


def _stamps(tool: ModuleType, base: float) -> Any:
    # sent, stamped, drained, fed, committed, frame, posed, built, drawn: uneven steps
    marks = [0.0, 0.004, 0.013, 0.0135, 0.0137, 0.0138, 0.020, 0.021, 0.028]
    n = tool.NoteStamps(*(base + m for m in marks[:5]))
    n.impact = base + 0.016
    n.frame, n.posed, n.built, n.drawn = (base + m for m in marks[5:])
    n.lead = 0.014
    return n


def test_stages_are_the_steps_between_stamps_and_add_up_to_the_latency(tool: ModuleType) -> None:
    n = _stamps(tool, 10.0)
    stages = n.stages()
    assert list(stages) == [name for name, _ in tool.STAGES]
    assert stages["jack"] == pytest.approx(0.004)
    assert stages["wait"] == pytest.approx(0.009)
    assert stages["draw"] == pytest.approx(0.007)
    assert sum(stages.values()) == pytest.approx(n.latency)
    assert n.latency == pytest.approx(0.028)


def test_print_stages_names_every_stage_with_its_median(
    tool: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    run = tool.ImpactRun(
        [_stamps(tool, 10.0), _stamps(tool, 11.0)],
        [(True, 0.007, 0.001, 0.006), (False, 0.005, 0.001, 0.006)],
    )
    tool.print_stages(run)
    out = capsys.readouterr().out
    for name, _ in tool.STAGES:
        line = next(ln for ln in out.splitlines() if ln.split()[:1] == [name])
        assert f"{run.notes[0].stages()[name] * 1000.0:.2f}" in line
    assert "frames with a note fed (1): pose 7.00" in out
    assert "frames with no note fed (1): pose 5.00" in out


def test_send_phases_say_where_in_the_loop_turn_each_key_was_sent(tool: ModuleType) -> None:
    a, b = _stamps(tool, 10.0), _stamps(tool, 11.0)
    b.sent = 11.0075  # three quarters into the turn from 11.0 to 11.01
    run = tool.ImpactRun([a, b], [], [9.99, 10.0, 10.02, 11.0, 11.01])
    assert run.send_phases() == pytest.approx([0.0, 0.75])
    # a key sent before the first turn or in the last (unfinished) one has no phase
    late = _stamps(tool, 12.0)
    assert tool.ImpactRun([late], [], [9.0, 11.5]).send_phases() == []


def test_turns_to_drain_measure_the_wait_in_lengths_of_the_turn(tool: ModuleType) -> None:
    a = _stamps(tool, 10.0)  # sent 10.0, drained 10.013
    run = tool.ImpactRun([a], [], [9.99, 10.0, 10.02])
    assert run.turns_to_drain() == pytest.approx([0.65])
