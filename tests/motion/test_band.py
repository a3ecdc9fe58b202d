"""BandAnimator: contact at impact for every clip, time warp, blending, masks, kit state."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tests.motion.helpers import bass, drum
from virja import quat
from virja.geometry import GEOMETRY
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary, UnknownMotionError, default_library
from virja.motion.drummer_body import BodySettings
from virja.motion.drummer_hands import HandSettings
from virja.motion.metrics import contact_distance
from virja.motion.skeleton import LIMB_JOINTS, SKELETON
from virja.vocab import BASS_STRINGS, HAND_PIECES, BassPluck, DrumStroke

DRUM_MOTIONS = [f"{p}_{h}" for p in HAND_PIECES for h in ("left_hand", "right_hand")] + [
    "kick_right_foot",
    "hihat_left_foot",
]
# the limb layer alone: these tests check the clips and their connections
STILL = BodySettings.still()
CLIPS = HandSettings.clips()  # the hands as their clips move them (not from where they are)
TOL = 0.01  # 1 cm


def test_library_has_every_basic_motion(library: MotionLibrary) -> None:
    want = set(DRUM_MOTIONS) | {"idle_drums", "idle_bass", "fret_open"}
    want |= {f"pluck_{s}" for s in BASS_STRINGS}
    want |= {f"fret_{s}_{f}" for s in BASS_STRINGS for f in range(1, 21)}
    assert want <= set(library)


@pytest.mark.parametrize("motion", DRUM_MOTIONS)
def test_drum_stroke_contact_within_1cm_at_impact(library: MotionLibrary, motion: str) -> None:
    clip = library[motion]
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    p = drum(motion, 1.0, 1.0 + clip.impact_s)
    a.add_planned(p)
    assert contact_distance(a, p, p.impact)[0] < TOL


@pytest.mark.parametrize("string", BASS_STRINGS)
def test_every_fret_contact_within_1cm_at_impact(library: MotionLibrary, string: str) -> None:
    for fret in range(0, 21):
        a = BandAnimator(library, body=STILL, hands=CLIPS)
        p = bass(string, fret, 1.0, 1.2)
        a.add_planned(p)
        pluck, fretting = contact_distance(a, p, p.impact)
        assert pluck < TOL, (string, fret)
        if fret:
            assert fretting is not None and fretting < TOL, (string, fret, fretting)


@pytest.mark.parametrize("prep_s", [0.06, 0.2, 0.6])
def test_time_warp_keeps_start_and_impact(library: MotionLibrary, prep_s: float) -> None:
    """The clip's first frame shows at ``start`` and the contact lands at ``impact``."""
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    p = drum("snare_right_hand", 2.0, 2.0 + prep_s)
    a.add_planned(p)
    idle = library["idle_drums"].rotations[0]
    assert contact_distance(a, p, p.impact)[0] < TOL
    # at start the pose is the clip's first frame (== the ready pose): nothing moved yet
    loc = a.local_rotations(2.0)[0]
    assert quat.angle_between(loc, idle).max() < 1e-6
    # closest approach of the stick tip is at the impact (1 ms grid)
    ts = p.impact + np.arange(-30, 31) * 1e-3
    d = [contact_distance(a, p, float(t))[0] for t in ts]
    assert abs(ts[int(np.argmin(d))] - p.impact) <= 1e-3 + 1e-9


def test_stroke_clips_start_and_end_in_the_ready_pose(library: MotionLibrary) -> None:
    """So a limb goes from rest into a stroke and back without a jump."""
    for clip in library.clips():
        if clip.kind != "stroke":
            continue
        idle = library[f"idle_{clip.performer}"].rotations[0, clip.joint_index]
        assert quat.angle_between(clip.rotations[0, clip.joint_index], idle).max() < 1e-4, clip.name
        assert quat.angle_between(clip.rotations[-1, clip.joint_index], idle).max() < 1e-4, (
            clip.name
        )


def _limb_locals(a: BandAnimator, t: float, limb: str) -> np.ndarray:
    return a.local_rotations(t)[0][SKELETON.mask(LIMB_JOINTS[limb])]


def test_crossfade_only_inside_the_overlap(library: MotionLibrary) -> None:
    """Outside [B.start, A.end] the limb shows A alone or B alone, exactly."""
    pa = drum("snare_left_hand", 1.0, 1.25)
    pb = drum("tom_high_left_hand", 1.35, 1.65)
    only_a, only_b, both = (
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
    )
    only_a.add_planned(pa)
    only_b.add_planned(pb)
    both.add_planned(pa)
    both.add_planned(pb)
    inst_b = both.timelines[("drums", "left_hand")].instances[1]
    r0, r1 = inst_b.ramp_start, inst_b.ramp_end
    assert r0 is not None and r1 is not None and r0 < r1
    for t in np.arange(0.9, r0, 0.01):
        assert (
            quat.angle_between(
                _limb_locals(both, t, "left_hand"), _limb_locals(only_a, t, "left_hand")
            ).max()
            < 1e-9
        )
    for t in np.arange(r1, 2.2, 0.01):
        assert (
            quat.angle_between(
                _limb_locals(both, t, "left_hand"), _limb_locals(only_b, t, "left_hand")
            ).max()
            < 1e-9
        )


def test_crossfade_weights_go_linearly_from_a_to_b(library: MotionLibrary) -> None:
    pa = drum("snare_left_hand", 1.0, 1.25)
    pb = drum("tom_high_left_hand", 1.35, 1.65)
    a, oa, ob = (
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
    )
    for an, ps in ((a, (pa, pb)), (oa, (pa,)), (ob, (pb,))):
        for p in ps:
            an.add_planned(p)
    inst_b = a.timelines[("drums", "left_hand")].instances[1]
    assert inst_b.ramp_start is not None and inst_b.ramp_end is not None
    for w in (0.25, 0.5, 0.75):
        t = inst_b.ramp_start + w * (inst_b.ramp_end - inst_b.ramp_start)
        want = quat.slerp(_limb_locals(oa, t, "left_hand"), _limb_locals(ob, t, "left_hand"), w)
        assert quat.angle_between(_limb_locals(a, t, "left_hand"), want).max() < 1e-9


def test_fast_repeat_keeps_both_impacts(library: MotionLibrary) -> None:
    """B starts before A's impact: the connection waits for A's impact, both land."""
    pa = drum("snare_right_hand", 1.0, 1.2)
    pb = drum("snare_right_hand", 1.1, 1.3)
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    a.add_planned(pa)
    a.add_planned(pb)
    assert contact_distance(a, pa, pa.impact)[0] < TOL
    assert contact_distance(a, pb, pb.impact)[0] < TOL


@pytest.mark.parametrize(
    ("performer", "limb", "note"),
    [
        ("drums", "right_hand", drum("ride_right_hand", 1.0, 1.3)),
        ("drums", "left_foot", drum("hihat_left_foot", 1.0, 1.2)),
        ("drums", "right_foot", drum("kick_right_foot", 1.0, 1.2)),
    ],
)
def test_limb_masks_are_independent(
    library: MotionLibrary, performer: str, limb: str, note: object
) -> None:
    """A motion of one limb changes that limb's joints only (and never the other figure)."""
    base, moved = (
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
    )
    base.add_planned(drum("snare_left_hand", 1.0, 1.25))
    moved.add_planned(drum("snare_left_hand", 1.0, 1.25))
    moved.add_planned(note)  # type: ignore[arg-type]
    mask = SKELETON.mask(LIMB_JOINTS[limb])
    changed = False
    for t in np.arange(0.95, 1.8, 0.02):
        la, lb = base.local_rotations(t), moved.local_rotations(t)
        assert quat.angle_between(la[0][~mask], lb[0][~mask]).max() < 1e-12
        assert quat.angle_between(la[1], lb[1]).max() < 1e-12
        changed |= bool(quat.angle_between(la[0][mask], lb[0][mask]).max() > 1e-3)
    assert changed


def test_bass_hands_are_independent(library: MotionLibrary) -> None:
    """The plucking hand goes where its clip says whatever the fretting hand does (the
    body follows the fretting hand, and the arms are solved again to keep both hands)."""
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    a.add_planned(bass("A", 5, 1.0, 1.2))
    b = BandAnimator(library, body=STILL, hands=CLIPS)
    b.add_planned(bass("A", 0, 1.0, 1.2))  # open string: the right hand alone moves
    tip = SKELETON.index("RightHandEnd")
    for t in np.arange(0.95, 1.6, 0.02):
        pa, pb = a.pose(float(t)).bass.positions, b.pose(float(t)).bass.positions
        assert np.linalg.norm(pa[tip] - pb[tip]) < 1e-6


def test_soft_stroke_is_smaller_but_still_lands(library: MotionLibrary) -> None:
    heights = []
    for vel in (30, 127):
        a = BandAnimator(library, body=STILL, hands=CLIPS)
        p = drum("snare_right_hand", 1.0, 1.3, velocity=vel)
        a.add_planned(p)
        assert contact_distance(a, p, p.impact)[0] < TOL
        heights.append(max(a.pose(float(t)).sticks[1, 1, 1] for t in np.arange(1.0, 1.3, 0.01)))
    assert heights[0] < heights[1] - 0.02


def test_faster_tempo_shortens_the_rebound(library: MotionLibrary) -> None:
    from virja.events import Beat

    slow, fast = (
        BandAnimator(library, body=STILL, hands=CLIPS),
        BandAnimator(library, body=STILL, hands=CLIPS),
    )
    fast.add_beat(Beat(0.0, 0, 1, 4, 0, 250_000))  # 240 bpm
    for a in (slow, fast):
        a.add_planned(drum("snare_right_hand", 1.0, 1.3))
    end = [a.timelines[("drums", "right_hand")].instances[0].end for a in (slow, fast)]
    assert end[1] < end[0]


def test_kit_state_follows_the_strokes(library: MotionLibrary) -> None:
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    a.add_planned(drum("snare_left_hand", 1.0, 1.25, velocity=127))
    a.add_planned(drum("crash_right_hand", 1.0, 1.4))
    a.add_planned(drum("hihat_left_foot", 1.0, 1.2))
    a.add_planned(bass("E", 3, 1.0, 1.2))
    assert a.pose(1.2).head_hits["snare"] == 0.0
    assert a.pose(1.25).head_hits["snare"] == pytest.approx(1.0)
    assert a.pose(1.6).head_hits["snare"] < 0.2
    assert a.pose(1.3).cymbal_swing["crash"] == 0.0
    assert abs(a.pose(1.5).cymbal_swing["crash"]) > 0.01
    assert a.pose(1.5).cymbal_swing["crash2"] == 0.0  # crash 2 hangs still: not struck
    assert a.pose(1.2).hihat_open < 0.05  # pedal pressed: closed
    assert a.pose(0.5).hihat_open > 0.5  # foot resting: open
    assert a.pose(1.1).string_vibration["E"] == 0.0
    assert a.pose(1.3).string_vibration["E"] > 0.0
    assert a.pose(1.3).string_stops["E"] == 3


def test_crash2_swings_on_its_own(library: MotionLibrary) -> None:
    """Crash 2 (on the right) swings when struck and crash 1 stays still."""
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    a.add_planned(drum("crash2_right_hand", 1.0, 1.4, velocity=110))
    assert a.pose(1.3).cymbal_swing["crash2"] == 0.0
    assert abs(a.pose(1.5).cymbal_swing["crash2"]) > 0.01
    assert a.pose(1.5).cymbal_swing["crash"] == 0.0


def test_an_animation_file_without_crash2_swings_crash2_like_crash1(tmp_path: Path) -> None:
    """animation.toml written before crash 2: it swings as crash 1 does."""
    from virja.motion.band import AnimationSettings
    from virja.resources import motions_dir

    text = (motions_dir() / "animation.toml").read_text()
    old = "\n".join(ln for ln in text.splitlines() if not ln.startswith("crash2_swing"))
    assert old != text
    (tmp_path / "animation.toml").write_text(old)
    swing = {s[0]: s[1:] for s in AnimationSettings.load(tmp_path / "animation.toml").swing}
    assert swing["crash2"] == swing["crash"]
    shipped = {s[0]: s[1:] for s in AnimationSettings.load().swing}
    assert shipped["crash2"] != shipped["crash"]  # its own: 18", heavier


def test_pose_fields_have_documented_shapes(library: MotionLibrary) -> None:
    p = BandAnimator(library, body=STILL, hands=CLIPS).pose(0.0)
    n = SKELETON.n_joints
    for fig in (p.drums, p.bass):
        assert fig.positions.shape == (n, 3) and fig.rotations.shape == (n, 4)
        assert fig.radii.shape == (n,) and fig.parents.shape == (n,) and fig.parents[0] == -1
        assert len(fig.names) == n
    assert p.sticks.shape == (2, 2, 3)
    assert p.fretting_tip.shape == (3,) and p.plucking_tip.shape == (3,)
    # the drummer sits (hips at the throne), the bassist stands
    assert p.drums.position("Hips")[1] < 0.7 < p.bass.position("Hips")[1]


def test_forget_before_bounds_memory(library: MotionLibrary) -> None:
    a = BandAnimator(library, body=STILL, hands=CLIPS)
    for i in range(400):
        t = 1.0 + 0.25 * i
        a.add_planned(drum("snare_left_hand" if i % 2 else "snare_right_hand", t - 0.2, t))
        a.add_planned(bass("A", 1 + i % 12, t - 0.15, t))
        a.forget_before(t - 1.0)
    assert max(len(tl) for tl in a.timelines.values()) < 10
    last = drum("snare_right_hand", 200.0, 200.2)
    a.add_planned(last)
    assert contact_distance(a, last, 200.2)[0] < TOL


def test_unknown_motion_raises(library: MotionLibrary) -> None:
    """A key whose clip the library lacks (a piece no clip strikes), or a bass motion
    given to the drummer, is an UnknownMotionError naming it."""
    note = drum("snare_left_hand", 1.0, 1.2)
    cowbell = replace(note, motion=DrumStroke("cowbell", "left_hand"))  # type: ignore[arg-type]
    with pytest.raises(UnknownMotionError, match="cowbell"):
        BandAnimator(library, body=STILL, hands=CLIPS).add_planned(cowbell)
    with pytest.raises(UnknownMotionError, match="pluck_A_fret3"):
        BandAnimator(library, body=STILL, hands=CLIPS).add_planned(
            replace(note, motion=BassPluck("A", 3))
        )


def test_default_library_is_shared() -> None:
    assert default_library() is default_library()


def test_geometry_string_points_follow_equal_temperament() -> None:
    b = GEOMETRY.bass
    d12 = np.linalg.norm(b.string_point("A", 12) - b.nut["A"])
    assert d12 == pytest.approx(b.scale_m / 2)
    assert np.linalg.norm(b.string_point("A", 0) - b.nut["A"]) == 0.0
