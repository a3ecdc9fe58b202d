"""BVH reading/writing: hierarchy, channel orders, frames, errors naming file and line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from virja import quat as Q
from virja.errors import InputFileError
from virja.motion.bvh import Bvh, BvhError, BvhJoint, format_bvh, parse_bvh, read_bvh, write_bvh

SMALL = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Arm
  {
    OFFSET 0.1 0.2 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 -0.3 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0166667
1 2 3 0 0 0 0 0 0
0 0.5 0 90 0 0 0 45 0
"""


def test_parse_hierarchy_offsets_channels() -> None:
    b = parse_bvh(SMALL, "small.bvh")
    assert b.names == ["Hips", "Arm"]
    assert list(b.parents) == [-1, 0]
    np.testing.assert_allclose(b.offsets[1], [0.1, 0.2, 0])
    assert b.joints[0].rotation_order == "ZXY"
    assert b.joints[1].rotation_order == "XYZ"
    assert b.joints[1].end_site == (0.0, -0.3, 0.0)
    assert b.n_frames == 2
    assert abs(b.frame_time_s - 0.0166667) < 1e-12


def test_frames_become_quaternions_and_root_translation() -> None:
    b = parse_bvh(SMALL)
    assert b.rotations.shape == (2, 2, 4)
    np.testing.assert_allclose(b.positions[0, 0], [1, 2, 3])
    np.testing.assert_allclose(b.positions[1, 1], [0.1, 0.2, 0])  # no position channels: offset
    assert Q.angle_between(b.rotations[1, 0], Q.from_axis_angle([0, 0, 1], np.pi / 2)) < 1e-12
    assert Q.angle_between(b.rotations[1, 1], Q.from_axis_angle([0, 1, 0], np.pi / 4)) < 1e-12


def test_round_trip_through_text(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    joints = [
        BvhJoint(
            "Root",
            -1,
            (0.0, 0.0, 0.0),
            ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),
        ),
        BvhJoint("A", 0, (0.0, 0.3, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
        BvhJoint("B", 1, (0.1, 0.0, 0.0), ("Yrotation", "Zrotation", "Xrotation"), (0.0, 0.1, 0.0)),
        BvhJoint("C", 0, (-0.1, 0.0, 0.0), ("Xrotation", "Yrotation", "Zrotation")),
    ]
    rot = Q.normalize(rng.normal(size=(5, 4, 4)))
    pos = np.broadcast_to(np.array([j.offset for j in joints]), (5, 4, 3)).copy()
    pos[:, 0] = rng.normal(size=(5, 3))
    src = Bvh(joints, 1 / 60, rot, pos)
    path = tmp_path / "rt.bvh"
    write_bvh(src, path, decimals=6)
    back = read_bvh(path)
    assert back.names == src.names
    assert [j.channels for j in back.joints] == [j.channels for j in joints]
    assert back.joints[2].end_site == (0.0, 0.1, 0.0)
    assert np.all(Q.angle_between(back.rotations, rot) < 1e-6)
    np.testing.assert_allclose(back.positions, pos, atol=1e-6)
    # and writing again gives the same text
    assert format_bvh(back, 6) == path.read_text()


def _error(text: str) -> BvhError:
    with pytest.raises(BvhError) as info:
        parse_bvh(text, "bad.bvh")
    return info.value


def test_error_names_file_and_line_for_bad_offset() -> None:
    e = _error(SMALL.replace("OFFSET 0.1 0.2 0", "OFFSET 0.1 x 0"))
    assert e.line == 8
    assert str(e).startswith("bad.bvh: line 8:")
    assert "OFFSET y" in str(e)


def test_error_unknown_channel_line() -> None:
    e = _error(SMALL.replace("Xrotation Yrotation Zrotation", "Xrotation Yrotation Wrotation"))
    assert e.line == 9 and "Wrotation" in str(e)


def test_error_frame_with_wrong_value_count() -> None:
    e = _error(SMALL.replace("0 0.5 0 90 0 0 0 45 0", "0 0.5 0 90 0 0 0 45"))
    assert e.line == 20 and "8 values" in str(e)


def test_error_frame_count_mismatch() -> None:
    e = _error(SMALL.replace("Frames: 2", "Frames: 3"))
    assert "'Frames: 3' but 2 frame lines" in str(e)


def test_error_missing_motion_section() -> None:
    e = _error(SMALL.split("MOTION")[0])
    assert "no MOTION section" in str(e)


def test_error_is_input_file_error_and_value_error() -> None:
    e = _error(SMALL.replace("Frame Time: 0.0166667", "Frame Time: soon"))
    assert isinstance(e, InputFileError) and isinstance(e, ValueError)
    assert e.line == 18


def test_unreadable_file_names_it(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="missing.bvh"):
        read_bvh(tmp_path / "missing.bvh")


def test_write_orders_frame_columns_like_the_hierarchy(tmp_path: Path) -> None:
    """A joint listed after a later sibling's subtree still gets its own rotations back."""
    joints = [
        BvhJoint("Root", -1, (0.0, 0.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
        BvhJoint("A", 0, (0.0, 1.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
        BvhJoint("B", 0, (1.0, 0.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
        BvhJoint("A2", 1, (0.0, 1.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    ]
    rot = Q.normalize(np.random.default_rng(5).normal(size=(2, 4, 4)))
    pos = np.broadcast_to(np.array([j.offset for j in joints]), (2, 4, 3)).copy()
    write_bvh(Bvh(joints, 0.1, rot, pos), tmp_path / "o.bvh", decimals=6)
    back = read_bvh(tmp_path / "o.bvh")
    assert back.names == ["Root", "A", "A2", "B"]
    for name in ("Root", "A", "B", "A2"):
        i, k = [j.name for j in joints].index(name), back.names.index(name)
        assert Q.angle_between(back.rotations[:, k], rot[:, i]).max() < 1e-6


def test_round_trip_with_children_listed_before_parents(tmp_path: Path) -> None:
    """Joints in no hierarchy order (a child before its parent, siblings interleaved):
    the text puts every number on its own joint, and reading it back gives each
    joint its rotation and root translation, the joints now depth first."""
    rng = np.random.default_rng(11)
    pos_rot = ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")
    joints = [
        BvhJoint("Hand", 3, (0.0, 0.2, 0.0), ("Xrotation", "Yrotation", "Zrotation"), (0, 0.1, 0)),
        BvhJoint("Leg", 2, (0.1, -0.1, 0.0), ("Yrotation", "Xrotation", "Zrotation")),
        BvhJoint("Hips", -1, (0.0, 0.0, 0.0), pos_rot),
        BvhJoint("Arm", 4, (0.2, 0.0, 0.0), ("Zrotation", "Yrotation", "Xrotation")),
        BvhJoint("Spine", 2, (0.0, 0.1, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    ]
    rot = Q.normalize(rng.normal(size=(4, 5, 4)))
    pos = np.broadcast_to(np.array([j.offset for j in joints]), (4, 5, 3)).copy()
    pos[:, 2] = rng.normal(size=(4, 3))
    write_bvh(Bvh(joints, 0.05, rot, pos), tmp_path / "mixed.bvh", decimals=7)
    back = read_bvh(tmp_path / "mixed.bvh")
    # depth first, children in list order: Hips, Leg, Spine, Arm, Hand
    assert back.names == ["Hips", "Leg", "Spine", "Arm", "Hand"]
    assert [back.names[p] if p >= 0 else None for p in back.parents] == [
        None, "Hips", "Hips", "Spine", "Arm"
    ]  # fmt: skip
    for i, j in enumerate(joints):
        k = back.names.index(j.name)
        assert back.joints[k].channels == j.channels
        assert back.joints[k].end_site == j.end_site
        assert Q.angle_between(back.rotations[:, k], rot[:, i]).max() < 1e-6, j.name
        np.testing.assert_allclose(back.positions[:, k], pos[:, i], atol=1e-6)


def test_write_refuses_a_joint_list_that_is_not_one_tree() -> None:
    """Two roots, or a joint whose parent chain never reaches the root, is a ValueError
    (the text could not be read back with every joint)."""
    rot = Q.identity((1, 3))
    pos = np.zeros((1, 3, 3))
    two_roots = [BvhJoint(n, -1, (0.0, 0.0, 0.0), ()) for n in "ABC"]
    with pytest.raises(ValueError, match="exactly one root"):
        format_bvh(Bvh(two_roots, 0.1, rot, pos))
    loop = [
        BvhJoint("R", -1, (0.0, 0.0, 0.0), ()),
        BvhJoint("A", 2, (0.0, 0.0, 0.0), ()),
        BvhJoint("B", 1, (0.0, 0.0, 0.0), ()),
    ]
    with pytest.raises(ValueError, match="do not hang from the root"):
        format_bvh(Bvh(loop, 0.1, rot, pos))


def test_deep_chain_parses_and_writes_without_recursion() -> None:
    """A 1500-joint chain (deeper than Python's recursion limit) reads and writes back."""
    n = 1500
    zxy = ("Zrotation", "Xrotation", "Yrotation")
    joints = [BvhJoint(f"j{i}", i - 1, (0.0, 1.0, 0.0), zxy) for i in range(n)]
    rot = Q.from_axis_angle([0, 0, 1], np.linspace(0, 1, n))[None]
    b = Bvh(joints, 0.1, rot, np.tile([0.0, 1.0, 0.0], (1, n, 1)))
    back = parse_bvh(format_bvh(b, decimals=6))
    assert back.names == b.names and list(back.parents) == list(range(-1, n - 1))
    assert Q.angle_between(back.rotations, rot).max() < 1e-6


@pytest.mark.parametrize(
    ("old", "new", "what"),
    [
        ("OFFSET 0.1 0.2 0", "OFFSET 0.1 ٣ 0", "OFFSET y"),  # Arabic-Indic 3: float() takes it
        ("OFFSET 0.1 0.2 0", "OFFSET 0.1 nan 0", "OFFSET y"),
        ("OFFSET 0.1 0.2 0", "OFFSET 0.1 1e999 0", "OFFSET y"),
        ("OFFSET 0.1 0.2 0", "OFFSET 0.1 1_0 0", "OFFSET y"),
        ("CHANNELS 3 Xrotation", "CHANNELS ³ Xrotation", "channel count"),
        ("CHANNELS 3 Xrotation", "CHANNELS 9 Xrotation", "at most 6"),
    ],
)
def test_hierarchy_numbers_must_be_ascii_and_finite(old: str, new: str, what: str) -> None:
    """Numbers are ASCII decimal and finite; anything else is a BvhError naming the line."""
    text = SMALL.replace(old, new)
    assert text != SMALL
    err = _error(text)
    assert "bad.bvh" in str(err) and what in str(err)
    assert err.line in (8, 9)


@pytest.mark.parametrize(
    ("frames", "line"),
    [("Frames: ²", 17), ("Frames: 2.0", 17), ("Frames: 100000000000000000", 20)],
)
def test_frame_count_must_be_ascii_and_match_the_lines(frames: str, line: int) -> None:
    """A frame count that is not ASCII digits, or more than the frame lines present
    (checked before any allocation), is a BvhError naming its line."""
    err = _error(SMALL.replace("Frames: 2", frames))
    assert err.line == line


@pytest.mark.parametrize("value", ["٣", "nan", "inf", "1e999", "0x1"])
def test_frame_values_must_be_ascii_and_finite(value: str) -> None:
    """A frame value that is not a finite ASCII decimal is a BvhError naming its line."""
    err = _error(SMALL.replace("0 0.5 0 90 0 0 0 45 0", f"0 0.5 0 90 0 0 0 {value} 0"))
    assert err.line == 20
