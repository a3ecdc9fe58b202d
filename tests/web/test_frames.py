"""The viewer's wire format: the native scene's instances, quantised within a visible tolerance."""

from __future__ import annotations

import json

import numpy as np
import pytest

from virja.motion.band import BandAnimator
from virja.render.meshes import MESHES
from virja.render.scene import FLOOR, RUG, band_scene, static_scene
from virja.web.frames import (
    BYTES_PER_INSTANCE,
    HEADER,
    KINDS,
    decode_frame,
    encode_frame,
    hello,
    instances,
)


def test_a_frame_round_trips_within_a_quarter_millimetre_and_a_tenth_of_a_percent() -> None:
    dl = band_scene(BandAnimator().pose(1.25))
    data = encode_frame(7, 1795400000.125, dl)
    counts, rows = instances(dl)
    assert len(data) == HEADER.size + BYTES_PER_INSTANCE * sum(counts)
    seq, t, by_kind = decode_frame(data)
    assert (seq, t) == (7, 1795400000.125)  # float64: session Unix time to the microsecond
    got = np.concatenate([by_kind[k] for k in KINDS])
    assert [len(by_kind[k]) for k in KINDS] == counts
    cols, want = got[:, :16].reshape(-1, 4, 4), rows[:, :16].reshape(-1, 4, 4)
    assert np.abs(cols[:, 3, :3] - want[:, 3, :3]).max() <= 0.5 / 4096 + 1e-7  # translation
    lin_err = np.abs(cols[:, :3, :3] - want[:, :3, :3])
    assert (lin_err <= 1e-3 * np.abs(want[:, :3, :3]) + 1e-7).all()  # float16: 11 bits
    assert np.abs(got[:, 16:] - rows[:, 16:]).max() <= 0.5 / 255 + 1e-7  # colours


def test_a_frame_names_what_is_wrong_with_it() -> None:
    data = encode_frame(1, 0.0, band_scene(BandAnimator().pose(0.0)))
    with pytest.raises(ValueError, match="truncated"):
        decode_frame(data[:10])
    with pytest.raises(ValueError, match="must be"):
        decode_frame(data[:-1])
    with pytest.raises(ValueError, match="not a version 1 frame"):
        decode_frame(b"\x07" + data[1:])


def test_hello_carries_the_native_meshes_stage_and_cameras_as_json() -> None:
    msg = json.loads(json.dumps(hello(static_scene(), fps=30.0, lead_s=0.1)))
    static = static_scene()
    for k in KINDS:
        assert len(msg["meshes"][k]) == MESHES[k]().size
        rows = np.array(msg["static"][k]["rows"]).reshape(-1, 20)
        np.testing.assert_allclose(rows, static.packed(k), atol=1e-5)
    # exactly the floor slab and the rug are marked as stage (hidden when transparent)
    marked = [
        tuple(np.round(np.array(msg["static"][k]["rows"]).reshape(-1, 20)[i, 16:], 5))
        for k in KINDS
        for i, s in enumerate(msg["static"][k]["stage"])
        if s
    ]
    assert sorted(marked) == sorted([tuple(np.round(FLOOR, 5)), tuple(np.round(RUG, 5))])
    assert {"front", "drums", "bass", "top"} <= set(msg["cameras"])
