"""The planner's provisional hands (OnlinePlanner.provisional): looking changes no plan,
and what it shows is the plan the commit then fixes, unless a later note revised it."""

from __future__ import annotations

from pathlib import Path

import pytest

from virja.events import NoteOn
from virja.midifile import read_midi
from virja.plan import plan_notes_with_report
from virja.plan.planner import OnlinePlanner, reveal_time
from virja.plan.types import PlannedNote
from virja.routing import Router, route_all
from virja.vocab import Performer

ROOT = Path(__file__).resolve().parents[2]
FILES = [
    ROOT / "virja" / "demo" / "blues.mid",
    ROOT / "virja" / "demo" / "bebop.mid",
    *sorted((ROOT / "tests" / "data" / "gmd").glob("*.mid"))[:2],
]


def _notes(path: Path) -> tuple[list[tuple[Performer, NoteOn]], object]:
    session = read_midi(path)
    router = Router.for_session(session)
    notes = [(w, e) for w, e in route_all(session.events, router) if isinstance(e, NoteOn)]
    return notes, session.tempo_map


def _key(p: PlannedNote) -> tuple[int, int, float]:
    return (p.channel, p.note, round(p.time, 9))


def _stream_looking(
    notes: list[tuple[Performer, NoteOn]], tempo: object
) -> tuple[list[PlannedNote], dict[tuple[int, int, float], list[PlannedNote]]]:
    """plan_notes_with_report's loop, asking for the provisional hands after every call;
    returns the plan and every provisional note seen, per note."""
    planner = OnlinePlanner(tempo=tempo)  # type: ignore[arg-type]
    order = sorted(range(len(notes)), key=lambda i: reveal_time(notes[i][1], tempo, 1.0))  # type: ignore[arg-type]
    out: list[PlannedNote] = []
    seen: dict[tuple[int, int, float], list[PlannedNote]] = {}

    def look() -> None:
        for p in planner.provisional():
            seen.setdefault(_key(p), []).append(p)

    for i in order:
        performer, note = notes[i]
        now = reveal_time(note, tempo, 1.0)  # type: ignore[arg-type]
        out.extend(planner.poll(now))
        look()
        planner.add_note(performer, note, now_s=now)
        look()
    out.extend(planner.flush())
    return out, seen


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_looking_at_the_provisional_hands_changes_no_plan(path: Path) -> None:
    notes, tempo = _notes(path)
    plan, report = plan_notes_with_report(notes, tempo)  # type: ignore[arg-type]
    looked, seen = _stream_looking(notes, tempo)
    assert looked == plan
    fixed = {_key(p): p for p in plan if p.performer == "drums"}
    assert seen, "no provisional hand was shown"
    hand_notes = [p for p in plan if p.performer == "drums" and p.limb.endswith("hand")]
    shown = [p for p in hand_notes if _key(p) in seen]
    assert len(shown) >= 0.8 * len(hand_notes)
    for key, shows in seen.items():
        last = shows[-1]
        assert last.performer == "drums" and last.limb in ("left_hand", "right_hand")
        final = fixed.get(key)
        if final is not None and final.limb == last.limb:
            # the same hand: the same stroke, timed the same
            assert (final.impact, final.start, final.piece, final.motion) == (
                last.impact,
                last.start,
                last.piece,
                last.motion,
            )
    # the last look before a note is fixed is mostly right
    right = sum(1 for p in shown if seen[_key(p)][-1].limb == p.limb)
    assert right >= 0.9 * len(shown)


def test_provisional_is_empty_without_pending_hand_notes() -> None:
    planner = OnlinePlanner()
    assert planner.provisional() == []
    planner.add_note("drums", NoteOn(2.0, 9, 36, 100), now_s=1.5)  # a kick: a foot's
    assert planner.provisional() == []
    planner.add_note("drums", NoteOn(2.0, 9, 38, 100), now_s=1.5)
    (p,) = planner.provisional()
    assert (p.piece, p.note, p.time) == ("snare", 38, 2.0)
    assert p.limb in ("left_hand", "right_hand")
    assert planner.pending_count == 2  # nothing fixed by looking
    fixed = planner.poll(2.0)
    assert [q.limb for q in fixed if q.note == 38] == [p.limb]
    assert planner.provisional() == []
