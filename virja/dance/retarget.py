"""Retargeting a person's capture (BVH of a common skeleton) to virja's figure.

Captures name their joints in a few common ways; :func:`find_landmarks`
maps them onto the figure's joints (``virja.motion.skeleton.SKELETON``):

- HumanIK style (Autodesk MotionBuilder / Maya HumanIK, Mixamo with its
  ``mixamorig:`` prefix, the CMU database's BVH conversion): ``Hips``,
  ``Spine``/``Spine1``/``Spine2``, ``Neck``, ``Head``, ``LeftShoulder`` (the
  collar bone), ``LeftArm``, ``LeftForeArm``, ``LeftHand``, ``LeftUpLeg``,
  ``LeftLeg``, ``LeftFoot``, ``LeftToeBase``; CMU's extra ``LHipJoint``,
  ``LowerBack``, ``Neck1`` and finger joints are passed over;
- classic Biovision / older MotionBuilder export: ``Hips``, ``Chest``,
  ``Chest2``, ``LeftCollar``, ``LeftShoulder`` (the upper arm!),
  ``LeftElbow``, ``LeftWrist``, ``LeftHip``, ``LeftKnee``, ``LeftAnkle``,
  ``LeftToe``.  A file with ``LeftCollar`` or ``LeftElbow`` is read this way.

Names are compared without any ``prefix:``, case, ``_``, ``-`` or spaces.

The motion is carried over by *directions*, not by copying rotations, so
the capture's rest pose (T-pose, A-pose, arms down) and units do not
matter: every frame's joint positions come from the capture's forward
kinematics; the figure's hips and chest take the frame spanned by the
left-right axis (hips / shoulders) and the spine; every other bone of the
figure turns by the smallest rotation that points it along the captured
bone (no twist about the bone, which the figure's capsules do not show).
The waist path is scaled by figure leg length / capture leg length, so the
result is in metres.  Output: a :class:`~virja.motion.bvh.Bvh` on the
figure's skeleton, ready for ``teach``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from virja import quat
from virja.dance.audio import FloatArray
from virja.errors import VirjaError
from virja.motion.bvh import Bvh, BvhJoint, world_pose
from virja.motion.export import skeleton_joints
from virja.motion.skeleton import SKELETON


class RetargetError(VirjaError, ValueError):
    """The capture's skeleton cannot be mapped onto the figure."""


_SIDES = ("Left", "Right")
# figure joint -> candidate names (normalised), per naming style; {s} = left/right
_HUMANIK: dict[str, tuple[str, ...]] = {
    "Hips": ("hips", "pelvis", "root"),
    "Spine": ("spine", "spine0", "abdomen", "lowerback"),
    "Chest": ("spine2", "spine1", "chest", "upperchest", "spine3"),
    "Neck": ("neck", "neck1"),
    "Head": ("head",),
    "{S}Shoulder": ("{s}shoulder", "{s}clavicle", "{s}collar"),
    "{S}Arm": ("{s}arm", "{s}uparm", "{s}upperarm"),
    "{S}ForeArm": ("{s}forearm", "{s}lowarm", "{s}lowerarm"),
    "{S}Hand": ("{s}hand", "{s}wrist"),
    "{S}UpLeg": ("{s}upleg", "{s}thigh", "{s}upperleg"),
    "{S}Leg": ("{s}leg", "{s}shin", "{s}lowleg", "{s}lowerleg"),
    "{S}Foot": ("{s}foot", "{s}ankle"),
    "{S}Toe": ("{s}toebase", "{s}toe", "{s}toes"),
}
_CLASSIC: dict[str, tuple[str, ...]] = {
    "Hips": ("hips", "pelvis", "root"),
    "Spine": ("chest", "spine", "abdomen"),
    "Chest": ("chest2", "chest3", "chest"),
    "Neck": ("neck",),
    "Head": ("head",),
    "{S}Shoulder": ("{s}collar", "{s}clavicle"),
    "{S}Arm": ("{s}shoulder", "{s}uparm"),
    "{S}ForeArm": ("{s}elbow", "{s}forearm", "{s}lowarm"),
    "{S}Hand": ("{s}wrist", "{s}hand"),
    "{S}UpLeg": ("{s}hip", "{s}upleg", "{s}thigh"),
    "{S}Leg": ("{s}knee", "{s}leg", "{s}shin"),
    "{S}Foot": ("{s}ankle", "{s}foot"),
    "{S}Toe": ("{s}toe", "{s}toebase"),
}
_OPTIONAL = {
    "Spine",
    "Chest",
    "Neck",
    "LeftShoulder",
    "RightShoulder",
    "LeftHand",
    "RightHand",
    "LeftToe",
    "RightToe",
}
_ENDS = {"HeadEnd": "Head", "LeftHandEnd": "LeftHand", "RightHandEnd": "RightHand"}


def normalise(name: str) -> str:
    """``mixamorig:Left_Arm`` -> ``leftarm``."""
    return re.sub(r"[\s_\-.]", "", name.rsplit(":", 1)[-1]).lower()


def _side_names(side: str, pattern: str) -> list[str]:
    s = side.lower()
    short = s[0]  # l / r prefixes: LHand, RArm ...
    return [pattern.format(s=s), pattern.format(s=short)]


@dataclass(frozen=True)
class Landmarks:
    """Figure joint -> capture joint index (``style``: "humanik" or "classic")."""

    style: str
    joints: dict[str, int]


def find_landmarks(names: list[str]) -> Landmarks:
    """Map the capture's joint ``names`` onto the figure's joints (module docstring)."""
    norm = [normalise(n) for n in names]
    index = {n: i for i, n in reversed(list(enumerate(norm)))}  # first occurrence wins
    classic = "leftcollar" in index or "leftelbow" in index
    table = _CLASSIC if classic else _HUMANIK
    found: dict[str, int] = {}
    missing: list[str] = []
    for key, cands in table.items():
        sides = _SIDES if "{S}" in key else ("",)
        for side in sides:
            fig = key.replace("{S}", side)
            options = (
                [c for p in cands for c in _side_names(side, p.replace("{s}", "{s}"))]
                if side
                else list(cands)
            )
            used = set(found.values())
            hit = next((index[c] for c in options if c in index and index[c] not in used), None)
            if hit is None:
                if fig not in _OPTIONAL:
                    missing.append(fig)
            else:
                found[fig] = hit
    if missing:
        raise RetargetError(
            f"cannot map the capture onto the figure: no joint for {', '.join(missing)} "
            f"(names seen: {', '.join(names[:12])}{' ...' if len(names) > 12 else ''}; "
            "docs/dance.md lists the naming conventions read)"
        )
    return Landmarks("classic" if classic else "humanik", found)


def _children(bvh: Bvh, j: int) -> list[int]:
    return [k for k, joint in enumerate(bvh.joints) if joint.parent == j]


def _end_position(bvh: Bvh, pos: FloatArray, rot: FloatArray, j: int) -> FloatArray | None:
    """(n, 3) position of where joint ``j``'s bone ends: its first child or its end site."""
    kids = _children(bvh, j)
    if kids:
        return pos[:, kids[0]]
    end = bvh.joints[j].end_site
    if end is None or not np.any(end):
        return None
    return pos[:, j] + quat.rotate(rot[:, j], np.asarray(end, dtype=np.float64))


def figure_joints() -> list[BvhJoint]:
    """BVH joints of the figure's skeleton (root with position channels, metres)."""
    return skeleton_joints()


def is_figure_skeleton(bvh: Bvh) -> bool:
    """True if ``bvh`` already uses the figure's joints in the figure's order."""
    return tuple(bvh.names) == SKELETON.names


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.asarray(v / np.where(n > 1e-12, n, 1.0), dtype=np.float64)


def _frame_y(x: FloatArray, y: FloatArray) -> FloatArray:
    """Rotation with its y axis along ``y`` exactly and its x axis as close to ``x`` as may be."""
    y = _unit(y)
    x = _unit(x - np.sum(x * y, axis=-1, keepdims=True) * y)
    return quat.from_frame(x, y)


def retarget_to_figure(bvh: Bvh) -> Bvh:
    """The capture's motion on the figure's skeleton (module docstring), metres."""
    lm = find_landmarks(bvh.names)
    pos, rot = world_pose(bvh)
    n = bvh.n_frames
    P: dict[str, FloatArray] = {k: pos[:, j] for k, j in lm.joints.items()}
    # optional joints: derived from their neighbours
    if "Spine" not in P:
        P["Spine"] = P["Hips"] + 0.2 * (P.get("Neck", P["Head"]) - P["Hips"])
    if "Chest" not in P:
        P["Chest"] = P["Spine"] + 0.5 * (P.get("Neck", P["Head"]) - P["Spine"])
    if "Neck" not in P:
        P["Neck"] = P["Chest"] + 0.7 * (P["Head"] - P["Chest"])
    for side in _SIDES:
        if f"{side}Hand" not in P:  # a forearm ending in an end site: the hand is there
            end = _end_position(bvh, pos, rot, lm.joints[f"{side}ForeArm"])
            if end is not None:
                P[f"{side}Hand"] = end
        if f"{side}Shoulder" not in P:
            P[f"{side}Shoulder"] = P["Chest"] + 0.5 * (P[f"{side}Arm"] - P["Chest"])
        if f"{side}Toe" not in P:
            end = _end_position(bvh, pos, rot, lm.joints[f"{side}Foot"])
            if end is not None:
                P[f"{side}Toe"] = end
    for end_name, of in _ENDS.items():
        if of not in lm.joints:
            continue
        cap = lm.joints[of]
        kids = _children(bvh, cap)
        if of == "Head":
            e = _end_position(bvh, pos, rot, cap)
        elif kids:  # a hand's end: the mean of its finger roots
            e = np.mean(pos[:, kids], axis=1)
        else:
            e = _end_position(bvh, pos, rot, cap)
        if e is not None and np.all(np.linalg.norm(e - P[of], axis=-1) > 1e-9):
            P[end_name] = e
    leg = np.mean(
        [
            np.linalg.norm(P[f"{s}Leg"][0] - P[f"{s}UpLeg"][0])
            + np.linalg.norm(P[f"{s}Foot"][0] - P[f"{s}Leg"][0])
            for s in _SIDES
        ]
    )
    if not leg > 0:
        raise RetargetError("cannot retarget: the capture's legs have no length at frame 0")
    fig_leg = float(
        np.linalg.norm(SKELETON.offsets[SKELETON.index("LeftLeg")])
        + np.linalg.norm(SKELETON.offsets[SKELETON.index("LeftFoot")])
    )
    scale = fig_leg / leg

    names = SKELETON.names
    J = len(names)
    W = np.empty((n, J, 4))
    local = np.empty((n, J, 4))
    hips_x = _unit(P["LeftUpLeg"] - P["RightUpLeg"])
    collar = "Shoulder" if all(f"{s}Shoulder" in lm.joints for s in _SIDES) else "Arm"
    chest_x = _unit(P[f"Left{collar}"] - P[f"Right{collar}"])
    W[:, 0] = _frame_y(hips_x, P["Spine"] - P["Hips"])
    for j in range(1, J):
        name = names[j]
        par = int(SKELETON.parents[j])
        wp = W[:, par]
        if name == "Chest":
            W[:, j] = _frame_y(chest_x, P["Neck"] - P["Chest"])
        elif name == "Spine":  # the twist between hips and chest, shared half-way
            W[:, j] = _frame_y(hips_x + chest_x, P["Chest"] - P["Spine"])
        else:
            kids = [k for k in range(J) if int(SKELETON.parents[k]) == j]
            child = names[kids[0]] if kids else None
            if child is None or child not in P or name not in P:
                W[:, j] = wp  # an end, or no captured direction: no rotation of its own
            else:
                rest_dir = quat.rotate(wp, _unit(SKELETON.offsets[kids[0]]))
                swing = quat.from_two_vectors(rest_dir, _unit(P[child] - P[name]))
                W[:, j] = quat.normalize(quat.multiply(swing, wp))
        local[:, j] = quat.normalize(quat.multiply(quat.conjugate(wp), W[:, j]))
    local[:, 0] = W[:, 0]
    positions = np.broadcast_to(SKELETON.offsets, (n, J, 3)).copy()
    positions[:, 0] = P["Hips"] * scale
    return Bvh(figure_joints(), bvh.frame_time_s, local, positions, source=bvh.source)
