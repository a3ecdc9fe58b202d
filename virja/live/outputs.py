"""The live outputs of a performance, opened in one place: the window's process, the
browsers' feed and the speakers, and the fan-out that hands them committed motions.

``serve``, ``replay`` (in real time) and ``jam`` parse their options into a
:class:`LiveSettings` once, build the performance with
:func:`virja.pipeline.build_performance`, then::

    outputs = LiveOutputs.open(perf, settings, clock.now_s)
    ...                                  # the command's own timer
    outputs.close()

The window draws in its own process (:mod:`virja.live.viewer`); the browsers' frames
are posed in this process by an animator of our own (an animator already on the
performance, as a jam's, is that animator); the synthesiser plays every event fed
(a tap).  What opened before a failure is closed again, and the error goes on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from virja.faults import survive_tick
from virja.live.sinks import Fanout
from virja.live.viewer import ViewerSpec

if TYPE_CHECKING:
    from virja.live.audio import LiveSynth
    from virja.live.viewer import Viewer
    from virja.session import Performance
    from virja.web.feed import WebFeed


@dataclass(frozen=True)
class WebSettings:
    """The browser viewer (``--web``, ``--web-fps``, ``--web-lead-ms``)."""

    host: str = "127.0.0.1"
    port: int = 8080
    fps: float = 30.0
    lead_s: float = 0.1


@dataclass(frozen=True)
class AudioSettings:
    """The session's notes through fluidsynth (``--audio``): a soundfont already found."""

    soundfont: Path
    driver: str | None = None


@dataclass(frozen=True)
class LiveSettings:
    """Which live outputs a command opens: ``window`` (None: headless), ``web``,
    ``audio``; each None when not asked for."""

    window: ViewerSpec | None = None
    web: WebSettings | None = None
    audio: AudioSettings | None = None


class LiveOutputs:
    """The opened outputs: ``sinks`` (the performance's animator), ``viewer``, ``web``,
    ``synth`` (each None when not opened)."""

    def __init__(self, settings: LiveSettings) -> None:
        self.settings = settings
        self.sinks = Fanout()
        self.viewer: Viewer | None = None
        self.web: WebFeed | None = None
        self.synth: LiveSynth | None = None

    @classmethod
    def open(
        cls, perf: Performance, settings: LiveSettings, now_s: Callable[[], float]
    ) -> LiveOutputs:
        """Open the outputs ``settings`` asks for and hand ``perf``'s motions to them:
        the web's animator and server, the synthesiser, the window, in this order."""
        outputs = cls(settings)
        try:
            outputs._open(perf, now_s)
        except BaseException:
            outputs.close()
            raise
        return outputs

    def _open(self, perf: Performance, now_s: Callable[[], float]) -> None:
        settings = self.settings
        if settings.web is not None:  # the browsers' frames are posed here
            if perf.animator is not None:
                self.sinks.add(perf.animator)
            else:
                from virja.motion.band import BandAnimator

                self.sinks.add(BandAnimator())
            self.web = open_web_feed(perf, settings.web, now_s)
        if settings.audio is not None:
            from virja.live.audio import LiveSynth

            self.synth = LiveSynth(settings.audio.soundfont, now_s, driver=settings.audio.driver)
            perf.taps.append(self.synth)
        if settings.window is not None:  # last: the slowest to open, and seen
            from virja.live.viewer import Viewer

            self.viewer = Viewer(settings.window, now_s)
            self.sinks.add(self.viewer)
        perf.animator = self.sinks if self.sinks.sinks else None

    def close_audio(self) -> None:
        """Stop the synthesiser (``serve`` does it first, with the receiving)."""
        if self.synth is not None:
            synth, self.synth = self.synth, None
            with survive_tick():
                synth.close()

    def close(self) -> None:
        """Close everything still open, each on its own (a failure is one warning)."""
        self.close_audio()
        if self.viewer is not None:
            viewer, self.viewer = self.viewer, None
            with survive_tick():
                viewer.close()
        if self.web is not None:
            web, self.web = self.web, None
            with survive_tick():
                web.close()


def open_web_feed(perf: Performance, settings: WebSettings, now_s: Callable[[], float]) -> WebFeed:
    """Start the browser viewer's server and tap ``perf`` (its address in ``feed.url``)."""
    from virja.errors import ConfigError
    from virja.web.feed import WebFeed

    try:
        feed = WebFeed(
            settings.host, settings.port, now_s, fps=settings.fps, lead_s=settings.lead_s
        )
    except ValueError as exc:
        raise ConfigError(f"--web-fps: {exc}") from None
    bound = feed.start()
    feed.attach(perf)
    shown = f"[{bound[0]}]" if ":" in bound[0] else bound[0]
    feed.url = f"http://{shown}:{bound[1]}/"
    return feed
