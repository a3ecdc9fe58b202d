"""The hi-hat opens and closes as its notes say (closed 42, pedal 44, open 46)."""

from __future__ import annotations

import dataclasses

from tests.motion.helpers import drum
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary
from virja.motion.drummer_kit import HihatState
from virja.plan import default_config

ARTICULATIONS = {n: d.articulation for n, d in default_config().kit.notes.items()}


def test_state_follows_the_notes() -> None:
    h = HihatState(lead_s=0.05, hold_open_s=1.0)
    assert h.openness(0.0) is None  # no note: the pedal decides
    h.add(1.0, "closed")
    h.add(1.5, "open")
    h.add(2.0, "pedal")
    h.add(2.2, "rim")  # not a hi-hat state: ignored
    assert h.openness(0.5) == 0.0
    assert h.openness(1.0) == 0.0
    assert h.openness(1.44) == 0.0  # the foot lifts only just before the open note
    assert 0.0 < h.openness(1.475) < 1.0  # type: ignore[operator]
    assert h.openness(1.5) == 1.0
    assert h.openness(1.9) == 1.0
    assert h.openness(2.0) == 0.0
    assert h.openness(2.5) == 0.0


def test_open_hihat_left_alone_closes() -> None:
    h = HihatState(lead_s=0.05, hold_open_s=1.0)
    h.add(1.0, "open")
    assert h.openness(1.9) == 1.0
    assert h.openness(2.2) == 0.0


def test_animator_opens_the_cymbals_for_open_notes(library: MotionLibrary) -> None:
    a = BandAnimator(library)
    a.set_articulations(ARTICULATIONS)
    closed = drum("hihat_right_hand", 0.8, 1.0)
    opened = dataclasses.replace(drum("hihat_right_hand", 1.3, 1.5), note=46)
    a.add_planned(dataclasses.replace(closed, note=42))
    a.add_planned(opened)
    assert a.pose(1.0).hihat_open <= 0.15
    assert a.pose(1.5).hihat_open >= 0.3
    assert ARTICULATIONS[44] == "pedal"


def test_the_shipped_kit_map_is_the_default(library: MotionLibrary) -> None:
    """Any animator (the live window's process too) follows the notes without being told."""
    a = BandAnimator(library)
    a.add_planned(dataclasses.replace(drum("hihat_right_hand", 1.3, 1.5), note=46))
    assert a.pose(1.5).hihat_open >= 0.3
    a.add_planned(dataclasses.replace(drum("hihat_left_foot", 1.8, 2.0), note=44))
    assert a.pose(2.0).hihat_open <= 0.15


def test_a_foot_chick_lets_the_foot_open_the_cymbals_just_before() -> None:
    h = HihatState()
    h.add(2.0, "pedal")
    h.add(3.0, "closed")  # a stick note: no chick
    assert h.chick_weight(1.5) == 0.0
    assert 0.0 < h.chick_weight(1.9) < 1.0
    assert h.chick_weight(2.0) == 1.0
    assert h.chick_weight(2.9) == 0.0


def test_a_closed_stroke_just_before_a_chick_lands_on_shut_cymbals() -> None:
    """Bebop's ride-like hi-hat: open, closed 170 ms later, the foot's chick 170 ms
    after that.  The foot lifts for the chick only after the closed stroke."""
    h = HihatState()
    h.add(0.0, "open")
    h.add(0.17, "closed")
    h.add(0.34, "pedal")
    assert h.chick_weight(0.17) == 0.0
    assert 0.0 < h.chick_weight(0.3) < 1.0
    assert h.chick_weight(0.34) == 1.0


def test_a_change_right_after_a_note_waits_for_its_impact() -> None:
    """MMA's jazz: a foot chick 35 ms before an open stroke.  The chick lands on shut
    cymbals, the foot lifts after it; the ramp is never longer than lead_s."""
    h = HihatState(lead_s=0.06, hold_open_s=1.0)
    h.add(1.0, "pedal")
    h.add(1.035, "open")
    h.add(1.08, "closed")
    assert h.openness(1.0) == 0.0
    assert 0.0 < h.openness(1.02) < 1.0  # type: ignore[operator]
    assert h.openness(1.035) == 1.0
    assert 1.0 > h.openness(1.06) > 0.0  # type: ignore[operator]
    assert h.openness(1.08) == 0.0
    h.add(2.0, "open")  # a change far after: still over lead_s only
    assert h.openness(1.93) == 0.0
    assert h.openness(1.97) == 0.5
