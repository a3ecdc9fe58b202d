"""Live pins (OnlinePlanner.pin_hands): a hand drawn moving for a note keeps it when the
other could only leave for it now, in a rush; with time to spare the plan may still
switch; a pin never drops a note; nothing pinned, nothing changes."""

from __future__ import annotations

from pathlib import Path

from virja.events import Beat, NoteOn
from virja.midifile import read_midi
from virja.plan import plan_notes_with_report
from virja.plan.planner import OnlinePlanner, reveal_time
from virja.plan.types import HandPin, PlannedNote
from virja.routing import Router, route_all
from virja.vocab import Performer

FILL = (
    Path(__file__).resolve().parents[1]
    / "data"
    / "gmd"
    / "drummer1_session1_127_funk-fast_125_fill_4-4.mid"
)

SPB = 0.2  # 300 bpm: a crash's motion starts about 0.1 s before it sounds
CRASH = NoteOn(1.5, 9, 49, 100)
# known late: 80 ms after the crash, a high tom in front.  (A ride there, round 7's case,
# now goes with the crash to the left: since round 8's crossed-arms price a left hand
# crossing to the ride costs more than the right turning back.)
TOM = NoteOn(1.58, 9, 48, 90)


def _notes(path: Path) -> tuple[list[tuple[Performer, NoteOn]], object]:
    session = read_midi(path)
    router = Router.for_session(session)
    notes = [(w, e) for w, e in route_all(session.events, router) if isinstance(e, NoteOn)]
    return notes, session.tempo_map


def _planner() -> OnlinePlanner:
    planner = OnlinePlanner()
    for k in range(12):
        planner.add_beat(Beat(SPB * k, k // 4, k % 4 + 1, 4, 0, int(SPB * 1e6)))
    return planner


def _play(tom_known: float, pin_at: float | None) -> dict[int, PlannedNote]:
    """The crash known at 1.3 s (shown to the right hand, from rest), the tom at
    ``tom_known``; pinned to the right hand at ``pin_at`` (None: never)."""
    planner = _planner()
    planner.add_note("drums", CRASH, now_s=1.3)
    shown = {p.note: p.limb for p in planner.provisional()}
    assert shown == {49: "right_hand"}
    if pin_at is not None:
        planner.pin_hands([HandPin(9, 49, 1.5, "right_hand", 1.3)], now_s=pin_at)
    planner.add_note("drums", TOM, now_s=tom_known)
    out = planner.poll(tom_known) + planner.flush()
    assert planner.report.summary()["dropped"] == 0
    return {p.note: p for p in out}


def test_a_hand_drawn_moving_keeps_its_note_when_the_other_would_rush() -> None:
    """The tom, known 6 ms before the crash's motion starts, makes the crash the left
    hand's (and the tom the right's) when nothing is pinned: the left would leave the
    snare for the crash 110 ms before it sounds.  Pinned, the right hand that was drawn
    moving keeps the crash and goes on to the tom (main fixed the left at the motion's
    start)."""
    start = _play(1.39, None)[49].start
    assert start > 1.39  # the crash's motion has not started when the tom arrives
    free = _play(1.39, None)
    assert free[49].limb == "left_hand" and free[48].limb == "right_hand"
    pinned = _play(1.39, 1.39)
    assert pinned[49].limb == "right_hand"
    assert pinned[48].limb == "right_hand"  # crash -> high tom in 80 ms, the same hand


def test_with_time_to_spare_the_plan_may_still_switch() -> None:
    """The same tom known 0.4 s ahead: the left hand has time to reach the crash, so a
    switch costs only a table step (``shown_hand_penalty``) and the plan is that of
    nothing pinned."""
    assert {n: p.limb for n, p in _play(1.16, 1.16).items()} == {
        n: p.limb for n, p in _play(1.16, None).items()
    }


def test_a_pin_never_drops_a_note() -> None:
    """A GMD fill (drummer1 funk-fast 125: flams, doubles, 35-50 ms snare strokes)
    streamed a beat ahead with every pending note pinned, before each call, to the
    other hand than the plan shows for it (the worst pins there can be): every note
    is still played, as without pins; pins only choose between hands that can."""
    notes, tempo = _notes(FILL)
    planner = OnlinePlanner(tempo=tempo)  # type: ignore[arg-type]
    order = sorted(range(len(notes)), key=lambda i: reveal_time(notes[i][1], tempo, 1.0))  # type: ignore[arg-type]
    out: list[PlannedNote] = []
    flipped = 0
    for i in order:
        performer, note = notes[i]
        now = reveal_time(note, tempo, 1.0)  # type: ignore[arg-type]
        pins = [
            HandPin(
                p.channel,
                p.note,
                p.time,
                "left_hand" if p.limb == "right_hand" else "right_hand",
                now,
            )
            for p in planner.provisional()
            if p.cost == 0.0
        ]
        flipped += planner.pin_hands(pins, now_s=now)
        out.extend(planner.poll(now))
        planner.add_note(performer, note, now_s=now)
    out.extend(planner.flush())
    plain, report = plan_notes_with_report(notes, tempo)  # type: ignore[arg-type]
    assert flipped >= 40
    assert planner.report.summary()["dropped"] == report.summary()["dropped"] == 0
    assert sorted((p.time, p.note) for p in out) == sorted((p.time, p.note) for p in plain)
    assert [p for p in out if p.late] == []


def test_no_pin_no_change() -> None:
    """Pins told and then withdrawn (the whole current set each time): the plan is that
    of a planner never told any."""
    plain = _play(1.39, None)
    planner = _planner()
    planner.add_note("drums", CRASH, now_s=1.3)
    planner.pin_hands([HandPin(9, 49, 1.5, "right_hand", 1.3)], now_s=1.35)
    planner.pin_hands([], now_s=1.36)
    planner.add_note("drums", TOM, now_s=1.39)
    out = {p.note: p for p in planner.poll(1.39) + planner.flush()}
    assert out == plain


def test_a_pin_to_a_hand_that_cannot_play_the_note_gives_way() -> None:
    """The crash pinned to the right hand, which strikes the ride 10 ms before it (too
    soon for any hand: timing.toml): the left plays the crash; a pin is never worth a
    drop."""
    planner = _planner()
    planner.add_note("drums", NoteOn(1.49, 9, 51, 90), now_s=1.0)
    planner.add_note("drums", CRASH, now_s=1.3)
    planner.pin_hands([HandPin(9, 49, 1.5, "right_hand", 1.3)], now_s=1.35)
    out = {p.note: p for p in planner.poll(1.35) + planner.flush()}
    assert out[51].limb == "right_hand" and out[49].limb == "left_hand"
    assert planner.report.summary()["dropped"] == 0
