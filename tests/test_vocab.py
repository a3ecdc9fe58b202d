"""The shared names and the motion keys (virja.vocab)."""

from __future__ import annotations

import itertools
import json
import re
from pathlib import Path

import pytest

from virja.plan.types import PlannedNote
from virja.resources import motions_dir
from virja.vocab import (
    ALL_BASS_STRINGS,
    FEET,
    FOOT_KINDS,
    FRET_OPEN_CLIP,
    HAND_PIECES,
    HANDS,
    LIMBS,
    PERFORMER_LIMBS,
    PERFORMERS,
    PIECES,
    BassPluck,
    DrumStroke,
    MotionKey,
    as_bass_string,
    as_limb,
    as_performer,
    as_piece,
    idle_clip,
)

MAX_FRET = 20  # the frets tools/author_motions.py writes holds for


def all_keys() -> list[MotionKey]:
    keys: list[MotionKey] = [DrumStroke(p, h) for p in HAND_PIECES for h in HANDS]
    keys += [DrumStroke(p, f) for p, f in FOOT_KINDS]
    for s, fret in itertools.product(ALL_BASS_STRINGS, range(MAX_FRET + 1)):
        keys += [BassPluck(s, fret), BassPluck(s, fret, max(fret, 1)), BassPluck(s, fret, 12)]
    return list(dict.fromkeys(keys))  # once each


def test_names_are_todays_spellings() -> None:
    assert DrumStroke("snare", "left_hand").name == "snare_left_hand"
    assert DrumStroke("tom_floor", "right_hand").name == "tom_floor_right_hand"
    assert DrumStroke("hihat", "left_foot").name == "hihat_left_foot"
    assert BassPluck("A", 3).name == "pluck_A_fret3"
    assert BassPluck("E", 0, 2).name == "pluck_E_fret0_pos2"
    assert str(BassPluck("C", 12, 10)) == "pluck_C_fret12_pos10"


def test_clip_names_come_from_the_key() -> None:
    assert DrumStroke("ride", "right_hand").clips == ("ride_right_hand",)
    assert BassPluck("A", 3, 2).clips == ("pluck_A", "fret_A_3")
    assert BassPluck("D", 0, 5).hold_clip == FRET_OPEN_CLIP == "fret_open"
    assert [idle_clip(p) for p in PERFORMERS] == ["idle_bass", "idle_drums"]


def test_parse_reads_every_name_back() -> None:
    keys = all_keys()
    assert len({k.name for k in keys}) == len(keys)
    for k in keys:
        assert MotionKey.parse(k.name) == k
        assert k.performer in PERFORMERS


@pytest.mark.parametrize(
    "bad",
    [
        "",
        "snare",
        "snare_left_knee",
        "gong_left_hand",
        "pluck_X_fret3",
        "pluck_A_fret",
        "pluck_A_fret3_pos",
        "fret_A_3",
    ],
)
def test_parse_rejects_other_text_in_one_line(bad: str) -> None:
    with pytest.raises(ValueError, match="not a motion name") as err:
        MotionKey.parse(bad)
    assert "\n" not in str(err.value)


def test_every_key_names_clips_the_library_has() -> None:
    """The planner's keys and the authored clips agree: each clip a key names is a file."""
    have = {p.stem for p in motions_dir().glob("*/*.bvh")}
    for k in all_keys():
        missing = set(k.clips) - have
        assert not missing, (k.name, missing)
    assert {idle_clip(p) for p in PERFORMERS} <= have


def test_the_sets_agree() -> None:
    assert set(HANDS) | set(FEET) == set(LIMBS)
    assert set(HAND_PIECES) < set(PIECES)
    assert {p for p, _ in FOOT_KINDS} <= set(PIECES)
    assert PERFORMER_LIMBS["drums"] == LIMBS and PERFORMER_LIMBS["bass"] == HANDS


def test_checked_conversions() -> None:
    assert as_limb("left_foot") == "left_foot"
    assert as_piece("crash") == "crash"
    assert as_bass_string("B") == "B"
    assert as_performer("bass") == "bass"
    for f, bad in (
        (as_limb, "tail"),
        (as_piece, "gong"),
        (as_bass_string, "F"),
        (as_performer, "sax"),
    ):
        with pytest.raises(ValueError, match=repr(bad)):
            f(bad)


def test_a_planned_note_writes_its_key_as_the_name() -> None:
    p = PlannedNote(
        time=1.0,
        performer="bass",
        channel=0,
        note=36,
        velocity=90,
        limb="right_hand",
        piece=None,
        string="A",
        fret=3,
        motion=BassPluck("A", 3, 2),
        start=0.8,
        impact=1.0,
        cost=0.0,
        late=False,
    )
    line = json.dumps(p.to_json())
    assert '"motion": "pluck_A_fret3_pos2"' in line
    assert PlannedNote.from_json(json.loads(line)) == p
    bad = {**p.to_json(), "motion": "pluck_A"}
    with pytest.raises(ValueError, match="not a motion name"):
        PlannedNote.from_json(bad)


# clip or motion names spelled from pieces, limbs, strings or frets
SPELLED = re.compile(r"""f["'](pluck|fret|idle)_\{|\{piece\}_\{|_\{(limb|hand|side)\}["']""")


def test_no_module_spells_a_clip_name() -> None:
    """Only virja/vocab.py turns pieces, limbs, strings and frets into motion or clip names."""
    root = Path(__file__).resolve().parent.parent
    files = [*root.joinpath("virja").rglob("*.py"), *root.joinpath("tools").glob("*.py")]
    found = [
        f"{f.relative_to(root)}:{i}: {line.strip()}"
        for f in files
        if f.name != "vocab.py"
        for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1)
        if SPELLED.search(line)
    ]
    assert not found, "\n".join(found)
    assert SPELLED.search('name = f"pluck_{s}"') and SPELLED.search('f"{piece}_{limb}"')
