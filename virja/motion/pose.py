"""``BandPose``: everything the renderer needs to draw the band at one instant.

Units: metres, radians, world frame of :mod:`virja.geometry` (y up, audience
at +z).  Quaternions are w x y z.  Arrays are float64 and must be treated as
read-only by the consumer.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

LEFT_FINGER_BONES = 10  # the fretting hand's bones in ``BandPose.bass_fingers``


@dataclass(frozen=True)
class FigurePose:
    """One player's skeleton at one instant.

    - ``names``: joint names, length n (same order as every array here);
    - ``parents``: (n,) int64, index of each joint's parent, -1 for the root;
      a bone is drawn from ``positions[parents[i]]`` to ``positions[i]``;
    - ``positions``: (n, 3) float64 world positions of the joints, metres;
    - ``rotations``: (n, 4) float64 world rotations, w x y z;
    - ``radii``: (n,) float64 radius of the bone ending at each joint, metres
      (for the root: the pelvis' radius).
    """

    names: tuple[str, ...]
    parents: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    radii: np.ndarray

    def position(self, name: str) -> np.ndarray:
        """(3,) world position of joint ``name``."""
        return self.positions[self.names.index(name)]


@dataclass(frozen=True)
class BandPose:
    """The band at ``time_s``.

    - ``time_s``: session time of the pose, seconds;
    - ``drums``, ``bass``: :class:`FigurePose` of the drummer and the bassist;
    - ``sticks``: (2, 2, 3) float64, [left, right] x [butt, tip] world points, metres;
    - ``hihat_open``: 0 (closed, pedal down) .. 1 (fully open), follows the left foot;
    - ``cymbal_swing``: piece ("ride", "crash", "crash2", "hihat") -> swing angle, radians
      about a horizontal axis through the stand, damped after each stroke;
    - ``head_hits``: drum piece ("kick", "snare", "tom_high", "tom_low",
      "tom_floor") -> 0..1, jumps to the stroke's loudness at impact and decays;
    - ``string_vibration``: string ("E", "A", "D", "G") -> vibration amplitude,
      metres at the middle of the vibrating part, decaying after a pluck;
    - ``string_stops``: string -> fret stopped now (0 = open);
    - ``fretting_tip``: (3,) the bassist's left (fretting) fingertip, metres;
    - ``plucking_tip``: (3,) the bassist's right (plucking) fingertip, metres;
    - ``bass_fingers``: (k, 2, 3) the bassist's finger bones (from, to), metres
      (:mod:`virja.motion.bassist`; empty when not drawn): the fretting hand's
      first (:data:`LEFT_FINGER_BONES`: index, middle, ring, little, two bones
      each, then the thumb's two), then the plucking hand's (index, middle, two
      bones each, ring and little curled, the thumb).
    - ``bass_transform``: (4, 4) the upright bass's world transform (a rotation
      about its endpin, :mod:`virja.motion.bass_lean`): the instrument of
      :mod:`virja.geometry` leans with its player; identity when he stands still.
    """

    time_s: float
    drums: FigurePose
    bass: FigurePose
    sticks: np.ndarray
    hihat_open: float
    cymbal_swing: Mapping[str, float]
    head_hits: Mapping[str, float]
    string_vibration: Mapping[str, float]
    string_stops: Mapping[str, int]
    fretting_tip: np.ndarray
    plucking_tip: np.ndarray
    bass_fingers: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))
    bass_transform: np.ndarray = field(default_factory=lambda: np.eye(4))

    def figure(self, performer: str) -> FigurePose:
        """``"drums"`` or ``"bass"``."""
        if performer == "drums":
            return self.drums
        if performer == "bass":
            return self.bass
        raise KeyError(f"no figure {performer!r}; expected 'drums' or 'bass'")
