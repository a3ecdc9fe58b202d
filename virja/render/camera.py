"""An orbit camera: a target, yaw and pitch around it, a distance, a lens.

Matrices come from pyrr (row-vector convention) and are returned here in
column-vector form (clip = P @ V @ world), as numpy float64 (4, 4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pyrr
from numpy.typing import NDArray


@dataclass(frozen=True)
class Camera:
    target: tuple[float, float, float] = (0.0, 0.85, 0.1)
    yaw_deg: float = 0.0  # 0: looking from the audience (+z) towards the stage
    pitch_deg: float = 12.0  # above the horizon
    distance_m: float = 4.1
    fov_deg: float = 42.0
    near_m: float = 0.05
    far_m: float = 60.0

    @property
    def eye(self) -> NDArray[np.float64]:
        yaw, pitch = math.radians(self.yaw_deg), math.radians(self.pitch_deg)
        offset = np.array(
            [
                math.sin(yaw) * math.cos(pitch),
                math.sin(pitch),
                math.cos(yaw) * math.cos(pitch),
            ]
        )
        return np.asarray(self.target, dtype=np.float64) + self.distance_m * offset

    def view(self) -> NDArray[np.float64]:
        m = pyrr.matrix44.create_look_at(
            self.eye, np.asarray(self.target), np.array([0.0, 1.0, 0.0])
        )
        return np.asarray(m, dtype=np.float64).T

    def projection(self, aspect: float) -> NDArray[np.float64]:
        m = pyrr.matrix44.create_perspective_projection(
            self.fov_deg, aspect, self.near_m, self.far_m
        )
        return np.asarray(m, dtype=np.float64).T

    def view_proj(self, aspect: float) -> NDArray[np.float64]:
        return self.projection(aspect) @ self.view()

    def orbit(self, d_yaw: float, d_pitch: float) -> Camera:
        return replace(
            self,
            yaw_deg=(self.yaw_deg + d_yaw) % 360.0,
            pitch_deg=min(85.0, max(-10.0, self.pitch_deg + d_pitch)),
        )

    def zoom(self, factor: float) -> Camera:
        return replace(self, distance_m=min(30.0, max(1.0, self.distance_m * factor)))


PRESETS: dict[str, Camera] = {
    "front": Camera(),
    # high enough to see the sticks over the rack toms; centred on the kit, which
    # stands 0.2-0.8 m in front of the drummer
    "drums": Camera(target=(-0.8, 0.8, 0.15), yaw_deg=-25.0, pitch_deg=30.0, distance_m=2.8),
    # from the audience's right, where the bass's strings face past the player
    "bass": Camera(target=(0.95, 1.05, 0.15), yaw_deg=20.0, pitch_deg=10.0, distance_m=2.5),
    "top": Camera(pitch_deg=70.0, distance_m=6.0),
    # close-ups of the bassist's hands: the fretting hand on the neck, the plucking hand
    "bass_left": Camera(target=(1.08, 1.45, 0.15), yaw_deg=-10.0, pitch_deg=5.0, distance_m=0.8),
    "bass_right": Camera(target=(1.0, 1.0, 0.25), yaw_deg=-25.0, pitch_deg=15.0, distance_m=0.8),
}


def project(
    view_proj: NDArray[np.float64], points: NDArray[np.float64], size: tuple[int, int]
) -> NDArray[np.float64]:
    """World points (n, 3) -> pixel coordinates (n, 2), origin top-left, y down."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    h = np.c_[p, np.ones(len(p))] @ view_proj.T
    ndc = h[:, :3] / h[:, 3:4]
    w, hgt = size
    return np.c_[(ndc[:, 0] + 1) * 0.5 * w, (1 - ndc[:, 1]) * 0.5 * hgt]
