"""What the drummer's chains share (virja.plan.chain_kit)."""

from __future__ import annotations

import pytest

from virja.plan.chain_kit import drum_stroke
from virja.vocab import DrumStroke


def test_drum_stroke_is_made_once_per_piece_and_limb() -> None:
    stroke = drum_stroke("ride", "right_hand")
    assert stroke == DrumStroke("ride", "right_hand")
    assert drum_stroke("ride", "right_hand") is stroke
    assert drum_stroke("ride", "left_hand") == DrumStroke("ride", "left_hand")


def test_drum_stroke_refuses_what_is_no_piece_or_limb() -> None:
    with pytest.raises(ValueError, match="not a drum piece"):
        drum_stroke("cowbell_xl", "right_hand")
    with pytest.raises(ValueError):
        drum_stroke("snare", "tail")
