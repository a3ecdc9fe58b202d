"""Following a keyboard that is unplugged and plugged back (pure, time passed in)."""

from __future__ import annotations

import pytest

from virja.jam.watch import PortChange, PortWatcher, find_port


def test_find_port_is_a_case_insensitive_substring_first_match() -> None:
    names = ["system:midi_capture_1", "Keystation 49:out", "keystation 61:out"]
    assert find_port(names, "KEYSTATION") == 1
    assert find_port(names, "nope") is None


def test_listed_port_needs_nothing() -> None:
    w = PortWatcher("kbd", connected="kbd:out")
    assert w.update(["x:y", "kbd:out"], now_s=0.0) is None


def test_vanished_port_is_disconnected() -> None:
    w = PortWatcher("kbd", connected="kbd:out")
    assert w.update(["x:y"], now_s=0.0) == PortChange("kbd:out", None, None)
    assert w.connected is None


def test_returning_port_is_connected_with_its_index() -> None:
    w = PortWatcher("kbd", connected="kbd:out")
    w.update([], now_s=0.0)
    assert w.update([], now_s=1.0) is None
    assert w.update(["x:y", "kbd:out"], now_s=2.0) == PortChange(None, "kbd:out", 1)
    assert w.connected == "kbd:out"


def test_a_renamed_port_is_swapped_in_one_change() -> None:
    """ALSA renumbers a replugged device between two polls: close the old, open the new."""
    w = PortWatcher("Keystation", connected="Keystation:out 20:0")
    assert w.update(["Keystation:out 24:0"], now_s=0.0) == PortChange(
        "Keystation:out 20:0", "Keystation:out 24:0", 0
    )


def test_the_held_port_is_kept_while_another_match_appears_first() -> None:
    w = PortWatcher("kbd", connected="kbd-b:out")
    assert w.update(["kbd-a:out", "kbd-b:out"], now_s=0.0) is None


def test_polls_are_due_at_the_low_rate_only() -> None:
    w = PortWatcher("kbd", poll_interval_s=0.5)
    assert w.due(0.0)
    w.update([], now_s=0.0)
    assert not w.due(0.49)
    assert w.due(0.5)


def test_forget_makes_the_next_poll_try_again() -> None:
    w = PortWatcher("kbd")
    assert w.update(["kbd:out"], now_s=0.0) is not None
    w.forget()
    assert w.update(["kbd:out"], now_s=1.0) == PortChange(None, "kbd:out", 0)


def test_poll_interval_must_be_positive() -> None:
    with pytest.raises(ValueError, match="poll_interval_s"):
        PortWatcher("kbd", poll_interval_s=0)
