"""A figure motion written as a capture of another skeleton: CMU, Mixamo, MotionBuilder naming.

No real capture can be shipped, so tests and docs make their own: the
figure's motion re-expressed on a skeleton named and built like a common
capture's (:func:`as_capture`).  Each style has its own joint names, extra
joints (CMU's ``LHipJoint``, ``LowerBack``, ``Neck1``, finger bases),
a T-pose rest (arms out sideways, so every arm rotation differs from the
figure's), its own units (CMU inches, Mixamo and MotionBuilder
centimetres) and Euler order.  World joint positions are the figure's, so
:func:`virja.dance.retarget.retarget_to_figure` must give the motion back.
"""

from __future__ import annotations

import numpy as np

from virja import quat
from virja.dance.audio import FloatArray
from virja.motion.bvh import Bvh, BvhJoint, world_pose
from virja.motion.skeleton import SKELETON

# (name, parent, figure joint) or (name, parent, (figure parent, figure child, fraction)) for
# a joint the figure does not have, placed on the figure's bone; end sites: {joint: figure end}
_Spec = tuple[str, str | None, "str | tuple[str, str, float]"]


def _limbs(style: str) -> list[_Spec]:
    out: list[_Spec] = []
    for side, s in (("Left", "L"), ("Right", "R")):
        if style == "motionbuilder":
            out += [
                (f"{side}Collar", "Chest2", f"{side}Shoulder"),
                (f"{side}Shoulder", f"{side}Collar", f"{side}Arm"),
                (f"{side}Elbow", f"{side}Shoulder", f"{side}ForeArm"),
                (f"{side}Wrist", f"{side}Elbow", f"{side}Hand"),
                (f"{side}Hip", "Hips", f"{side}UpLeg"),
                (f"{side}Knee", f"{side}Hip", f"{side}Leg"),
                (f"{side}Ankle", f"{side}Knee", f"{side}Foot"),
                (f"{side}Toe", f"{side}Ankle", f"{side}Toe"),
            ]
            continue
        chest = "Spine1" if style == "cmu" else "Spine2"
        hip_parent = f"{s}HipJoint" if style == "cmu" else "Hips"
        if style == "cmu":
            out.append((f"{s}HipJoint", "Hips", ("Hips", f"{side}UpLeg", 0.5)))
        out += [
            (f"{side}Shoulder", chest, f"{side}Shoulder"),
            (f"{side}Arm", f"{side}Shoulder", f"{side}Arm"),
            (f"{side}ForeArm", f"{side}Arm", f"{side}ForeArm"),
            (f"{side}Hand", f"{side}ForeArm", f"{side}Hand"),
            (
                f"{side}FingerBase" if style == "cmu" else f"{side}HandMiddle1",
                f"{side}Hand",
                (f"{side}Hand", f"{side}HandEnd", 0.6),
            ),
            (f"{side}UpLeg", hip_parent, f"{side}UpLeg"),
            (f"{side}Leg", f"{side}UpLeg", f"{side}Leg"),
            (f"{side}Foot", f"{side}Leg", f"{side}Foot"),
            (f"{side}ToeBase", f"{side}Foot", f"{side}Toe"),
        ]
    return out


STYLES: dict[str, tuple[list[_Spec], str, float, str]] = {
    # style: (joints, name prefix, units per metre, rotation channels)
    "cmu": (
        [
            ("Hips", None, "Hips"),
            ("LowerBack", "Hips", ("Hips", "Spine", 0.5)),
            ("Spine", "LowerBack", "Spine"),
            ("Spine1", "Spine", "Chest"),
            ("Neck", "Spine1", "Neck"),
            ("Neck1", "Neck", ("Neck", "Head", 0.5)),
            ("Head", "Neck1", "Head"),
            *_limbs("cmu"),
        ],
        "",
        100.0 / 2.54,
        "ZYX",
    ),
    "mixamo": (
        [
            ("Hips", None, "Hips"),
            ("Spine", "Hips", "Spine"),
            ("Spine1", "Spine", ("Spine", "Chest", 0.5)),
            ("Spine2", "Spine1", "Chest"),
            ("Neck", "Spine2", "Neck"),
            ("Head", "Neck", "Head"),
            *_limbs("mixamo"),
        ],
        "mixamorig:",
        100.0,
        "ZXY",
    ),
    "motionbuilder": (
        [
            ("Hips", None, "Hips"),
            ("Chest", "Hips", "Spine"),
            ("Chest2", "Chest", "Chest"),
            ("Neck", "Chest2", "Neck"),
            ("Head", "Neck", "Head"),
            *_limbs("motionbuilder"),
        ],
        "",
        100.0,
        "ZXY",
    ),
}
_END_OF = {"Head": "HeadEnd", "LeftHand": "LeftHandEnd", "RightHand": "RightHandEnd"}


def _tpose(fig: str) -> FloatArray:
    """Rest correction C of a figure joint: arms out sideways (T-pose) instead of down."""
    if fig in ("LeftArm", "LeftForeArm", "LeftHand"):
        return quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(-np.pi / 2))
    if fig in ("RightArm", "RightForeArm", "RightHand"):
        return quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(np.pi / 2))
    return quat.identity()


def as_capture(fig_bvh: Bvh, style: str) -> Bvh:
    """The figure motion ``fig_bvh`` on a ``style`` skeleton (``cmu``, ``mixamo``, ``motionbuilder``)."""
    if style not in STYLES:
        raise ValueError(f"style must be one of {', '.join(STYLES)}, got {style!r}")
    specs, prefix, units, order = STYLES[style]
    rest = SKELETON.rest_positions()
    wpos, wrot = world_pose(fig_bvh)
    n = fig_bvh.n_frames
    fi = {name: i for i, name in enumerate(fig_bvh.names)}
    names = [s[0] for s in specs]
    X: list[FloatArray] = []  # rest world position (m)
    C: list[FloatArray] = []  # rest correction
    Wt: list[FloatArray] = []  # world rotation over time
    for _name, parent, fig in specs:
        if isinstance(fig, tuple):
            p, c, frac = fig
            X.append(
                rest[SKELETON.index(p)] + frac * (rest[SKELETON.index(c)] - rest[SKELETON.index(p)])
            )
            k = names.index(parent) if parent else 0
            C.append(C[k])
            Wt.append(Wt[k])
        else:
            X.append(rest[SKELETON.index(fig)])
            C.append(_tpose(fig))
            Wt.append(quat.multiply(wrot[:, fi[fig]], C[-1]))
    joints: list[BvhJoint] = []
    rot = np.empty((n, len(specs), 4))
    pos = np.zeros((n, len(specs), 3))
    rot_ch = tuple(f"{a}rotation" for a in order)
    for k, (name, parent, fig) in enumerate(specs):
        pk = names.index(parent) if parent else -1
        if pk < 0:
            off = np.zeros(3)
            rot[:, k] = Wt[k]
            pos[:, k] = wpos[:, 0] * units
        else:
            off = quat.rotate(quat.conjugate(C[pk]), X[k] - X[pk]) * units
            rot[:, k] = quat.multiply(quat.conjugate(Wt[pk]), Wt[k])
            pos[:, k] = off
        end = None
        has_child = any(s[1] == name for s in specs)
        if not has_child:
            fig_end = _END_OF.get(fig if isinstance(fig, str) else "")
            if isinstance(fig, tuple):  # a finger base: end at the hand's end
                target = rest[SKELETON.index(fig[1])]
            elif fig_end is not None:
                target = rest[SKELETON.index(fig_end)]
            else:  # toes: a short stub along the toe's parent bone
                target = X[k] + 0.3 * (X[k] - X[pk])
            e = quat.rotate(quat.conjugate(C[k]), target - X[k]) * units
            end = (float(e[0]), float(e[1]), float(e[2]))
        ch = (("Xposition", "Yposition", "Zposition") if pk < 0 else ()) + rot_ch
        joints.append(
            BvhJoint(prefix + name, pk, (float(off[0]), float(off[1]), float(off[2])), ch, end)
        )
    return Bvh(joints, fig_bvh.frame_time_s, quat.normalize(rot), pos, source=f"<{style}>")
