"""BVH from `export`: one file per figure, read back by virja's reader and by the `bvh` package."""

from __future__ import annotations

from pathlib import Path

import bvh as bvh_pkg
import numpy as np
import pytest

from tests.export.conftest import GMD_TAKES, gmd_take
from virja import quat
from virja.export import Export, export_performance
from virja.motion.bvh import read_bvh
from virja.motion.skeleton import SKELETON


def _files(export: Export) -> dict[str, Path]:
    return {p.stem.rsplit("_", 1)[1]: p for p in export.outputs if p.suffix == ".bvh"}


def test_one_bvh_per_figure_named_after_the_output(demo_export: Export) -> None:
    files = _files(demo_export)
    assert set(files) == {"drums", "bass"}
    assert all(p.name == f"blues_{fig}.bvh" for fig, p in files.items())


def test_virja_reads_back_the_performed_rotations(demo_export: Export) -> None:
    files = _files(demo_export)
    from tests.export.test_gltf import _replan

    animator = _replan()
    t0 = demo_export.t0_s
    for fi, fig in enumerate(("drums", "bass")):
        b = read_bvh(files[fig])
        assert [j.name for j in b.joints] == list(SKELETON.names)
        assert b.rotations.shape[0] == demo_export.frames
        assert b.frame_time_s == pytest.approx(1 / 30, abs=1e-6)
        for k in (0, 150, 400):
            want = animator.local_rotations(t0 + k / 30)[fi]
            # BVH stores degrees with 6 decimals: the same rotation within 1e-5 rad
            assert np.all(quat.angle_between(b.rotations[k], want) < 1e-4)


def test_the_bvh_package_reads_the_same_hierarchy_and_frames(demo_export: Export) -> None:
    for path in _files(demo_export).values():
        mocap = bvh_pkg.Bvh(path.read_text())
        assert mocap.get_joints_names() == list(SKELETON.names)
        assert mocap.nframes == demo_export.frames
        assert mocap.frame_time == pytest.approx(1 / 30, abs=1e-6)
        assert mocap.joint_parent("LeftForeArm").name == "LeftArm"
        ours = read_bvh(path)
        k = 321
        euler = np.radians(
            mocap.frame_joint_channels(k, "RightArm", ["Zrotation", "Xrotation", "Yrotation"])
        )
        assert np.allclose(
            quat.from_euler(euler, "ZXY"), ours.rotations[k, SKELETON.index("RightArm")], atol=1e-6
        )


@pytest.mark.parametrize("take", GMD_TAKES[:1])
def test_gmd_take_exports_bvh(take: str, tmp_path: Path) -> None:
    out = export_performance(gmd_take(take), bvh=tmp_path / "take.bvh", fps=60, start_s=1, end_s=3)
    assert [p.name for p in out.outputs] == ["take_drums.bvh", "take_bass.bvh"]
    assert read_bvh(out.outputs[0]).rotations.shape[0] == 121
