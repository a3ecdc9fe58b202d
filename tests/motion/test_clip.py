"""Clip files: BVH + TOML sidecar, validated with the file (and line) named."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from virja import quat
from virja.motion.clip import ClipError, MotionLibrary, load_clip
from virja.resources import motions_dir

SRC = motions_dir() / "drums" / "snare_left_hand"


def _copy(tmp_path: Path) -> Path:
    shutil.copy(SRC.with_suffix(".bvh"), tmp_path / "snare_left_hand.bvh")
    shutil.copy(SRC.with_suffix(".toml"), tmp_path / "snare_left_hand.toml")
    return tmp_path / "snare_left_hand.bvh"


def test_clip_loads_with_its_sidecar(tmp_path: Path) -> None:
    clip = load_clip(_copy(tmp_path))
    assert clip.performer == "drums" and clip.limb == "left_hand" and clip.piece == "snare"
    assert clip.kind == "stroke" and 0 < clip.impact_s < clip.duration_s
    assert clip.fps == pytest.approx(60.0)


def test_missing_sidecar_is_named(tmp_path: Path) -> None:
    bvh = _copy(tmp_path)
    bvh.with_suffix(".toml").unlink()
    with pytest.raises(ClipError, match="no sidecar snare_left_hand.toml"):
        load_clip(bvh)


def test_bad_sidecar_value_names_file_and_line(tmp_path: Path) -> None:
    bvh = _copy(tmp_path)
    side = bvh.with_suffix(".toml")
    text = side.read_text().replace('limb = "left_hand"', 'limb = "left_elbow"')
    side.write_text(text)
    line = next(i for i, ln in enumerate(text.splitlines(), 1) if ln.startswith("limb"))
    with pytest.raises(ClipError, match=rf"snare_left_hand.toml: line {line}: limb must be one of"):
        load_clip(bvh)


def test_sidecar_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    bvh = _copy(tmp_path)
    bvh.with_suffix(".toml").write_text('performer = "drums"\nkind = \n')
    with pytest.raises(ClipError, match=r"snare_left_hand.toml: .*line 2"):
        load_clip(bvh)


def test_impact_past_the_end_is_refused(tmp_path: Path) -> None:
    bvh = _copy(tmp_path)
    side = bvh.with_suffix(".toml")
    lines = [
        ("impact_s = 9.0" if ln.startswith("impact_s") else ln)
        for ln in side.read_text().splitlines()
    ]
    side.write_text("\n".join(lines) + "\n")
    with pytest.raises(ClipError, match="past the clip's end"):
        load_clip(bvh)


def test_captured_bvh_with_other_joint_order_and_extra_joints_replaces_a_clip(
    tmp_path: Path,
) -> None:
    """Joints are matched by name: order and extra joints do not matter."""
    from virja.motion.bvh import Bvh, BvhJoint, read_bvh, write_bvh

    src = read_bvh(SRC.with_suffix(".bvh"))
    # add an extra finger joint under LeftHand
    hand = src.names.index("LeftHand")
    joints = list(src.joints) + [
        BvhJoint("LeftFinger", hand, (0.0, -0.1, 0.0), ("Zrotation", "Xrotation", "Yrotation"))
    ]
    import numpy as np

    rot = np.concatenate([src.rotations, quat.identity((src.n_frames, 1))], axis=1)
    pos = np.concatenate(
        [src.positions, np.tile([[[0.0, -0.1, 0.0]]], (src.n_frames, 1, 1))], axis=1
    )
    bvh = tmp_path / "snare_left_hand.bvh"
    write_bvh(Bvh(joints, src.frame_time_s, rot, pos), bvh)
    shutil.copy(SRC.with_suffix(".toml"), bvh.with_suffix(".toml"))
    clip = load_clip(bvh)
    orig = load_clip(SRC.with_suffix(".bvh"))
    assert quat.angle_between(clip.rotations, orig.rotations).max() < 1e-6


def test_bvh_missing_a_skeleton_joint_is_refused(tmp_path: Path) -> None:
    bvh = _copy(tmp_path)
    bvh.write_text(bvh.read_text().replace("JOINT HeadEnd", "JOINT Hat"))
    with pytest.raises(ClipError, match="lacks joints \\['HeadEnd'\\]"):
        load_clip(bvh)


def test_library_refuses_an_empty_folder(tmp_path: Path) -> None:
    with pytest.raises(ClipError, match="no clips"):
        MotionLibrary.load(tmp_path)


def test_authoring_is_deterministic(tmp_path: Path) -> None:
    """tools/author_motions.py rewrites the committed clips (one checked; 0.001 deg text precision)."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
    try:
        import author_motions  # type: ignore[import-not-found]
    finally:
        sys.path.pop(0)
    from virja.geometry import GEOMETRY

    loc, root, imp = author_motions.hand_stroke(GEOMETRY, "snare", "Left")
    out = tmp_path / "drums"
    out.mkdir()
    meta = {
        "performer": "drums",
        "limb": "left_hand",
        "kind": "stroke",
        "impact_s": imp,
        "joints": ["LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"],
        "piece": "snare",
        "velocity": 96,
    }
    author_motions.write_clip(
        out,
        "snare_left_hand",
        loc,
        root,
        meta,
        "snare struck with the left stick: ready, back-swing, strike, rebound, ready",
    )
    assert (out / "snare_left_hand.toml").read_text() == SRC.with_suffix(".toml").read_text()
    # the BVH text may differ in a last digit across numpy builds (e.g. -180.000 vs 180.000)
    from virja.motion.bvh import read_bvh

    new, old = read_bvh(out / "snare_left_hand.bvh"), read_bvh(SRC.with_suffix(".bvh"))
    assert new.names == old.names and new.n_frames == old.n_frames
    assert quat.angle_between(new.rotations, old.rotations).max() < 1e-4
