"""The configured tuning reaches every animator: the window's process and the web feed's.

A five-string ``[plan] bass_tuning`` must be played and drawn with five strings
live, not only offline: ``Performance`` tells its sink when it is set (serve and
replay set it after building the sinks), a ``Fanout`` tells sinks added later,
and the window's process gets it through its queue.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from virja.events import NoteOn
from virja.live.frames import FrameLoop, Inbox
from virja.live.pacing import FramePacer
from virja.live.sinks import Fanout
from virja.live.viewer import Viewer
from virja.motion.band import BandAnimator
from virja.motion.pose import BandPose
from virja.plan.config import load_plan_config
from virja.plan.planner import OnlinePlanner
from virja.render.scene import band_scene
from virja.routing import Router
from virja.session import Performance
from virja.web.frames import decode_frame, encode_frame

FIVE = ("B", "E", "A", "D", "G")


def _five_string_perf(tmp_path: Path) -> Performance:
    path = tmp_path / "five.toml"
    path.write_text('[plan]\nbass_tuning = "five"\n')
    return Performance(router=Router(), planner=OnlinePlanner(load_plan_config(path)))


def _string_cylinders(pose: BandPose) -> int:
    """Cylinders of a frame sent to browsers, minus those of a silent four-string frame."""
    _, _, rows = decode_frame(encode_frame(1, pose.time_s, band_scene(pose)))
    _, _, four = decode_frame(encode_frame(1, 0.0, band_scene(BandAnimator().pose(0.0))))
    return len(rows["cylinder"]) - len(four["cylinder"])


class _Recorder:
    """A sink like the window's: records what it is told."""

    def __init__(self) -> None:
        self.told: list[tuple[str, Any]] = []

    def add_planned(self, p: Any) -> None:
        self.told.append(("planned", p))

    def add_beat(self, beat: Any) -> None:
        self.told.append(("beat", beat))

    def use_bass_strings(self, strings: tuple[str, ...]) -> None:
        self.told.append(("strings", strings))


def test_sinks_added_after_the_animator_is_set_learn_the_five_string_tuning(
    tmp_path: Path,
) -> None:
    perf = _five_string_perf(tmp_path)
    sinks = Fanout()
    perf.animator = sinks  # replay's order: the fan-out first, its sinks after
    web_animator = BandAnimator()
    window = _Recorder()
    sinks.add(web_animator)
    sinks.add(window)
    assert web_animator.bass_strings == FIVE
    assert window.told == [("strings", FIVE)]
    # the lowest note of a five-string bass: the open B, planned, animated, sent to browsers
    perf.feed_routed("bass", NoteOn(1.0, 0, 23, 100), now_s=0.0)
    planned = perf.finish()
    assert [(p.string, p.fret) for p in planned] == [("B", 0)]
    pose = perf.pose(50.0)  # rung out: one cylinder a string
    assert tuple(pose.string_vibration) == FIVE
    assert _string_cylinders(pose) == 1


def test_serve_order_sinks_first_then_the_animator_set(tmp_path: Path) -> None:
    perf = _five_string_perf(tmp_path)
    web_animator = BandAnimator()
    perf.animator = Fanout([web_animator])
    assert web_animator.bass_strings == FIVE


def test_the_window_process_plays_and_draws_the_tuning_it_is_sent(tmp_path: Path) -> None:
    # the planning side: Viewer.use_bass_strings puts the tuning on the window's queue
    sent: list[tuple[Any, ...]] = []
    viewer = Viewer.__new__(Viewer)  # no process: only its queue side is under test
    viewer._shut = False
    viewer._inbox = type("Q", (), {"put": staticmethod(sent.append)})()
    perf = _five_string_perf(tmp_path)
    perf.animator = Fanout([viewer])
    perf.feed_routed("bass", NoteOn(1.0, 0, 25, 100), now_s=0.0)  # B string, fret 2
    perf.finish()  # committed through the fan-out to the window's queue
    assert [item[0] for item in sent] == ["articulations", "strings", "planned"]
    assert sent[1] == ("strings", FIVE)

    # the window's side: its frame loop drains the queue into its own animator
    items = [("clock", 0.0), *sent]
    shown: list[BandPose] = []

    class Window:
        closed = False

        def show(self, pose: BandPose) -> None:
            shown.append(pose)
            Window.closed = True

    now = [1.1]
    animator = BandAnimator()
    loop = FrameLoop(
        animator,
        [Window()],
        Inbox(lambda: items.pop(0) if items else None),
        FramePacer(0.02),
        monotonic=lambda: now[0],
        sleep=lambda s: now.__setitem__(0, now[0] + s),
    )
    loop.run()
    assert animator.bass_strings == FIVE and loop.received == 1
    pose = shown[0]
    assert tuple(pose.string_vibration) == FIVE
    assert pose.string_stops["B"] == 2  # the B string stopped at the second fret
    drawn = band_scene(pose)
    four = band_scene(BandAnimator().pose(pose.time_s))
    assert sum(len(m) for m in drawn.models["cylinder"]) > sum(
        len(m) for m in four.models["cylinder"]
    )


def test_live_outputs_tell_the_web_animator_and_the_window_the_tuning(
    tmp_path: Path, monkeypatch: Any
) -> None:
    """Through the pipeline builder and the live outputs (serve, replay, jam): the web
    feed's own animator and the window (its queue) both learn the five strings."""
    import virja.live.viewer as viewer_module
    from virja.live.outputs import LiveOutputs, LiveSettings, WebSettings
    from virja.pipeline import PerformanceSettings, build_performance

    sent: list[tuple[Any, ...]] = []

    def queue_only(self: Viewer, *args: Any, **kwargs: Any) -> None:
        self._shut = False  # no process: only the queue side is under test
        self._inbox = type("Q", (), {"put": staticmethod(sent.append)})()

    monkeypatch.setattr(viewer_module.Viewer, "__init__", queue_only)
    monkeypatch.setattr(viewer_module.Viewer, "close", lambda self: None)
    path = tmp_path / "five.toml"
    path.write_text('[plan]\nbass_tuning = "five"\n')
    perf = build_performance(PerformanceSettings(plan=load_plan_config(path)))
    window: Any = object()  # the window's settings: unused by the queue-only viewer
    settings = LiveSettings(window=window, web=WebSettings(port=0))
    outputs = LiveOutputs.open(perf, settings, lambda: 1000.0)
    try:
        web_animator, viewer = outputs.sinks.sinks
        assert isinstance(web_animator, BandAnimator) and viewer is outputs.viewer
        assert web_animator.bass_strings == FIVE
        assert ("strings", FIVE) in sent
    finally:
        outputs.close()
