"""The online planner (virja.plan.planner): streaming, fixing, reporting."""

from __future__ import annotations

import itertools
import random
from collections import Counter

import pytest

from virja.events import Beat, NoteOn
from virja.plan import OnlinePlanner, PlanConfig, plan_notes, plan_notes_with_report, reveal_time
from virja.plan import planner as planner_mod
from virja.plan.timing import anticipation_s
from virja.tempo import ConstantTempo, TempoMap
from virja.vocab import Performer

T120 = ConstantTempo(0.5)
DRUMS = (36, 38, 38, 42, 42, 46, 51, 49, 45, 48, 43, 44, 37)


def random_performance(seed: int, n: int = 60) -> list[tuple[Performer, NoteOn]]:
    rng = random.Random(seed)
    out: list[tuple[Performer, NoteOn]] = []
    for _ in range(n):
        t = rng.randrange(0, 64) * 0.0625
        if rng.random() < 0.4:
            out.append(("bass", NoteOn(t, 0, rng.randint(20, 75), rng.randint(1, 127))))
        else:
            out.append(("drums", NoteOn(t, 9, rng.choice(DRUMS), rng.randint(1, 127))))
    return out


def _key(performer: str, time: float, channel: int, note: int, velocity: int) -> tuple:  # type: ignore[type-arg]
    return (performer, round(time, 6), channel, note, velocity)


def test_every_note_is_planned_or_reported_exactly_once() -> None:
    for seed in range(8):
        notes = random_performance(seed)
        planned, report = plan_notes_with_report(notes, T120)
        moved = {id(m.note): m.played_note for m in report.moved}
        want = Counter(
            _key(p, n.time_s, n.channel, moved.get(id(n), n.note), n.velocity) for p, n in notes
        )
        got = Counter(_key(p.performer, p.time, p.channel, p.note, p.velocity) for p in planned)
        got.update(
            _key(d.performer, d.note.time_s, d.note.channel, moved.get(id(d.note), d.note.note),
                 d.note.velocity)
            for d in report.dropped
        )  # fmt: skip
        assert got == want


def test_no_limb_is_in_two_places_at_once(config: PlanConfig) -> None:
    for seed in range(8):
        planned = plan_notes(random_performance(seed, 80), T120)
        by_limb: dict[tuple[str, str], list] = {}  # type: ignore[type-arg]
        for p in planned:
            by_limb.setdefault((p.performer, p.limb), []).append(p)
        for (performer, _limb), ps in by_limb.items():
            ps.sort(key=lambda p: p.time)
            for a, b in itertools.pairwise(ps):
                if abs(a.time - b.time) <= 0.001:
                    if performer == "drums":
                        assert a.motion == b.motion and a.impact == b.impact
                    else:
                        assert a.string != b.string or a.fret == b.fret
                elif performer == "drums" and not (a.late or b.late):
                    kind = {"kick": "kick"}.get(b.piece or "", b.piece or "")
                    if b.limb == "left_foot":
                        kind = "hihat_pedal"
                    gap = config.timing.get(kind).min_interval_s
                    if b.limb in ("left_hand", "right_hand"):  # at a stretch at most
                        gap = config.timing.stretch_gap(a.piece, b.piece or "")
                    dt = b.time - a.time
                    # or a rebound of the stroke before on the same piece (a buzz, a
                    # pad's double trigger) within the grouping window
                    rebound = a.piece == b.piece and (
                        dt <= planner_mod.HAND_WINDOW_S + 1e-9
                        or (
                            b.velocity < planner_mod.BUZZ_VELOCITY
                            and dt <= max(planner_mod.BUZZ_S, gap) + 0.002
                        )
                    )
                    assert rebound or dt >= gap - 1e-9


def test_impact_equals_time_for_notes_that_are_not_late() -> None:
    planned = plan_notes(random_performance(3, 100), T120)
    assert planned
    for p in planned:
        assert p.late or abs(p.impact - p.time) <= 0.001
        assert p.start < p.impact


def test_notes_at_time_zero_of_a_file_start_before_zero() -> None:
    planned = plan_notes(
        [("drums", NoteOn(0.0, 9, 38, 100)), ("bass", NoteOn(0.0, 0, 40, 90))], T120
    )
    assert all(p.start < 0 and not p.late for p in planned)


def test_plan_notes_equals_a_manual_streaming_simulation_with_frame_polls() -> None:
    for seed in range(5):
        notes = random_performance(seed, 70)
        expected = plan_notes(notes, T120, lookahead_beats=1.0)
        planner = OnlinePlanner(tempo=T120)
        arrivals = sorted(((reveal_time(n, T120, 1.0), p, n) for p, n in notes), key=lambda a: a[0])
        got = []
        frame = -1.0
        for now, performer, note in arrivals:
            while frame < now:  # a renderer polling at 30 fps between arrivals
                got.extend(planner.poll(frame))
                frame += 1 / 30
            planner.add_note(performer, note, now_s=now)
        got.extend(planner.flush())
        assert sorted(got, key=lambda p: (p.start, p.time, p.limb, p.note)) == sorted(
            expected, key=lambda p: (p.start, p.time, p.limb, p.note)
        )


def test_poll_returns_only_started_motions_in_start_order_and_each_once() -> None:
    notes = random_performance(11, 80)
    planner = OnlinePlanner(tempo=T120)
    arrivals = sorted(((reveal_time(n, T120, 1.0), p, n) for p, n in notes), key=lambda a: a[0])
    seen: list = []  # type: ignore[type-arg]
    for now, performer, note in arrivals:
        out = planner.poll(now)
        assert all(p.start <= now for p in out)
        assert [p.start for p in out] == sorted(p.start for p in out)
        seen.extend(out)
        planner.add_note(performer, note, now_s=now)
    seen.extend(planner.flush())
    assert len({id(p) for p in seen}) == len(seen)
    assert planner.pending_count == 0


def test_replanning_never_changes_a_started_motion() -> None:
    planner = OnlinePlanner(tempo=T120)
    planner.add_note("drums", NoteOn(0.0, 9, 38, 100), now_s=-0.5)
    first = planner.poll(-0.15)
    assert [p.motion.name for p in first] == ["snare_left_hand"]
    # a ride at the same instant arrives after the snare stroke has started: the
    # snare keeps its hand, the ride gets the free one
    planner.add_note("drums", NoteOn(0.0, 9, 51, 100), now_s=-0.1)
    planner.add_note("drums", NoteOn(0.0, 9, 38, 100), now_s=-0.1)  # doubled snare
    rest = planner.flush()
    assert {p.motion.name for p in rest} == {"ride_right_hand", "snare_left_hand"}
    twin = next(p for p in rest if p.piece == "snare")
    assert (twin.start, twin.impact, twin.cost) == (first[0].start, first[0].impact, 0.0)


def test_unstarted_notes_are_replanned_when_new_notes_arrive() -> None:
    planner = OnlinePlanner(tempo=T120)
    for i in range(4):
        planner.add_note("drums", NoteOn(1.0 + i * 0.125, 9, 38, 100), now_s=0.0)
    for i in range(2):
        planner.add_note("drums", NoteOn(1.0 + i * 0.25, 9, 51, 100), now_s=0.1)
    out = planner.flush()
    snare = {p.limb for p in out if p.piece == "snare"}
    ride = {p.limb for p in out if p.piece == "ride"}
    assert snare == {"left_hand"} and ride == {"right_hand"}


def test_paper_experiments_through_plan_notes() -> None:
    snare = [("drums", NoteOn(i * 0.125, 9, 38, 100)) for i in range(4)]
    out = plan_notes(snare, T120, lookahead_beats=2.0)
    assert [p.limb for p in sorted(out, key=lambda p: p.time)] == [
        "left_hand", "right_hand", "left_hand", "right_hand",
    ]  # fmt: skip
    assert sum(p.cost for p in out) == 2.0
    ride = [("drums", NoteOn(i * 0.25, 9, 51, 100)) for i in range(2)]
    out = plan_notes(snare + ride, T120, lookahead_beats=2.0)
    assert all(p.limb == "left_hand" for p in out if p.piece == "snare")
    assert all(p.limb == "right_hand" for p in out if p.piece == "ride")


def test_bass_paper_example_through_plan_notes() -> None:
    out = plan_notes([("bass", NoteOn(0.0, 0, 29, 100)), ("bass", NoteOn(0.5, 0, 34, 100))], T120)
    assert [(p.string, p.fret, p.motion.name, p.cost) for p in out] == [
        ("E", 1, "pluck_E_fret1_pos1", 0.0),
        ("A", 1, "pluck_A_fret1_pos1", 1.0),
    ]


def test_tempo_scales_anticipation(config: PlanConfig) -> None:
    for bpm in (60, 120, 300):
        tempo = ConstantTempo(60 / bpm)
        out = plan_notes([("drums", NoteOn(4.0, 9, 38, 100))], tempo)
        expected = anticipation_s(config.timing, "snare", 60 / bpm)
        assert out[0].start == pytest.approx(4.0 - expected)
        assert not out[0].late
    fast = plan_notes([("drums", NoteOn(4.0, 9, 38, 100))], ConstantTempo(0.2))[0]
    slow = plan_notes([("drums", NoteOn(4.0, 9, 38, 100))], ConstantTempo(1.0))[0]
    assert fast.impact - fast.start < slow.impact - slow.start


def test_beats_set_the_tempo_of_a_live_planner(config: PlanConfig) -> None:
    planner = OnlinePlanner()
    planner.add_beat(Beat(0.0, 0, 1, 4, 0, 200_000))  # 300 bpm
    planner.add_note("drums", NoteOn(1.0, 9, 38, 100), now_s=0.0)
    (p,) = planner.flush()
    assert p.start == pytest.approx(1.0 - anticipation_s(config.timing, "snare", 0.2))


def test_tempo_map_changes_the_reveal_time() -> None:
    tm = TempoMap([(0.0, 0.5), (2.0, 0.25)])
    assert reveal_time(NoteOn(3.0, 9, 38, 1), tm, 1.0) == pytest.approx(2.75)


def test_late_notes_are_compressed_and_marked() -> None:
    out = plan_notes([("drums", NoteOn(0.0, 9, 38, 100))], T120, lookahead_beats=0.0)
    (p,) = out
    assert p.late and p.start == 0.0 and p.impact > 0.0


def test_out_of_range_bass_notes_are_moved_by_octaves_and_reported() -> None:
    notes = [("bass", NoteOn(0.0, 0, 16, 100)), ("bass", NoteOn(0.5, 0, 80, 100))]
    planned, report = plan_notes_with_report(notes, T120)
    assert [p.note for p in planned] == [28, 56]
    assert [(m.note.note, m.played_note) for m in report.moved] == [(16, 28), (80, 56)]
    assert report.summary()["moved"] == 2


def test_bass_double_stop_and_dropped_third_note() -> None:
    chord = [("bass", NoteOn(0.0, 0, n, 100)) for n in (45, 40, 33)]
    planned, report = plan_notes_with_report(chord, T120)
    assert sorted(p.note for p in planned) == [40, 45]
    assert len({p.string for p in planned}) == 2
    assert [(d.note.note, d.reason) for d in report.dropped] == [(33, "no_double_stop")]


def test_more_hand_notes_than_hands_keep_the_most_important() -> None:
    notes = [("drums", NoteOn(0.0, 9, n, 100)) for n in (49, 42, 38, 45)]
    planned, report = plan_notes_with_report(notes, T120)
    # the hi-hat goes to the left foot (a chick), the hands keep snare and tom
    assert {(p.piece, p.limb) for p in planned} == {
        ("snare", "left_hand"),
        ("tom_low", "right_hand"),
        ("hihat", "left_foot"),
    }
    assert sorted(d.note.note for d in report.dropped) == [49]
    assert {d.reason for d in report.dropped} == {"three_pieces_at_once"}


def test_doubled_drum_note_shares_one_stroke() -> None:
    notes = [("drums", NoteOn(0.0, 9, 38, 100)), ("drums", NoteOn(0.0005, 9, 38, 80))]
    a, b = plan_notes(notes, T120)
    assert (a.limb, a.motion, a.start, a.impact) == (b.limb, b.motion, b.start, b.impact)
    assert b.cost == 0.0


def test_feet_play_kick_and_hihat_pedal() -> None:
    notes = [("drums", NoteOn(0.0, 9, 36, 100)), ("drums", NoteOn(0.0, 9, 44, 100))]
    out = {p.motion.name: p.limb for p in plan_notes(notes, T120)}
    assert out == {"kick_right_foot": "right_foot", "hihat_left_foot": "left_foot"}


def test_unmapped_drum_note_is_reported() -> None:
    planned, report = plan_notes_with_report([("drums", NoteOn(0.0, 9, 20, 100))], T120)
    assert planned == [] and [d.reason for d in report.dropped] == ["unmapped"]


def test_a_long_session_keeps_bounded_tempo_and_report_history() -> None:
    """Hours of beats and drops must not grow the planner without bound."""
    from virja.events import Beat
    from virja.plan import planner as planner_mod

    p = planner_mod.OnlinePlanner()
    for i in range(planner_mod.MAX_BEATS_KEPT + 500):
        p.add_beat(Beat(i * 0.5, i // 4, 1 + i % 4, 4, 0, 500_000))
    assert len(p._track.times) == planner_mod.MAX_BEATS_KEPT
    assert p.seconds_per_beat_at(1e9) == 0.5


def test_a_planner_no_longer_used_is_freed_without_the_cyclic_collector() -> None:
    """No reference cycle through the chains (their tempo look-up holds the tempo track,
    not the planner): dropping the last reference frees the planner and its notes at
    once, so planning makes no garbage for the cyclic collector to pause on."""
    import gc
    import weakref

    planner = OnlinePlanner(tempo=T120)
    for i in range(8):
        planner.add_note("bass", NoteOn(1.0 + 0.25 * i, 0, 40 + i, 90), now_s=0.0)
        planner.add_note("drums", NoteOn(1.0 + 0.25 * i, 9, 38, 90), now_s=0.0)
    planner.poll(1.5)
    assert planner.flush()
    ref = weakref.ref(planner)
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        del planner
        assert ref() is None
    finally:
        if was_enabled:
            gc.enable()


def test_each_note_goes_to_its_chain_and_an_unknown_performer_is_refused() -> None:
    planner = OnlinePlanner(tempo=T120)
    planner.add_note("bass", NoteOn(1.0, 0, 40, 90), now_s=0.0)
    planner.add_note("drums", NoteOn(1.0, 9, 36, 90), now_s=0.0)  # kick: right foot
    planner.add_note("drums", NoteOn(1.0, 9, 44, 90), now_s=0.0)  # pedal hi-hat: left foot
    planner.add_note("drums", NoteOn(1.0, 9, 38, 90), now_s=0.0)  # snare: a hand
    planner.add_note("drums", NoteOn(1.0, 9, 20, 90), now_s=0.0)  # not in the kit map
    assert planner.pending_count == 4
    assert planner.next_deadline() == min(p.start for p in planner.flush())
    with pytest.raises(ValueError, match="unknown performer"):
        planner.add_note("piano", NoteOn(1.0, 0, 60, 90), now_s=0.0)  # type: ignore[arg-type]
    out = plan_notes(
        [
            ("drums", NoteOn(1.0, 9, 36, 90)),
            ("drums", NoteOn(1.0, 9, 44, 90)),
            ("drums", NoteOn(1.0, 9, 38, 90)),
            ("bass", NoteOn(1.0, 0, 40, 90)),
        ],
        T120,
    )
    limbs = {p.note: p.limb for p in out}
    assert (limbs[40], limbs[36], limbs[44]) == ("right_hand", "right_foot", "left_foot")
    assert limbs[38] in ("left_hand", "right_hand")
