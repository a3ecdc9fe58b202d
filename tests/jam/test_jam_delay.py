"""The thru delay line (pure, time passed in)."""

from __future__ import annotations

from virja.jam.delay import DelayLine


def test_nothing_comes_out_before_it_is_due() -> None:
    line = DelayLine()
    line.push(b"a", 10.2)
    assert line.pop_due(10.19) == []
    assert line.pop_due(10.2) == [b"a"]
    assert len(line) == 0


def test_messages_come_out_in_due_order_not_push_order() -> None:
    line = DelayLine()
    line.push(b"late", 2.0)
    line.push(b"early", 1.0)
    assert line.next_due_s() == 1.0
    assert line.pop_due(5.0) == [b"early", b"late"]


def test_equal_due_times_keep_push_order() -> None:
    """A note-off pushed after its note-on at the same time never overtakes it."""
    line = DelayLine()
    for i in range(50):
        line.push(bytes([i]), 1.0)
    assert line.pop_due(1.0) == [bytes([i]) for i in range(50)]


def test_empty_line_has_no_next_due() -> None:
    assert DelayLine().next_due_s() is None


def test_drain_returns_everything_in_order() -> None:
    line = DelayLine()
    line.push(b"b", 3.0)
    line.push(b"a", 1.0)
    assert line.drain() == [b"a", b"b"]
    assert line.pop_due(10.0) == []


def test_a_full_line_drops_and_counts() -> None:
    line = DelayLine(limit=2)
    assert line.push(b"1", 1.0) and line.push(b"2", 1.0)
    assert not line.push(b"3", 1.0)
    assert line.dropped == 1 and len(line) == 2
