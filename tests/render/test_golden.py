"""Frames of the demo compared with golden images within a tolerance.

Regenerate with tools/update_golden.py after an intended change of look (and
look at the new images).  The tolerance allows for rasteriser differences at
edges, not for a moved figure or instrument.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from virja.render.images import decode_png_rgb

REPO = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(REPO / "tools"))
from update_golden import FRAMES, GOLDEN, render  # noqa: E402


@pytest.mark.parametrize("name", sorted(FRAMES))
def test_frame_matches_golden_image(name: str, tmp_path: Path) -> None:
    out = tmp_path / f"{name}.png"
    assert render(name, out) == 0
    got = decode_png_rgb(out.read_bytes()).astype(int)
    want = decode_png_rgb((GOLDEN / f"{name}.png").read_bytes()).astype(int)
    assert got.shape == want.shape
    diff = np.abs(got - want).max(axis=2)
    assert diff.mean() < 0.25, diff.mean()
    assert (diff > 48).mean() < 0.001, (diff > 48).mean()  # 80 ms of motion fails this
