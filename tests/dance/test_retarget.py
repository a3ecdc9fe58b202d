"""Tests of virja.dance.retarget: captures of common skeletons onto the figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from virja import quat
from virja.dance.capture_styles import STYLES, as_capture
from virja.dance.retarget import (
    RetargetError,
    figure_joints,
    find_landmarks,
    is_figure_skeleton,
    normalise,
    retarget_to_figure,
)
from virja.motion.bvh import Bvh, read_bvh, world_pose, write_bvh
from virja.motion.skeleton import SKELETON


def _figure_motion(n: int = 30, seed: int = 0) -> Bvh:
    """Every joint of the figure turning on its own slow sine about its own axis."""
    rng = np.random.default_rng(seed)
    J = SKELETON.n_joints
    t = np.arange(n) / 30.0
    axes = rng.normal(size=(J, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    ang = 0.5 * np.sin(2 * np.pi * 0.7 * t[:, None] + rng.uniform(0, 6, J))
    rot = quat.from_axis_angle(np.broadcast_to(axes, (n, J, 3)), ang)
    pos = np.broadcast_to(SKELETON.offsets, (n, J, 3)).copy()
    pos[:, 0] = [0.1, 0.95, 0.2]
    pos[:, 0, 1] += 0.05 * np.sin(t)
    return Bvh(figure_joints(), 1 / 30, rot, pos)


@pytest.mark.parametrize("style", sorted(STYLES))
def test_a_capture_in_each_naming_comes_back_as_the_figure_motion(
    style: str, tmp_path: Path
) -> None:
    fig = _figure_motion()
    path = tmp_path / f"{style}.bvh"
    write_bvh(as_capture(fig, style), path)
    cap = read_bvh(path)
    assert not is_figure_skeleton(cap)
    back = retarget_to_figure(cap)
    assert is_figure_skeleton(back)
    want, _ = world_pose(fig)
    got, _ = world_pose(back)
    assert np.max(np.abs(got - want)) < 1e-3  # metres, whatever the capture's units


def test_the_test_captures_really_differ_from_the_figure() -> None:
    fig = _figure_motion()
    cmu = as_capture(fig, "cmu")
    mixamo = as_capture(fig, "mixamo")
    mb = as_capture(fig, "motionbuilder")
    assert "LHipJoint" in cmu.names and "Neck1" in cmu.names
    assert all(n.startswith("mixamorig:") for n in mixamo.names)
    assert "LeftElbow" in mb.names and "LeftCollar" in mb.names
    arm = mixamo.names.index("mixamorig:LeftForeArm")
    assert mixamo.joints[arm].offset[0] > 20  # T-pose, centimetres
    assert find_landmarks(mb.names).style == "classic"
    assert find_landmarks(cmu.names).style == "humanik"


def test_classic_left_shoulder_is_the_upper_arm() -> None:
    names = ["Hips", "Chest", "Neck", "Head", "LeftCollar", "LeftShoulder", "LeftElbow"]
    names += ["LeftWrist", "RightCollar", "RightShoulder", "RightElbow", "RightWrist"]
    names += [f"{s}{j}" for s in ("Left", "Right") for j in ("Hip", "Knee", "Ankle")]
    lm = find_landmarks(names)
    assert names[lm.joints["LeftArm"]] == "LeftShoulder"
    assert names[lm.joints["LeftShoulder"]] == "LeftCollar"
    assert names[lm.joints["LeftUpLeg"]] == "LeftHip"


def test_names_are_compared_without_prefix_case_or_separators() -> None:
    assert normalise("mixamorig:Left_Fore-Arm") == "leftforearm"
    assert normalise("Bip01 Spine") == "bip01spine"


def test_a_skeleton_without_legs_is_refused_with_the_joints_missing() -> None:
    with pytest.raises(RetargetError, match="LeftUpLeg"):
        find_landmarks(["Hips", "Spine", "Head", "LeftArm", "LeftForeArm", "RightArm"])


def test_a_synthetic_teacher_in_centimetres_becomes_a_figure_in_metres() -> None:
    from virja.dance.synth_capture import make_teacher, random_boundaries

    t = make_teacher("bounce", random_boundaries(6, np.random.default_rng(0)), seed=0)
    fig = retarget_to_figure(t.bvh)
    pos, _ = world_pose(fig)
    foot = SKELETON.index("LeftFoot")
    height = pos[0, SKELETON.index("HeadEnd"), 1] - pos[0, foot, 1]
    assert 1.3 < height < 2.0
