"""PlannedNote's JSON contract (virja.plan.types)."""

from __future__ import annotations

import dataclasses

import pytest

from virja.plan.types import JSON_KEYS, LOG_KEYS, PlannedNote
from virja.vocab import BassPluck, DrumStroke

P = PlannedNote(
    time=1.0,
    performer="drums",
    channel=9,
    note=38,
    velocity=90,
    limb="left_hand",
    piece="snare",
    string=None,
    fret=None,
    motion=DrumStroke("snare", "left_hand"),
    start=0.8,
    impact=1.0,
    cost=0.0,
    late=False,
)


def test_json_keys_are_exactly_the_contract_in_order() -> None:
    assert tuple(P.to_json()) == JSON_KEYS
    assert JSON_KEYS == (
        "time", "performer", "channel", "note", "velocity", "limb", "piece",
        "string", "fret", "motion", "start", "impact", "cost", "late",
    )  # fmt: skip


def test_json_round_trip() -> None:
    assert PlannedNote.from_json(P.to_json()) == P


def test_json_channel_counts_as_musicians_do() -> None:
    """The drums are channel 10 in the plan log, as in every message and option."""
    assert P.to_json()["channel"] == 10


def test_from_json_rejects_missing_keys() -> None:
    data = P.to_json()
    del data["cost"]
    with pytest.raises(ValueError, match="cost"):
        PlannedNote.from_json(data)


# a recording's times inside are Unix seconds; its JSON counts from its first packet
ORIGIN = 1_795_393_538.25
LIVE = PlannedNote(
    **{**P.__dict__, "time": ORIGIN + 1.0, "start": ORIGIN + 0.8, "impact": ORIGIN + 1.0}
)


def test_json_times_count_from_the_inputs_start() -> None:
    data = LIVE.to_json(ORIGIN)
    assert (data["time"], data["start"], data["impact"]) == (1.0, 0.8, 1.0)
    assert tuple(data) == JSON_KEYS  # plan --json: no other key
    assert PlannedNote.from_json(data, ORIGIN) == LIVE


def test_a_midi_files_json_is_its_own_times() -> None:
    """Origin 0: the times as they were (MIDI plans stay byte-identical)."""
    assert P.to_json(0.0) == P.to_json()
    assert P.to_json()["time"] == 1.0 and P.to_json()["start"] == 0.8


def test_the_plan_log_keeps_session_time_in_its_own_field() -> None:
    line = LIVE.to_log_json(ORIGIN)
    assert tuple(line) == LOG_KEYS == (*JSON_KEYS, "session_time")
    assert line["time"] == 1.0 and line["session_time"] == ORIGIN + 1.0
    assert PlannedNote.from_json(line) == LIVE  # session_time gives the origin back


def test_from_json_rejects_an_unknown_key() -> None:
    data = {**P.to_json(), "origin": 3.0}
    with pytest.raises(ValueError, match="unexpected \\['origin'\\]"):
        PlannedNote.from_json(data)


def test_planned_note_of_is_the_same_note_as_the_constructor() -> None:
    """The planner's fast constructor makes an equal note: same fields in the same
    order, equal, same hash and repr, the same JSON; still frozen."""
    for motion, piece, string, fret in (
        (DrumStroke("snare", "left_hand"), "snare", None, None),
        (BassPluck("A", 3, 1), None, "A", 3),
    ):
        args = (1.25, "drums", 9, 38, 100, "left_hand", piece, string, fret, motion, 1.1, 1.25)
        made = PlannedNote(*args, 0.5, False)  # type: ignore[arg-type]
        fast = PlannedNote.of(*args, 0.5, False)  # type: ignore[arg-type]
        assert fast == made and hash(fast) == hash(made) and repr(fast) == repr(made)
        assert list(vars(fast)) == [f.name for f in dataclasses.fields(PlannedNote)]
        assert fast.to_json(1.0) == made.to_json(1.0)
        assert fast != PlannedNote.of(*args, 0.5, True)  # type: ignore[arg-type]
        with pytest.raises(dataclasses.FrozenInstanceError):
            fast.cost = 1.0  # type: ignore[misc]
