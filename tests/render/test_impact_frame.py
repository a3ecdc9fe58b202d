"""The impact frame shows the impact: the stick tip on the drum head, the finger on the string.

The band is planned and animated from real notes, the frame at the impact is
rendered headless, and the stick tip and the fretting fingertip are projected
to the screen and checked against the projected drum head and string point;
the pixels there must be drawn (not background).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from virja.events import NoteOn
from virja.geometry import GEOMETRY
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.plan.planner import plan_notes
from virja.render.camera import PRESETS, project
from virja.render.hosts import OffscreenTarget
from virja.render.renderer import BACKGROUND, Renderer
from virja.render.scene import band_scene, static_scene
from virja.tempo import ConstantTempo

SIZE = (480, 270)


def _plan(notes: list[tuple[str, NoteOn]]) -> tuple[BandAnimator, list[Any]]:
    planned = plan_notes(notes, ConstantTempo(0.5))  # type: ignore[arg-type]
    animator = BandAnimator()
    for p in planned:
        animator.add_planned(p)
    return animator, planned


def _render(gl_ctx: Any, animator: BandAnimator, t: float, camera: str) -> np.ndarray:
    renderer = Renderer(gl_ctx)
    target = OffscreenTarget(gl_ctx, SIZE, samples=1)
    renderer.draw([static_scene(), band_scene(animator.pose(t))], PRESETS[camera], target.fbo)
    img = target.read_rgb().copy()
    assert gl_ctx.error == "GL_NO_ERROR"
    target.release()
    renderer.release()
    return img


def _is_background(px: np.ndarray) -> bool:
    return bool(np.all(np.abs(px.astype(int) - np.round(np.array(BACKGROUND) * 255)) <= 3))


def test_snare_impact_frame_puts_the_stick_tip_on_the_head(gl_ctx: Any) -> None:
    animator, planned = _plan([("drums", NoteOn(1.0, 9, 38, 110))])
    (p,) = planned
    pose = animator.pose(p.impact)
    hand = 0 if p.limb == "left_hand" else 1
    tip = pose.sticks[hand, 1]
    assert GEOMETRY.kit.surface_distance("snare", tip) < 0.01
    cam = PRESETS["drums"]
    vp = cam.view_proj(SIZE[0] / SIZE[1])
    snare = GEOMETRY.kit.pieces["snare"]
    # the head's rim, projected: the tip must fall inside its screen outline
    u = np.cross(snare.normal, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(snare.normal, u)
    ang = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    rim = snare.centre + snare.radius * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v)
    rim_px = project(vp, rim, SIZE)
    (tip_px,) = project(vp, tip[None], SIZE)
    lo, hi = rim_px.min(axis=0), rim_px.max(axis=0)
    assert np.all(tip_px >= lo - 2) and np.all(tip_px <= hi + 2), (tip_px, lo, hi)
    img = _render(gl_ctx, animator, p.impact, "drums")
    x, y = np.round(tip_px).astype(int)
    assert not _is_background(img[y, x])


def test_bass_impact_frame_puts_the_finger_on_the_chosen_string_and_fret(gl_ctx: Any) -> None:
    # B-flat after F: the paper's example, played on the A string, fret 1
    animator, planned = _plan(
        [("bass", NoteOn(1.0, 1, 29, 100)), ("bass", NoteOn(1.5, 1, 34, 100))]
    )
    p = planned[-1]
    assert (p.string, p.fret) == ("A", 1)
    pose = animator.pose(p.impact)
    # the string where the bass leans it (on the beat the player's weight is on a foot)
    target = bass_lean.apply(pose.bass_transform, GEOMETRY.bass.string_point("A", 1))
    assert np.linalg.norm(pose.fretting_tip - target) < 0.01
    cam = PRESETS["bass"]
    vp = cam.view_proj(SIZE[0] / SIZE[1])
    finger_px, string_px = project(vp, np.array([pose.fretting_tip, target]), SIZE)
    assert np.linalg.norm(finger_px - string_px) < 3.0  # pixels
    img = _render(gl_ctx, animator, p.impact, "bass")
    x, y = np.round(finger_px).astype(int)
    assert not _is_background(img[y, x])
