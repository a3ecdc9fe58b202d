"""Live sound for ``serve --audio``: the session's notes through fluidsynth, at their time.

Notes reach the daemon about a beat ahead of when they sound.  Each note event
fed to the performance is handed to :class:`LiveSynth` (a ``Performance.taps``
callback, which only puts it on a queue and returns); a thread of its own
waits until the event's session time and writes it to a fluidsynth process's
command shell (``noteon 9 38 100``).  Receiving and planning never wait for
the synth, and a synth that stops or fails is reported once and silenced,
never a reason to stop the band.  The soundfont is found as for ``render``
(``--soundfont``, ``$VIRJA_SOUNDFONT``, the Debian GM soundfont).
"""

from __future__ import annotations

import contextlib
import heapq
import logging
import shutil
import subprocess
import threading
from collections.abc import Callable
from pathlib import Path

from virja.errors import NotAvailableError
from virja.events import ControlChange, Event, NoteOff, NoteOn, ProgramChange

log = logging.getLogger(__name__)

MAX_PENDING = 10_000  # events waiting for their time; more is a flood, the oldest go first
LATE_S = 0.25  # an event this late is not sounded (a burst of stale notes helps nobody)


def command(event: Event) -> str | None:
    """The fluidsynth shell command for ``event`` (channels 0-15, as the shell counts)."""
    if isinstance(event, NoteOn):
        return f"noteon {event.channel} {event.note} {event.velocity}"
    if isinstance(event, NoteOff):
        return f"noteoff {event.channel} {event.note}"
    if isinstance(event, ProgramChange):
        return f"prog {event.channel} {event.program}"
    if isinstance(event, ControlChange):
        return f"cc {event.channel} {event.control} {event.value}"
    return None


class LiveSynth:
    """A fluidsynth process fed each note at its session time from a thread of its own."""

    def __init__(
        self,
        soundfont: Path,
        now_s: Callable[[], float],
        *,
        driver: str | None = None,
        extra_args: tuple[str, ...] = (),
    ) -> None:
        exe = shutil.which("fluidsynth")
        if exe is None:
            raise NotAvailableError("--audio needs fluidsynth (apt-get install fluidsynth)")
        args = [exe, "-q", "-g", "0.6"]  # its command shell on stdin
        if driver:
            args += ["-a", driver]
        args += [*extra_args, str(soundfont)]
        try:
            self._proc = subprocess.Popen(
                args,
                stdin=subprocess.PIPE,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
            )
        except OSError as exc:
            raise NotAvailableError(f"--audio: cannot start fluidsynth: {exc}") from None
        self._now_s = now_s
        self._heap: list[tuple[float, int, str]] = []
        self._seq = 0
        self._cond = threading.Condition()
        self._stopped = False
        self.sent = 0
        self.skipped_late = 0
        self.failed: str | None = None
        self._thread = threading.Thread(target=self._run, name="virja-audio", daemon=True)
        self._thread.start()

    def __call__(self, event: Event) -> None:
        """A ``Performance.taps`` callback: queue ``event`` for its time; never blocks long."""
        line = command(event)
        if line is None or self.failed is not None:
            return
        with self._cond:
            if len(self._heap) >= MAX_PENDING:
                heapq.heappop(self._heap)
            heapq.heappush(self._heap, (event.time_s, self._seq, line))
            self._seq += 1
            self._cond.notify()

    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._stopped:
                    wait = self._heap[0][0] - self._now_s() if self._heap else None
                    if wait is not None and wait <= 0:
                        break
                    self._cond.wait(timeout=wait)
                if self._stopped:
                    return
                due, _, line = heapq.heappop(self._heap)
            if self._now_s() - due > LATE_S:
                self.skipped_late += 1
                continue
            self._write(line)

    def _write(self, line: str) -> None:
        if self.failed is not None:
            return
        try:
            assert self._proc.stdin is not None
            self._proc.stdin.write(line + "\n")
            self._proc.stdin.flush()
            self.sent += 1
        except (OSError, ValueError) as exc:  # the synth went away: say so once, go on silent
            self.failed = f"fluidsynth stopped ({exc}); the band goes on without sound"
            log.warning("%s", self.failed)

    def close(self) -> None:
        with self._cond:
            self._stopped = True
            self._cond.notify()
        self._thread.join(timeout=2)
        with contextlib.suppress(OSError, ValueError):
            assert self._proc.stdin is not None
            self._proc.stdin.write("quit\n")
            self._proc.stdin.close()
        try:
            self._proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
