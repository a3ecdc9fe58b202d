"""Unit meshes face outward; instance transforms put primitives where asked."""

from __future__ import annotations

import numpy as np
import pytest

from virja.errors import ConfigError
from virja.render.camera import Camera, project
from virja.render.meshes import MESHES, pack_instances, segment_transforms, sphere_transforms
from virja.render.offline import OutputSpec, parse_size


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_triangles_wind_counter_clockwise_seen_from_outside(kind: str) -> None:
    tris = MESHES[kind]().reshape(-1, 3, 6)
    p, n = tris[:, :, :3], tris[:, :, 3:].mean(axis=1)
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = np.linalg.norm(face, axis=1)
    keep = area > 1e-9
    assert np.all(np.einsum("ij,ij->i", face[keep], n[keep]) > 0)


def test_segment_transform_maps_unit_cylinder_ends_to_the_points() -> None:
    a = np.array([[0.1, 0.2, 0.3]])
    b = np.array([[0.5, -0.1, 1.0]])
    m = segment_transforms(a, b, 0.02)[0]
    assert np.allclose(m @ [0, 0, 0, 1], [*a[0], 1])
    assert np.allclose(m @ [0, 1, 0, 1], [*b[0], 1])
    side = m @ [1, 0, 0, 0]
    assert np.linalg.norm(side[:3]) == pytest.approx(0.02)
    assert abs(np.dot(side[:3], b[0] - a[0])) < 1e-12


def test_pack_instances_is_column_major() -> None:
    m = sphere_transforms([[1.0, 2.0, 3.0]], 0.5)
    row = pack_instances(m, (0.1, 0.2, 0.3, 0.4))[0]
    assert list(row[12:15]) == [1.0, 2.0, 3.0]  # the translation is the 4th column
    assert row[16:] == pytest.approx([0.1, 0.2, 0.3, 0.4])


def test_camera_projects_its_target_to_the_centre() -> None:
    cam = Camera(target=(0.3, 1.0, -0.2), yaw_deg=30, pitch_deg=20)
    ((x, y),) = project(cam.view_proj(16 / 9), np.array([cam.target]), (1600, 900))
    assert x == pytest.approx(800) and y == pytest.approx(450)


def test_output_kind_from_the_path() -> None:
    assert OutputSpec.from_path("a/b.mp4").kind == "video"
    assert OutputSpec.from_path("frames").kind == "folder"
    assert OutputSpec.from_path("x.png").frame_path(3).name == "x_00003.png"
    with pytest.raises(ConfigError, match="unknown output type"):
        OutputSpec.from_path("x.gif")


@pytest.mark.parametrize("text", ["1280", "axb", "10x10", "99999x10"])
def test_bad_sizes_are_clear_errors(text: str) -> None:
    with pytest.raises(ConfigError):
        parse_size(text)
