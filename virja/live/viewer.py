"""The window in its own process, so that no frame can delay receiving or planning.

Seen from the planning side, :class:`Viewer` is a plan sink: ``add_planned``,
``add_beat`` and ``note_off`` put the item on a queue (never blocking: a feeder
thread writes the pipe) and return.  The viewer process owns the glfw window,
its GL context, an animator and the frame loop (:mod:`virja.live.frames`).
Why a process and not a thread: moderngl holds the GIL through every GL call,
including the waits for llvmpipe, so a drawing thread stalls a receiving
thread for whole frames (measured: 170-300 ms); in its own process, at a lower
priority (nice 5), a frame only competes for a core, and the kernel hands the
core to the woken receiver first.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import multiprocessing as mp
import os
import queue
import signal
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from virja.errors import NotAvailableError
from virja.events import Beat, Chord, NoteOff, NoteOn
from virja.plan.types import PlannedNote
from virja.vocab import Performer

log = logging.getLogger(__name__)

READY_TIMEOUT_S = 60.0
ANCHOR_TOLERANCE_S = 1e-4
# The viewer's scheduling priority (nice): when the cores are short, a frame is what
# gives way (it is skipped), never a datagram, the planner, or the sender beside us.
VIEWER_NICE = 5


@dataclass(frozen=True)
class ViewerSpec:
    """What the viewer process needs to open its window."""

    size: tuple[int, int] = (1280, 720)
    title: str = "virja"
    fps: float = 60.0
    samples: int = 1
    camera: str = "front"
    vsync: bool = True
    hud: bool = False  # heads-up display shown from the start (key H toggles it)


@dataclass(frozen=True)
class ViewerStats:
    frames: int = 0
    skipped: int = 0
    motions: int = 0
    vsync: bool = False


class Viewer:
    """Starts the viewer process and waits until its window is open (or says why not).

    ``now_s`` is the planning side's session clock; the viewer draws at
    ``anchor + monotonic()`` with ``anchor = now_s() - monotonic()``, sent again by
    :meth:`sync_clock` when the clock is corrected (``--clock-server``).
    """

    def __init__(
        self,
        spec: ViewerSpec,
        now_s: Callable[[], float],
        *,
        ready_timeout_s: float = READY_TIMEOUT_S,
    ) -> None:
        if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            raise NotAvailableError(
                "no display for a window (DISPLAY is not set); use --headless, or run under Xvfb"
            )
        ctx = mp.get_context("spawn")
        self.spec = spec
        self._now_s = now_s
        self._anchor: float | None = None
        self._shut = False
        self._inbox: Any = ctx.Queue()
        self._back: Any = ctx.Queue()
        self.sync_clock()
        self._proc = ctx.Process(
            target=viewer_main,
            args=(spec, self._inbox, self._back, os.getpid(), self._anchor),
            name="virja-viewer",
            daemon=True,
        )
        self._proc.start()
        self.stats: ViewerStats | None = None
        try:
            msg = self._back.get(timeout=ready_timeout_s)
        except queue.Empty:
            self._kill()
            raise NotAvailableError(
                f"the window did not open within {ready_timeout_s:g} s"
            ) from None
        if msg[0] != "ready":
            self._proc.join(timeout=10)
            raise NotAvailableError(str(msg[1]))

    # -- the plan sink ---------------------------------------------------------
    def add_planned(self, p: PlannedNote) -> None:
        self._put(("planned", p))

    def note_known(self, performer: Performer, note: NoteOn, at_s: float) -> None:
        """When a note became known: the window's drummer may move toward it from then."""
        self._put(("known", performer, note, at_s))

    def note_provisional(self, notes: list[PlannedNote]) -> None:
        """The plan's current hands for notes not yet started: the window's drummer
        moves toward them, and re-targets when the plan fixes another hand."""
        self._put(("provisional", list(notes)))

    def add_beat(self, beat: Beat) -> None:
        self._put(("beat", beat))

    def add_chord(self, chord: Chord) -> None:
        self._put(("chord", chord))

    def note_off(self, performer: Performer, event: NoteOff) -> None:
        self._put(("off", performer, event))

    def use_bass_strings(self, strings: tuple[str, ...]) -> None:
        """The tuning's strings (B E A D G for a five-string): the window's animator plays
        and draws them (``Performance`` tells every sink that takes them)."""
        self._put(("strings", tuple(strings)))

    def set_articulations(self, articulations: Mapping[int, str | None]) -> None:
        """The kit map's hi-hat articulations, for the window's animator."""
        self._put(("articulations", dict(articulations)))

    def _put(self, item: tuple[Any, ...]) -> None:
        if not self._shut:  # after close (a replay's last notes) nothing is drawn
            self._inbox.put(item)

    def sync_clock(self) -> None:
        """Send the session clock's anchor if it moved (a clock offset correction)."""
        anchor = self._now_s() - time.monotonic()
        if self._anchor is None or abs(anchor - self._anchor) > ANCHOR_TOLERANCE_S:
            self._anchor = anchor
            self._put(("clock", anchor))

    # -- life ------------------------------------------------------------------
    @property
    def closed(self) -> bool:
        """The window was closed (Esc, Q, the window manager) or its process ended."""
        return not self._proc.is_alive()

    @property
    def sentinel(self) -> int:
        """A file descriptor that becomes readable when the viewer process ends."""
        return int(self._proc.sentinel)

    def close(self, timeout_s: float = 10.0) -> ViewerStats:
        """Stop the frame loop, close the window, collect the frame counts."""
        if self._shut:
            return self.stats or ViewerStats()
        if self._proc.is_alive():
            self._inbox.put(("stop",))
        self._shut = True
        deadline = time.monotonic() + timeout_s
        while self.stats is None and time.monotonic() < deadline:
            try:
                msg = self._back.get(timeout=max(0.01, deadline - time.monotonic()))
            except queue.Empty:
                break
            if msg[0] == "stats":
                self.stats = ViewerStats(**msg[1])
        self._proc.join(timeout=max(0.1, deadline - time.monotonic()))
        if self._proc.is_alive():
            self._kill()
        self._inbox.close()
        self._inbox.cancel_join_thread()
        return self.stats or ViewerStats()

    def _kill(self) -> None:
        self._proc.terminate()
        self._proc.join(timeout=5)


def viewer_main(spec: ViewerSpec, inbox: Any, back: Any, parent_pid: int, anchor: float) -> None:
    """The viewer process: open the window, then draw frames until told to stop."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the planning side's to handle
    with contextlib.suppress(OSError):  # under load, drawing yields the cores first
        os.nice(VIEWER_NICE)
    try:
        from virja.live.frames import FrameLoop, Inbox
        from virja.live.pacing import FramePacer
        from virja.motion.band import BandAnimator
        from virja.render.camera import PRESETS
        from virja.render.live import LiveView

        view = LiveView(spec.size, spec.title, spec.samples, vsync=spec.vsync, hud=spec.hud)
        view.host.state.camera = PRESETS[spec.camera]
        animator = BandAnimator()
    except Exception as exc:  # a clear line for the parent, which raises it
        back.put(("error", str(exc)))
        return
    back.put(("ready",))

    def get() -> tuple[Any, ...] | None:
        try:
            item: tuple[Any, ...] = inbox.get_nowait()
        except queue.Empty:
            return None
        return item

    pacer = FramePacer(1.0 / spec.fps)
    loop = FrameLoop(
        animator,
        [view],
        Inbox(get),
        pacer,
        anchor_s=anchor,
        alive=lambda: os.getppid() == parent_pid,
    )
    # Start-up is over here too (modules, the GL context, the motion library): those
    # objects live as long as the window, so they leave the collector's generations, as
    # in `virja serve` (cmd_serve); a full collection of them is a frame's pause
    # (docs/performance.md, "Pose and scene, eighth round").
    gc.freeze()
    try:
        while loop.step():
            if not pacer.vsync and pacer.shown == 30:
                refresh = view.refresh_s()
                if refresh is not None:  # the swaps wait for the display: let them pace
                    pacer.vsync = True
                    pacer.period_s = refresh
    except Exception as exc:
        print(f"virja viewer: {exc}", file=sys.stderr, flush=True)
    finally:
        stats = ViewerStats(view.frames, pacer.skipped, loop.received, pacer.vsync)
        with contextlib.suppress(Exception):
            view.close()
        back.put(("stats", stats.__dict__))
