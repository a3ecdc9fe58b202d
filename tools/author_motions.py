"""Author the basic-motion library in motions/ by inverse kinematics.

Every gesture (preparation, strike, rebound, return) is a path of the
contact point (stick tip, toe, fingertip) through key points placed against
:mod:`virja.geometry`; each frame is solved with analytic two-bone IK, so at
the impact frame the contact point lies exactly on the instrument.
Deterministic: running it again rewrites the same files.

    .venv/bin/python tools/author_motions.py [--out motions]

Writes motions/drums/*.bvh|toml and motions/bass/*.bvh|toml (never the
scheduler's cost/timing tables at the top of motions/).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

import numpy as np

from virja import quat
from virja.geometry import GEOMETRY, Geometry
from virja.motion import ik
from virja.motion.bvh import Bvh, BvhJoint, write_bvh
from virja.motion.skeleton import (
    LIMB_JOINTS,
    SKELETON,
    STICK_AXIS_LOCAL,
    STICK_TIP_M,
)
from virja.vocab import (
    ALL_BASS_STRINGS,
    FOOT_KINDS,
    FRET_OPEN_CLIP,
    HAND_PIECES,
    HANDS,
    BassPluck,
    DrumStroke,
    idle_clip,
)

FPS = 60.0
SK = SKELETON
UP = np.array([0.0, 1.0, 0.0])
HAND_END = SK.offsets[SK.index("LeftHandEnd")]  # (0, -0.08, 0): wrist -> grip / fingertip
TOE = SK.offsets[SK.index("LeftToe")]
FOOT_LEN = float(np.linalg.norm(TOE))
ARM_LEN = (
    float(np.linalg.norm(SK.offsets[SK.index("LeftForeArm")])),
    float(np.linalg.norm(SK.offsets[SK.index("LeftHand")])),
)
LEG_LEN = (
    float(np.linalg.norm(SK.offsets[SK.index("LeftLeg")])),
    float(np.linalg.norm(SK.offsets[SK.index("LeftFoot")])),
)
ARM_REST_DIR, ARM_REST_HINGE = np.array([0.0, -1.0, 0.0]), np.array([-1.0, 0.0, 0.0])
LEG_REST_DIR, LEG_REST_HINGE = np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0])
MAX_FRET = 20
NOMINAL_VELOCITY = 96


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _smooth(u: float) -> float:
    return u * u * (3.0 - 2.0 * u)


class Body:
    """A figure's base pose (locals) with helpers to pose one limb by IK."""

    def __init__(self, root: np.ndarray, torso: dict[str, np.ndarray]) -> None:
        self.root = root
        self.local = quat.identity((SK.n_joints,))
        for name, q in torso.items():
            self.local[SK.index(name)] = q
        self._update()

    def _update(self) -> None:
        self.wpos, self.wrot = SK.fk(self.local, self.root)

    def copy(self) -> Body:
        b = Body.__new__(Body)
        b.root = self.root
        b.local = self.local.copy()
        b._update()
        return b

    def pos(self, name: str) -> np.ndarray:
        return self.wpos[SK.index(name)]

    def arm(self, side: str, wrist: np.ndarray, hand_world: np.ndarray, pole: np.ndarray) -> bool:
        """Put the ``side`` ("Left"/"Right") wrist at ``wrist`` with the hand's world rotation."""
        sh = SK.index(f"{side}Shoulder")
        root = self.pos(f"{side}Arm")
        sol = ik.two_bone(root, wrist, pole, *ARM_LEN, ARM_REST_DIR, ARM_REST_HINGE)
        self.local[SK.index(f"{side}Arm")] = ik.local_from_world(self.wrot[sh], sol.upper)
        self.local[SK.index(f"{side}ForeArm")] = ik.local_from_world(sol.upper, sol.lower)
        self.local[SK.index(f"{side}Hand")] = ik.local_from_world(sol.lower, hand_world)
        self._update()
        return sol.reached

    def leg(self, side: str, ankle: np.ndarray, toe: np.ndarray, pole: np.ndarray) -> bool:
        """Put the ``side`` ankle at ``ankle`` and point the foot at ``toe`` (|toe - ankle| = foot)."""
        root = self.pos(f"{side}UpLeg")
        sol = ik.two_bone(root, ankle, pole, *LEG_LEN, LEG_REST_DIR, LEG_REST_HINGE)
        self.local[SK.index(f"{side}UpLeg")] = ik.local_from_world(self.wrot[0], sol.upper)
        self.local[SK.index(f"{side}Leg")] = ik.local_from_world(sol.upper, sol.lower)
        foot = ik.aim(_unit(TOE), np.array([1.0, 0, 0]), _unit(toe - ankle), np.array([1.0, 0, 0]))
        self.local[SK.index(f"{side}Foot")] = ik.local_from_world(sol.lower, foot)
        self._update()
        return sol.reached


# ----------------------------------------------------------------------------- drummer


def drummer_body(geo: Geometry) -> Body:
    o = geo.stage.drummer_origin
    torso = {
        "Spine": quat.from_axis_angle([1, 0, 0], 0.12),  # lean 7 deg toward the kit
        "Neck": quat.from_axis_angle([1, 0, 0], -0.10),  # head upright again
    }
    return Body(o + np.array([0.0, 0.60, 0.0]), torso)


STICK_PITCH_RAD = 0.30  # sticks slope down 17 deg toward what they strike
# Sticks converge in a V (matched grip): each stick points along the line from a
# point 12 cm outside and 10 cm ahead of its shoulder to the tip, so on the snare
# the two sticks meet at ~75 deg and the hands sit outside the tips, well ahead of
# the belly, instead of straight behind the tips against the body.
STICK_ANCHOR = np.array([0.12, 0.0, 0.10])
READY_RISE_M = 0.07  # at rest the stick tips hover 7 cm over the snare


def stick_hand(body: Body, side: str, tip: np.ndarray, rise: float = 0.0) -> bool:
    """Pose the ``side`` arm so its stick tip is exactly at ``tip``.

    The stick points from above and behind: horizontally along the line from
    a point outside and ahead of the shoulder (STICK_ANCHOR) to the tip, pitched
    down STICK_PITCH_RAD, so the sticks slope down onto the heads and converge
    toward the middle of the kit.  ``rise``
    (m) is how far the tip is lifted above its stroke's strike point: the wrist
    takes most of the lift (the stick tilts up), as drummers do.
    """
    pitch = float(np.arcsin(np.clip(np.sin(STICK_PITCH_RAD) - 0.8 * rise / STICK_TIP_M, -0.6, 0.9)))
    s = 1.0 if side == "Left" else -1.0
    shoulder = body.pos(f"{side}Arm")
    flat = tip - (shoulder + STICK_ANCHOR * np.array([s, 1.0, 1.0]))
    flat[1] = 0.0
    flat = _unit(flat)
    d = np.cos(pitch) * flat - np.sin(pitch) * UP
    grip = tip - STICK_TIP_M * d
    pole = shoulder + np.array([s * 0.40, -0.35, -0.20])
    side_axis = np.cross(UP, d) + 1e-9 * UP
    reached = False
    for _ in range(3):
        # roll the hand like the forearm (no wrist twist): take the forearm's side axis
        hand = ik.aim(STICK_AXIS_LOCAL, np.array([1.0, 0, 0]), d, side_axis)
        wrist = grip - quat.rotate(hand, HAND_END)
        reached = body.arm(side, wrist, hand, pole)
        side_axis = quat.rotate(body.wrot[SK.index(f"{side}ForeArm")], np.array([1.0, 0, 0]))
    return reached


def drummer_ready(body: Body, geo: Geometry) -> None:
    kit = geo.kit
    snare = kit.pieces["snare"]
    sp = kit.strike_point("snare")
    stick_hand(
        body, "Left", sp + np.array([0.05, 0, 0]) + READY_RISE_M * snare.normal, READY_RISE_M
    )
    stick_hand(
        body, "Right", sp + np.array([-0.10, 0, 0.02]) + READY_RISE_M * snare.normal, READY_RISE_M
    )
    for side, pedal in (("Left", kit.hihat_pedal), ("Right", kit.kick_pedal)):
        ankle = foot_ankle(pedal)
        body.leg(
            side,
            ankle,
            ankle + FOOT_LEN * _unit(pedal.toe_point(False) - ankle),
            knee_pole(body, side),
        )


def foot_ankle(pedal: object) -> np.ndarray:
    """Ankle above the heel plate, exactly a foot's length from the pressed toe point."""
    press = pedal.toe_point(True)  # type: ignore[attr-defined]
    guess = pedal.heel + np.array([0.0, 0.085, -0.02])  # type: ignore[attr-defined]
    return np.asarray(press + FOOT_LEN * _unit(guess - press))


def knee_pole(body: Body, side: str) -> np.ndarray:
    s = 1.0 if side == "Left" else -1.0
    return body.pos(f"{side}UpLeg") + np.array([s * 0.10, 0.30, 0.60])


Path3 = Callable[[float], np.ndarray]


def keyed_path(keys: list[tuple[float, np.ndarray, str]]) -> Path3:
    """A piecewise path through (time, point, easing into this key) keys."""

    def at(t: float) -> np.ndarray:
        if t <= keys[0][0]:
            return keys[0][1]
        for (t0, p0, _), (t1, p1, ease) in zip(keys[:-1], keys[1:], strict=True):
            if t <= t1:
                u = (t - t0) / (t1 - t0)
                s = {"smooth": _smooth(u), "accel": u * u, "decel": 1 - (1 - u) ** 2}[ease]
                return np.asarray(p0 + s * (p1 - p0))
        return keys[-1][1]

    return at


def hand_stroke(geo: Geometry, piece: str, side: str) -> tuple[np.ndarray, np.ndarray, float]:
    """A stroke on ``piece``; a piece across the kit that the arm cannot reach at
    its usual spot (the left hand on the ride) is struck nearer its edge."""
    fraction = geo.kit.strike_in[piece]
    while True:
        try:
            return _hand_stroke(geo, piece, side, fraction)
        except OutOfReach:
            if fraction >= 0.9:
                raise
            fraction = min(0.9, fraction + 0.1)


class OutOfReach(SystemExit):
    """A key point of a stroke is beyond the arm's reach."""


def _hand_stroke(
    geo: Geometry, piece: str, side: str, fraction: float
) -> tuple[np.ndarray, np.ndarray, float]:
    base = drummer_body(geo)
    drummer_ready(base, geo)
    limb = f"{side.lower()}_hand"
    ready = (
        base.pos(f"{side}HandEnd")
        + quat.rotate(base.wrot[SK.index(f"{side}Hand")], STICK_AXIS_LOCAL) * STICK_TIP_M
    )
    p = geo.kit.pieces[piece]
    strike = geo.kit.strike_point(piece, base.pos(f"{side}Arm"), fraction)
    travel = float(np.linalg.norm(strike - ready))
    # seconds from the ready pose to impact: farther pieces take longer; on a frame
    prep = _on_frame(0.22 + 0.35 * travel)
    lift = 0.16  # stick height over the head at the top of the back-swing, mf
    ready_rise = READY_RISE_M
    end = _on_frame(prep + 0.25 + 0.30 * travel)
    keys = [
        (0.0, ready, "smooth"),
        (0.6 * prep, strike + lift * p.normal, "smooth"),
        (prep, strike, "accel"),  # the stick accelerates into the head
        (prep + 0.10, strike + 0.07 * p.normal, "decel"),  # rebound
        (end, ready, "smooth"),
    ]
    # how far the tip is "lifted" (sets how much the wrist tilts the stick up),
    # keyed like the path so the first and last frames are the ready pose exactly
    rises = [ready_rise, lift, 0.0, 0.07, ready_rise]
    rise_path = keyed_path(
        [(k[0], np.array([r, 0.0, 0.0]), k[2]) for k, r in zip(keys, rises, strict=True)]
    )
    path = keyed_path(keys)
    frames = _frames(keys[-1][0])
    out = []
    for t in frames:
        b = base.copy()
        if not stick_hand(b, side, path(t), float(rise_path(t)[0])):
            raise OutOfReach(f"{piece} {limb}: stick tip out of reach at t={t:.3f}")
        out.append(b.local.copy())
    return np.array(out), base.root, prep


def foot_stroke(geo: Geometry, piece: str, side: str) -> tuple[np.ndarray, np.ndarray, float]:
    base = drummer_body(geo)
    drummer_ready(base, geo)
    pedal = geo.kit.kick_pedal if piece == "kick" else geo.kit.hihat_pedal
    ankle = foot_ankle(pedal)
    rest_dir = _unit(pedal.toe_point(False) - ankle)
    press_dir = _unit(pedal.toe_point(True) - ankle)
    axis = np.cross(press_dir, rest_dir)
    lift_dir = quat.rotate(
        quat.from_axis_angle(axis, np.radians(14.0)), rest_dir
    )  # toe up 14 deg more
    prep = _on_frame(0.20)
    keys = [
        (0.0, ankle + FOOT_LEN * rest_dir, "smooth"),
        (0.55 * prep, ankle + FOOT_LEN * lift_dir, "smooth"),
        (prep, ankle + FOOT_LEN * press_dir, "accel"),
        (prep + 0.08, ankle + FOOT_LEN * _unit(press_dir + rest_dir), "decel"),
        (_on_frame(prep + 0.30), ankle + FOOT_LEN * rest_dir, "smooth"),
    ]
    path = keyed_path(keys)
    out = []
    for t in _frames(keys[-1][0]):
        b = base.copy()
        toe = ankle + FOOT_LEN * _unit(path(t) - ankle)
        b.leg(side, ankle, toe, knee_pole(b, side))
        out.append(b.local.copy())
    return np.array(out), base.root, prep


def _on_frame(t: float) -> float:
    """``t`` rounded to a whole frame, so the impact is a frame of its own (exact contact)."""
    return round(t * FPS) / FPS


def _frames(duration: float) -> np.ndarray:
    n = int(round(duration * FPS))
    return np.arange(n + 1) / FPS


# ----------------------------------------------------------------------------- bassist


def bassist_body(geo: Geometry) -> Body:
    o = geo.stage.bassist_origin
    torso = {
        "Spine": quat.from_axis_angle([0, 1, 0], 0.40),  # turned 23 deg toward the bass (his left)
        "Chest": quat.from_axis_angle([1, 0, 0], 0.08),
    }
    return Body(o + np.array([0.0, 0.96, -0.05]), torso)


def finger_hand(
    body: Body, side: str, tip: np.ndarray, into: np.ndarray, pole_off: np.ndarray
) -> bool:
    """Pose the ``side`` arm with its fingertip (hand end joint) exactly at ``tip``."""
    shoulder = body.pos(f"{side}Arm")
    d = _unit(_unit(tip - shoulder) + 0.8 * into)
    side_axis = np.cross(UP, d)
    if np.linalg.norm(side_axis) < 1e-6:
        side_axis = np.array([1.0, 0, 0])
    hand = ik.aim(np.array([0.0, -1.0, 0]), np.array([1.0, 0, 0]), d, side_axis)
    wrist = tip - quat.rotate(hand, HAND_END)
    return body.arm(side, wrist, hand, shoulder + pole_off)


LEFT_POLE = np.array([0.45, -0.35, -0.10])
# the fretting hand comes round the neck from its E side (the player's left, where the
# arm is): from the wrist to the fingertip mostly across the fingerboard toward the G
# side level with the strings (over the fingerboard, never through it) and down the
# neck; the thumb (virja.motion.bassist) stays behind the neck
FRET_HAND_DIR = (-0.85, 0.0, -0.45)  # (lateral toward E, front, axis toward the scroll)


def fret_hand(body: Body, geo: Geometry, tip: np.ndarray) -> bool:
    """Pose the left arm with its fingertip at ``tip``, the hand round the neck's E side
    (where the arm cannot reach so far round, high up the low strings, less far)."""
    b = geo.bass
    lateral = _unit(np.cross(b.axis, b.front))
    lt, fr, ax = FRET_HAND_DIR
    want = _unit(lt * lateral + fr * b.front + ax * b.axis)
    shoulder = body.pos("LeftArm")
    plain = _unit(_unit(tip - shoulder) - 0.8 * b.front)  # straight at the string
    for w in (1.0, 0.8, 0.6, 0.4, 0.2, 0.0):
        d = _unit(w * want + (1.0 - w) * plain)
        hand = ik.aim(np.array([0.0, -1.0, 0]), np.array([1.0, 0, 0]), d, -b.front)
        wrist = tip - quat.rotate(hand, HAND_END)
        trial = body.copy()
        if trial.arm("Left", wrist, hand, shoulder + LEFT_POLE):
            body.local, body.wpos, body.wrot = trial.local, trial.wpos, trial.wrot
            return True
    return False


RIGHT_POLE = np.array([-0.40, -0.40, -0.20])


def bass_ready(body: Body, geo: Geometry) -> None:
    b = geo.bass
    fret_hand(body, geo, b.string_point("D", 5) + 0.02 * b.front)
    finger_hand(body, "Right", right_ready(geo), -b.front, RIGHT_POLE)


def right_ready(geo: Geometry) -> np.ndarray:
    b = geo.bass
    mid = 0.5 * (b.pluck_point("A") + b.pluck_point("D"))
    return np.asarray(mid + 0.015 * b.front)


def fret_hold(geo: Geometry, string: str | None, fret: int) -> tuple[np.ndarray, np.ndarray, float]:
    base = bassist_body(geo)
    bass_ready(base, geo)
    b = geo.bass
    impact = _on_frame(0.06)
    if string is None:  # release: back to the idle hand
        frames = [base.local.copy() for _ in _frames(0.12)]
        return np.array(frames), base.root, impact
    target = b.string_point(string, fret)
    keys = [
        (0.0, target + 0.02 * b.front, "smooth"),  # finger just off the string
        (impact, target, "accel"),  # press
        (0.12, target, "smooth"),  # hold
    ]
    path = keyed_path(keys)
    out = []
    for t in _frames(0.12):
        body = base.copy()
        if not fret_hand(body, geo, path(t)):
            raise SystemExit(f"fret {string}{fret}: out of reach")
        out.append(body.local.copy())
    return np.array(out), base.root, impact


def pluck(geo: Geometry, string: str) -> tuple[np.ndarray, np.ndarray, float]:
    base = bassist_body(geo)
    bass_ready(base, geo)
    b = geo.bass
    lateral = _unit(np.cross(b.axis, b.front))
    p = b.pluck_point(string)
    # pizzicato from the side: the hand waits just off the middle strings and the
    # finger does the work, so the arm stays almost still (a few cm, not the forearm)
    ready = right_ready(geo)
    prep = _on_frame(0.14)
    keys = [
        (0.0, ready, "smooth"),
        (0.6 * prep, p + 0.008 * b.front + 0.006 * lateral, "smooth"),
        (prep, p, "accel"),  # finger on the string at the moment it lets go
        (
            prep + 0.06,
            p + 0.02 * lateral - 0.004 * b.front,
            "decel",
        ),  # pull through toward the next string
        (_on_frame(prep + 0.30), ready, "smooth"),
    ]
    path = keyed_path(keys)
    out = []
    for t in _frames(keys[-1][0]):
        body = base.copy()
        if not finger_hand(body, "Right", path(t), -b.front, RIGHT_POLE):
            raise SystemExit(f"pluck {string}: out of reach at t={t:.3f}")
        out.append(body.local.copy())
    return np.array(out), base.root, prep


# ----------------------------------------------------------------------------- writing


def _joints() -> list[BvhJoint]:
    out = []
    for i, name in enumerate(SK.names):
        ch: tuple[str, ...] = ("Zrotation", "Xrotation", "Yrotation")
        if i == 0:
            ch = ("Xposition", "Yposition", "Zposition") + ch
        out.append(BvhJoint(name, int(SK.parents[i]), tuple(float(x) for x in SK.offsets[i]), ch))  # type: ignore[arg-type]
    return out


def write_clip(
    folder: Path,
    name: str,
    locals_: np.ndarray,
    root: np.ndarray,
    meta: dict[str, object],
    comment: str,
) -> None:
    n = locals_.shape[0]
    pos = np.broadcast_to(SK.offsets, (n, SK.n_joints, 3)).copy()
    pos[:, 0] = root
    write_bvh(Bvh(_joints(), 1.0 / FPS, locals_, pos), folder / f"{name}.bvh", decimals=3)
    lines = [
        f"# {comment}",
        "# written by tools/author_motions.py; run it again rather than editing",
    ]
    for k, v in meta.items():
        if isinstance(v, str):
            lines.append(f'{k} = "{v}"')
        elif isinstance(v, list):
            lines.append(f"{k} = [" + ", ".join(f'"{x}"' for x in v) + "]")
        elif isinstance(v, float):
            lines.append(f"{k} = {v:.6f}")
        else:
            lines.append(f"{k} = {v}")
    (folder / f"{name}.toml").write_text("\n".join(lines) + "\n", encoding="utf-8")


def author(out: Path, geo: Geometry = GEOMETRY) -> int:
    drums = out / "drums"
    bass = out / "bass"
    drums.mkdir(parents=True, exist_ok=True)
    bass.mkdir(parents=True, exist_ok=True)
    count = 0
    for piece in HAND_PIECES:
        for limb in HANDS:
            side = "Left" if limb == "left_hand" else "Right"
            loc, root, imp = hand_stroke(geo, piece, side)
            meta = {
                "performer": "drums",
                "limb": limb,
                "kind": "stroke",
                "impact_s": imp,
                "joints": list(LIMB_JOINTS[limb]),
                "piece": piece,
                "velocity": NOMINAL_VELOCITY,
            }
            write_clip(
                drums,
                DrumStroke(piece, limb).clip,
                loc,
                root,
                meta,
                f"{piece} struck with the {side.lower()} stick: ready, back-swing, strike, rebound, ready",
            )
            count += 1
    for piece, limb in FOOT_KINDS:
        side = "Left" if limb == "left_foot" else "Right"
        loc, root, imp = foot_stroke(geo, piece, side)
        meta = {
            "performer": "drums",
            "limb": limb,
            "kind": "stroke",
            "impact_s": imp,
            "joints": list(LIMB_JOINTS[limb]),
            "piece": piece,
            "velocity": NOMINAL_VELOCITY,
        }
        write_clip(
            drums,
            DrumStroke(piece, limb).clip,
            loc,
            root,
            meta,
            f"{piece} pedal with the {side.lower()} foot: toe up, press, rebound",
        )
        count += 1
    body = drummer_body(geo)
    drummer_ready(body, geo)
    write_clip(
        drums,
        idle_clip("drums"),
        np.array([body.local, body.local]),
        body.root,
        {"performer": "drums", "kind": "idle", "impact_s": 0.0, "joints": list(SK.names)},
        "the drummer's ready pose: sticks over the snare, feet on the pedals",
    )
    count += 1
    for s in ALL_BASS_STRINGS:  # the five- and six-string basses' B and C too
        for f in range(1, MAX_FRET + 1):
            loc, root, imp = fret_hold(geo, s, f)
            meta = {
                "performer": "bass",
                "limb": "left_hand",
                "kind": "hold",
                "impact_s": imp,
                "joints": list(LIMB_JOINTS["left_hand"]),
                "string": s,
                "fret": f,
            }
            write_clip(
                bass,
                BassPluck(s, f).hold_clip,
                loc,
                root,
                meta,
                f"left hand stops the {s} string at fret {f}: approach, press, hold",
            )
            count += 1
        loc, root, imp = pluck(geo, s)
        meta = {
            "performer": "bass",
            "limb": "right_hand",
            "kind": "stroke",
            "impact_s": imp,
            "joints": list(LIMB_JOINTS["right_hand"]),
            "string": s,
            "velocity": NOMINAL_VELOCITY,
        }
        write_clip(
            bass,
            BassPluck(s, 0).pluck_clip,
            loc,
            root,
            meta,
            f"right hand plucks the {s} string: approach, pull through, back",
        )
        count += 1
    loc, root, imp = fret_hold(geo, None, 0)
    write_clip(
        bass,
        FRET_OPEN_CLIP,
        loc,
        root,
        {
            "performer": "bass",
            "limb": "left_hand",
            "kind": "hold",
            "impact_s": imp,
            "joints": list(LIMB_JOINTS["left_hand"]),
            "fret": 0,
        },
        "left hand lets go of the strings (open string): back to its rest by the neck",
    )
    body = bassist_body(geo)
    bass_ready(body, geo)
    write_clip(
        bass,
        idle_clip("bass"),
        np.array([body.local, body.local]),
        body.root,
        {"performer": "bass", "kind": "idle", "impact_s": 0.0, "joints": list(SK.names)},
        "the bassist's rest pose: left hand by the neck, right hand over the strings",
    )
    return count + 2


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent.parent / "motions")
    args = ap.parse_args(argv)
    n = author(args.out)
    print(f"wrote {n} clips under {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
