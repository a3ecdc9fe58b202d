"""The window's frame loop poses a BandAnimator a few slots ahead (render.chunks) and
throws those frames away whenever the animator is told something: a note that
arrives late (its motion already under way) is in the very next frame drawn."""

from __future__ import annotations

from typing import Any

import numpy as np

from tests.motion.helpers import drum
from virja.live.frames import AHEAD_FRAMES, FrameLoop, Inbox
from virja.live.pacing import FramePacer
from virja.motion.band import BandAnimator
from virja.motion.pose import BandPose
from virja.render.renderer import DrawList
from virja.render.scene import band_scene


class Window:
    """A sink that takes the chunk's instances, as render.live.LiveView does."""

    closed = False

    def __init__(self) -> None:
        self.frames: list[tuple[BandPose, DrawList]] = []

    def show(self, pose: BandPose) -> None:
        raise AssertionError("a window with show_frame gets the chunk's instances")

    def show_frame(self, pose: BandPose, scene: DrawList) -> None:
        self.frames.append((pose, scene))


def _loop(items: list[tuple[Any, ...]], window: Window, now: list[float]) -> FrameLoop:
    def sleep(s: float) -> None:
        now[0] += s

    return FrameLoop(
        BandAnimator(),
        [window],
        Inbox(lambda: items.pop(0) if items else None),
        FramePacer(1 / 60),
        monotonic=lambda: now[0],
        sleep=sleep,
    )


def _same(pose: BandPose, scene: DrawList, want: BandPose) -> bool:
    return bool(
        np.allclose(pose.drums.positions, want.drums.positions, rtol=0, atol=1e-12)
        and np.allclose(scene.packed("cylinder"), band_scene(want).packed("cylinder"), atol=1e-6)
    )


def test_frames_are_posed_ahead_and_a_late_note_is_in_the_next_frame() -> None:
    items: list[tuple[Any, ...]] = [("clock", 0.0)]
    window = Window()
    now = [1.0]
    loop = _loop(items, window, now)
    for _ in range(AHEAD_FRAMES + 2):  # into the second chunk
        assert loop.step()
    assert loop.chunks is not None
    assert loop.chunks.chunks == 2  # nothing new: one batch a chunk
    # a snare stroke whose motion started 50 ms ago arrives now (late)
    t_next = now[0] + 1 / 60
    note = drum("snare_right_hand", t_next - 0.05, t_next + 0.1)
    items.append(("planned", note))
    assert loop.step()
    pose, scene = window.frames[-1]
    told = BandAnimator()
    told.mark_drawn(window.frames[-2][0].time_s)  # shown before the note came: kept
    told.add_planned(note)
    assert _same(pose, scene, told.pose(pose.time_s))  # drawn with the stroke
    assert not _same(pose, scene, BandAnimator().pose(pose.time_s))  # which shows
    for p, s in window.frames[:-1]:  # and the frames before it were the animator's own
        assert _same(p, s, BandAnimator().pose(p.time_s))
    # the frame with the news was posed alone (no dearer than frame by frame); the
    # next ones a chunk again
    assert (loop.chunks.chunks, loop.chunks.frames) == (3, 2 * AHEAD_FRAMES + 1)
    for _ in range(AHEAD_FRAMES):
        assert loop.step()
    assert (loop.chunks.chunks, loop.chunks.frames) == (4, 3 * AHEAD_FRAMES + 1)
    for p, s in window.frames[-AHEAD_FRAMES:]:
        assert _same(p, s, told.pose(p.time_s))


def test_with_vsync_the_band_is_posed_one_slot_at_a_time() -> None:
    window = Window()
    now = [1.0]
    loop = _loop([("clock", 0.0)], window, now)
    loop.pacer.vsync = True
    for _ in range(4):
        assert loop.step()
        now[0] += 1 / 60
    assert loop.chunks is not None and loop.chunks.chunks == loop.chunks.frames == 4
