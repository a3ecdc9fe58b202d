"""Print the basic motion the scheduler picks for each note of a MIDI file or a recording.

The notes go through the same planner as a live performance: each is revealed
--lookahead-beats beats before it sounds (for a pcap recording of RMCP
traffic: when its datagram was captured), and a motion, once started, is never
changed.  Without --json: an aligned table and a summary (notes per performer,
total cost, dropped and moved notes).  With --json: one JSON object per line
per planned note, the keys of virja.plan.PlannedNote.  Times are seconds from the
start of the input, for a recording from its first packet (as render --at counts).

Example:  virja plan song.mid --lookahead-beats 1
          virja plan session.pcap --json > plan.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from virja.cli.common import (
    add_routing_arguments,
    finite_float,
    performance_settings,
    routing_config,
)
from virja.errors import ConfigError
from virja.input import PerformanceInput, nothing_for_the_band
from virja.plan.types import DROP_REASON_TEXT, PlannedNote, PlanReport
from virja.vocab import PERFORMERS

PCAP_SUFFIXES = {".pcap", ".pcapng", ".cap"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="MIDI file (type 0/1) or pcap/pcapng recording of RMCP")
    parser.add_argument("--json", action="store_true", help="one JSON object per planned note")
    parser.add_argument(
        "--lookahead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="MIDI files: each note is known B beats before it sounds (default 1)",
    )
    parser.add_argument(
        "--port", type=int, default=None, metavar="N", help="pcap: the RMCP UDP port"
    )
    add_routing_arguments(parser)


def _plan(
    src: PerformanceInput, args: argparse.Namespace, doc: dict[str, Any]
) -> tuple[list[PlannedNote], PlanReport]:
    """The input through the pipeline every command builds (:func:`virja.pipeline.perform`):
    a MIDI file's events (notes, note-offs, its BEAT messages) each revealed
    --lookahead-beats ahead, a recording's on its recorded clock, planned as the daemon would."""
    from virja.pipeline import perform

    perf, planned = perform(performance_settings(args, doc), src)
    return planned, perf.planner.report


def _input(path: Path, args: argparse.Namespace, doc: dict[str, Any]) -> PerformanceInput:
    from virja.input import load_performance_input

    routing = routing_config(args, doc)
    return load_performance_input(
        path, routing, lookahead_beats=args.lookahead_beats, port=args.port
    )


def _fmt(value: object) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.3f}"
    return str(value)


def _table(planned: list[PlannedNote], origin_s: float = 0.0) -> list[str]:
    """The plan as a table, times in seconds from ``origin_s`` (a recording's start)."""
    cols = ["time", "performer", "note", "limb", "motion", "start", "impact", "cost", "late"]

    def cell(p: PlannedNote, c: str) -> str:
        if c == "late":
            return "LATE" if p.late else ""
        value = getattr(p, c)
        return _fmt(value - origin_s if c in ("time", "start", "impact") else value)

    rows = [[cell(p, c) for c in cols]
            for p in sorted(planned, key=lambda p: (p.time, p.performer, p.start))]  # fmt: skip
    widths = [max([len(c)] + [len(r[i]) for r in rows]) for i, c in enumerate(cols)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(cols, widths, strict=True)).rstrip()]
    lines += ["  ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    return lines


def _summary(planned: list[PlannedNote], report: PlanReport, origin_s: float = 0.0) -> list[str]:
    per = Counter(p.performer for p in planned)
    cost: dict[str, float] = {"bass": 0.0, "drums": 0.0}
    for p in planned:
        cost[p.performer] += p.cost
    lines = [
        f"{who}: {per[who]} notes planned, total cost {cost[who]:g}, "
        f"{sum(1 for p in planned if p.performer == who and p.late)} late"
        for who in PERFORMERS
    ]
    drops = Counter((d.performer, d.reason) for d in report.dropped)
    lines.append(
        f"dropped: {len(report.dropped)}"
        + "".join(
            f"; {who} {reason}: {n} ({DROP_REASON_TEXT.get(reason, reason)})"
            for (who, reason), n in sorted(drops.items())
        )
    )
    if report.unplayed:
        lines.append(
            "routed to nobody (no kit drummer plays them): "
            + "; ".join(f"{name} {n}" for name, n in report.unplayed)
        )
    lines.append(
        f"moved by octaves: {len(report.moved)}"
        + "".join(f"; {m.note.note} -> {m.played_note} at {m.note.time_s - origin_s:.3f} s"
                  for m in report.moved[:10])
        + (" ..." if len(report.moved) > 10 else "")
    )  # fmt: skip
    return lines


def run(args: argparse.Namespace) -> int:
    from virja.config import load_config

    if args.lookahead_beats < 0:
        raise ConfigError("--lookahead-beats must be >= 0")
    path = Path(args.input)
    doc = load_config(args.config)
    src = _input(path, args, doc)
    # where each track went, and hints when the band got nothing: on stderr with --json
    for line in src.report:
        print(line, file=sys.stderr if args.json else sys.stdout)
    if src.note_count == 0:
        raise nothing_for_the_band(path, src.report)
    planned, report = _plan(src, args, doc)
    if args.json:
        try:
            for p in planned:
                print(json.dumps(p.to_json(src.start_s)))
        except BrokenPipeError:  # `virja plan --json ... | head`
            return 0
        return 0
    if src.start_s:
        print(
            f"times: seconds from the recording's start (its first packet, session time "
            f"{src.start_s:.6f} s; a plan log's session_time gives each note's)"
        )
    for line in _table(planned, src.start_s):
        print(line)
    print()
    for line in _summary(planned, report, src.start_s):
        print(line)
    return 0
