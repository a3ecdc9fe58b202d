"""Tests of virja.dance.intervals.correct_intervals (the paper's step 2)."""

from __future__ import annotations

import pytest

from virja.dance import CorrectedInterval, correct_intervals

PAPER_SEGMENTS = [5, 6, 7, 8, 9, 11, 12, 13, 23, 24, 25, 26, 32, 33, 34, 41, 45, 46, 59, 70]


def test_paper_example_1_merges_14_13_14_into_41_with_tolerance_0() -> None:
    """14 and 27 match nothing, 41 matches exactly: one interval 0..2, tolerance 0."""
    assert correct_intervals([14, 13, 14], PAPER_SEGMENTS) == [CorrectedInterval(0, 2, 41, 0)]


def test_paper_example_2_outputs_shortest_of_smallest_tolerance_14() -> None:
    """14(1) 22(1) 29(3) 43(2) 54(5) 64(5) then 71 > 70: output 14 with tolerance 1."""
    beat = [14, 8, 7, 14, 11, 10, 7]  # cumulative 14, 22, 29, 43, 54, 64, 71
    out = correct_intervals(beat, PAPER_SEGMENTS)
    assert out[0] == CorrectedInterval(0, 0, 14, 1)


def test_paper_example_2_continues_with_the_interval_after_the_output() -> None:
    """After 14 the next run starts at interval 1 (8): 8 is a segment length."""
    out = correct_intervals([14, 8, 7, 14, 11, 10, 7], PAPER_SEGMENTS)
    assert out[1] == CorrectedInterval(1, 1, 8, 0)
    assert out[2] == CorrectedInterval(2, 2, 7, 0)


def test_output_covers_every_beat_interval_once_in_order() -> None:
    beat = [14, 8, 7, 14, 11, 10, 7, 3, 2, 100, 4, 19]
    out = correct_intervals(beat, PAPER_SEGMENTS)
    covered = [k for c in out for k in range(c.first, c.last + 1)]
    assert covered == list(range(len(beat)))
    for c in out:
        assert c.span == sum(beat[c.first : c.last + 1])


def test_exact_single_interval_is_output_unchanged() -> None:
    assert correct_intervals([23], PAPER_SEGMENTS) == [CorrectedInterval(0, 0, 23, 0)]


def test_single_interval_longer_than_longest_is_kept_alone_with_distance_to_longest() -> None:
    """Policy: nothing remembered at (6) -> output it alone, tolerance span - longest."""
    assert correct_intervals([90, 5], PAPER_SEGMENTS) == [
        CorrectedInterval(0, 0, 90, 20),
        CorrectedInterval(1, 1, 5, 0),
    ]


def test_last_interval_without_a_next_one_goes_to_step_6() -> None:
    """3 then 2: 3 (tol 2), 5 exact -> 0..1; a lone 4 at the end -> tolerance 1."""
    assert correct_intervals([3, 2, 4], PAPER_SEGMENTS) == [
        CorrectedInterval(0, 1, 5, 0),
        CorrectedInterval(2, 2, 4, 1),
    ]


def test_tolerance_is_distance_to_closest_segment_length() -> None:
    out = correct_intervals([60], [10, 50])
    assert out == [CorrectedInterval(0, 0, 60, 10)]


def test_empty_beat_list_gives_nothing() -> None:
    assert correct_intervals([], PAPER_SEGMENTS) == []


@pytest.mark.parametrize("beat,segs", [([0], [5]), ([5], []), ([-1], [5])])
def test_non_positive_lengths_or_no_segments_raise_value_error(
    beat: list[int], segs: list[int]
) -> None:
    with pytest.raises(ValueError):
        correct_intervals(beat, segs)
