"""The fingerboard of a tuning (virja.fingerboard): its edges follow the strings, the three
sheared boxes the renderer draws fill exactly its trapezoid, and its corners (the glTF
mesh) are its edges'."""

from __future__ import annotations

import numpy as np
import pytest

from virja.fingerboard import fingerboard
from virja.geometry import GEOMETRY

TUNINGS = [("E", "A", "D", "G"), ("B", "E", "A", "D", "G"), ("B", "E", "A", "D", "G", "C")]


@pytest.mark.parametrize("strings", TUNINGS, ids=["four", "five", "six"])
def test_the_drawn_boxes_fill_the_board_and_nothing_else(strings: tuple[str, ...]) -> None:
    board = fingerboard(GEOMETRY.bass, strings)
    inv = np.linalg.inv(board.pieces())  # (3, 4, 4): world -> each unit box
    rng = np.random.default_rng(7)
    # points on the board's mid-plane, over a box a little larger than the board
    u = rng.uniform(0.01, board.length - 0.01, 4000)
    lat = rng.uniform(board.high[1] - 0.02, board.low[1] + 0.02, 4000)
    face = board.spec.face_m - board.spec.thickness_m / 2
    pts = board.nut + u[:, None] * board.along + lat[:, None] * board.lateral + face * board.face
    local = np.einsum("kij,nj->kni", inv[:, :3, :3], pts) + inv[:, None, :3, 3]
    in_a_box = (np.abs(local) <= 0.5 + 1e-9).all(axis=-1).any(axis=0)
    on_board = (lat < board.low_edge(u)) & (lat > board.high_edge(u))
    near_edge = np.minimum(np.abs(lat - board.low_edge(u)), np.abs(lat - board.high_edge(u)))
    clear = near_edge > 1e-6
    assert np.array_equal(in_a_box[clear], on_board[clear])


@pytest.mark.parametrize("strings", TUNINGS, ids=["four", "five", "six"])
def test_corners_are_the_edges(strings: tuple[str, ...]) -> None:
    board = fingerboard(GEOMETRY.bass, strings)
    c = board.coords(board.corners())
    for i, (a, lat, f) in enumerate(c):
        end, high, top = (i >> 2) & 1, (i >> 1) & 1, i & 1
        assert a == pytest.approx(board.length * end, abs=1e-12)
        assert lat == pytest.approx((board.high if high else board.low)[end], abs=1e-12)
        want = board.spec.face_m - (0.0 if top else board.spec.thickness_m)
        assert f == pytest.approx(want, abs=1e-12)
    assert board.width(0.0) == pytest.approx(board.low[0] - board.high[0])


def test_a_string_the_bass_lacks_is_one_clear_error() -> None:
    with pytest.raises(ValueError, match="the bass has the strings B E A D G C; got E X"):
        fingerboard(GEOMETRY.bass, ("E", "X"))
    with pytest.raises(ValueError, match="got none"):
        fingerboard(GEOMETRY.bass, ())
