"""A performance to browsers: poses sampled at the display rate, ahead of the clock.

The host (``serve``, ``replay``, ``jam``) calls :meth:`WebFeed.publish` from its
timer loop with the session time; when a frame is due and anyone is watching,
the feed takes the pose at ``now + lead_s`` (the only work on the host's
thread, about a millisecond) and hands it to the server's thread, which builds
the scene, encodes the frame (:mod:`virja.web.frames`) and fans it out.  The
browser keeps its own estimate of the session clock (``ping``/``pong``) and
draws, at each display refresh, the moment it shows, interpolated between
the two frames around it: an impact appears when its note sounds.

Beats and chords reach the page as small JSON messages as they become known
(:meth:`observe`, a tap on :meth:`virja.session.Performance.feed`); the page's
status line shows the ones in force at the moment drawn.
"""

from __future__ import annotations

import bisect
import json
import threading
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING

from virja.chords import chord_name
from virja.events import Beat, Chord, Event
from virja.render.scene import band_scene, static_scene
from virja.web.fanout import Message
from virja.web.frames import encode_frame, hello
from virja.web.server import WebServer

if TYPE_CHECKING:
    from virja.motion.pose import BandPose
    from virja.plan.types import PlannedNote
    from virja.session import Performance

DEFAULT_FPS = 30.0
DEFAULT_LEAD_S = 0.1  # frames are sampled this far ahead: delivery and one frame period
KEEP_STATUS = 16  # recent beats and chords a new viewer is told
IMPACT_GAP_S = 0.004  # an impact this close to a frame already sent gets no frame of its own


def status_message(event: Event) -> str | None:
    """The JSON the page gets for a beat or a chord (None for anything else)."""
    if isinstance(event, Beat):
        bpm = 60e6 / event.tempo_us if event.tempo_us > 0 else None
        return json.dumps(
            {
                "type": "beat",
                "t": event.time_s,
                "bar": event.bar + 1,
                "beat": event.beat,
                "bpb": event.beats_per_bar,
                "bpm": None if bpm is None else round(bpm, 2),
            }
        )
    if isinstance(event, Chord):
        return json.dumps({"type": "chord", "t": event.time_s, "name": chord_name(event)})
    return None


class WebFeed:
    """Publishes one performance to every connected browser."""

    def __init__(
        self,
        host: str,
        port: int,
        now_s: Callable[[], float],
        *,
        fps: float = DEFAULT_FPS,
        lead_s: float = DEFAULT_LEAD_S,
    ) -> None:
        if not 1.0 <= fps <= 120.0:
            raise ValueError(f"web frame rate must be 1-120 fps, got {fps:g}")
        self.fps = fps
        self.lead_s = lead_s
        self._hello = json.dumps(hello(static_scene(), fps=fps, lead_s=lead_s))
        self._recent: deque[str] = deque(maxlen=KEEP_STATUS)
        self._lock = threading.Lock()
        self.server = WebServer(host, port, greeting=self._greeting, now_s=now_s)
        self._next_s = float("-inf")
        self._impacts: list[float] = []  # impact times not yet sent as frames of their own
        self._sent: list[float] = []  # recent frame times, ascending
        self._seq = 0
        self._encoding = False
        self.frames = 0
        self.skipped = 0
        self.url = ""

    def start(self) -> tuple[str, int]:
        return self.server.start()

    def attach(self, perf: Performance) -> None:
        """Tap the performance's events, for the status line's beats and chords."""
        perf.taps.append(self.observe)
        perf.planned_taps.append(self.planned)

    def planned(self, note: PlannedNote) -> None:
        """A committed motion: its impact instant gets a frame of its own, so the stick is
        drawn on the head at the moment of the note, not between two grid frames."""
        if self.server.viewers:
            bisect.insort(self._impacts, note.impact)

    def observe(self, event: Event) -> None:
        msg = status_message(event)
        if msg is None:
            return
        with self._lock:
            self._recent.append(msg)
        self.server.broadcast(msg, droppable=False)

    def publish(self, perf: Performance, now_s: float) -> None:
        """Call often (every tick): sends a frame when one is due and someone watches;
        and one at each impact instant within the lead that is not yet past."""
        if self.server.viewers == 0:
            self._impacts.clear()
            return
        horizon = now_s + self.lead_s
        while self._impacts and self._impacts[0] <= horizon and not self._encoding:
            t = self._impacts.pop(0)
            if t > now_s and not self._near_sent(t):
                self._send(perf, t)
        if now_s < self._next_s:
            return
        step = 1.0 / self.fps
        self._next_s = max(self._next_s + step, now_s - step)
        if self._encoding:  # the server thread is behind: skip rather than queue
            self.skipped += 1
            return
        self._send(perf, horizon)

    def _near_sent(self, t: float) -> bool:
        i = bisect.bisect_left(self._sent, t)
        near = [self._sent[j] for j in (i - 1, i) if 0 <= j < len(self._sent)]
        return any(abs(s - t) < IMPACT_GAP_S for s in near)

    def _send(self, perf: Performance, t: float) -> None:
        self._encoding = True
        self._seq += 1
        bisect.insort(self._sent, t)
        del self._sent[:-16]
        self.server.submit(self._encode, self._seq, perf.pose(t))

    def _encode(self, seq: int, pose: BandPose) -> None:
        try:
            self.server.fan_here(encode_frame(seq, pose.time_s, band_scene(pose)))
            self.frames += 1
        finally:
            self._encoding = False

    def _greeting(self) -> list[Message]:
        with self._lock:
            return [self._hello, *self._recent]

    def summary(self) -> str:
        st = self.server.stats
        return (
            f"web: {st.viewers_total} viewers, {self.frames} frames "
            f"({self.skipped} skipped while encoding), {st.bytes_queued / 1e6:.1f} MB queued, "
            f"{self.dropped} frames dropped for slow viewers"
        )

    @property
    def dropped(self) -> int:
        return self.server.dropped

    def close(self) -> None:
        self.server.close()
