"""PlannedNote's JSON contract (virja.plan.types)."""

from __future__ import annotations

import pytest

from virja.plan.types import JSON_KEYS, PlannedNote
from virja.vocab import DrumStroke

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
