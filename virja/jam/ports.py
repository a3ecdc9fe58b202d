"""MIDI ports through python-rtmidi (JACK or ALSA): the thin IO part of ``virja jam``.

- :func:`probe_api` picks a backend that works here (JACK first, then ALSA);
  a backend that cannot start raises :class:`BackendUnavailableError`.
- :func:`list_ports` names the ports one can read from (``"input"``: keyboards,
  the output ports of other clients) or write to (``"output"``: synths).
- :class:`MidiInput` is virja's input: connected to the first source port whose
  name contains a pattern, or a virtual port of its own named ``virja``.  Every
  message is stamped with the injected clock on arrival and handed to a
  callback (on the MIDI backend's thread).  :meth:`MidiInput.poll` follows a
  keyboard that is unplugged and plugged back (see :mod:`virja.jam.watch`).
- :class:`MidiOutput` is the thru output: messages go out at once, or at a due
  time through a :class:`virja.jam.delay.DelayLine` served by one thread.

No function here reads a clock of its own: ``clock`` is passed in.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Literal

import rtmidi

from virja.errors import NotAvailableError, VirjaError
from virja.jam.delay import DelayLine
from virja.jam.watch import DEFAULT_POLL_INTERVAL_S, PortChange, PortWatcher, find_port

log = logging.getLogger(__name__)

ApiName = Literal["jack", "alsa"]
API_NAMES: tuple[ApiName, ...] = ("jack", "alsa")
_API_CODES: dict[str, int] = {"jack": rtmidi.API_UNIX_JACK, "alsa": rtmidi.API_LINUX_ALSA}
Direction = Literal["input", "output"]

CLIENT_NAME = "virja"
VIRTUAL_PORT_NAME = "virja"

Clock = Callable[[], float]
MessageHandler = Callable[[bytes, float], None]


class PortNotFoundError(VirjaError, LookupError):
    """No MIDI port matches the name given; the message lists the ports there are."""

    def __init__(self, pattern: str, direction: Direction, available: Sequence[str]) -> None:
        self.pattern = pattern
        self.available = list(available)
        kind = "source (keyboard)" if direction == "input" else "destination (synth)"
        listed = ", ".join(repr(n) for n in available) if available else "none"
        super().__init__(f"no MIDI {kind} port matches {pattern!r}; ports there: {listed}")


class BackendUnavailableError(NotAvailableError):
    """The MIDI API asked for (or every API) cannot be used on this machine."""


@contextlib.contextmanager
def quiet_c_stderr() -> Iterator[None]:
    """Silence what libasound and libjack print on fd 2 while a client starts.

    Their lines ("ALSA lib seq_hw.c ...", "Cannot connect to server socket")
    would bury the one clear message the CLI prints instead.
    """
    try:
        saved = os.dup(2)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _explain(api: str, exc: BaseException) -> str:
    if api == "jack":
        return (
            f"the JACK MIDI API cannot start ({exc}); is a JACK server running? "
            "(start one, e.g. `jackd -d alsa` or `jackd -d dummy`, or choose --api alsa)"
        )
    return (
        f"the ALSA MIDI API cannot start ({exc}); this machine has no ALSA sequencer "
        "(/dev/snd/seq; load snd-seq or choose --api jack)"
    )


def _client(api: str, direction: Direction, name: str) -> Any:
    """A MidiIn (``"input"``) or MidiOut (``"output"``) client on ``api``."""
    if api not in _API_CODES:
        raise BackendUnavailableError(f"unknown MIDI API {api!r}; choose one of {API_NAMES}")
    if _API_CODES[api] not in rtmidi.get_compiled_api():
        raise BackendUnavailableError(f"python-rtmidi was built without the {api} MIDI API")
    cls = rtmidi.MidiIn if direction == "input" else rtmidi.MidiOut
    try:
        with quiet_c_stderr():
            return cls(_API_CODES[api], name)
    except rtmidi.RtMidiError as exc:
        raise BackendUnavailableError(_explain(api, exc)) from exc


def probe_api(api: str | None = None) -> ApiName:
    """The API to use: ``api`` if given and working, else the first of JACK, ALSA that works."""
    candidates = API_NAMES if api is None else (api,)
    reasons = []
    for name in candidates:
        try:
            client = _client(name, "input", f"{CLIENT_NAME}-probe")
        except BackendUnavailableError as exc:
            reasons.append(str(exc))
            continue
        client.delete()
        return name  # type: ignore[return-value]
    if api is not None:
        raise BackendUnavailableError(reasons[0])
    raise BackendUnavailableError("no MIDI API works here: " + "; ".join(reasons))


def list_ports(api: str, direction: Direction) -> list[str]:
    """Names of the ports to read from (``"input"``) or to write to (``"output"``)."""
    client = _client(api, direction, f"{CLIENT_NAME}-list")
    try:
        return [str(n) for n in client.get_ports()]
    finally:
        client.delete()


class _Connection:
    """One rtmidi client keeping a connection to a port matched by name."""

    direction: Direction

    def __init__(self, api: str, client_name: str, port_name: str, poll_interval_s: float) -> None:
        self.api = api
        self._client = _client(api, self.direction, client_name)
        self._port_name = port_name
        self._poll_interval_s = poll_interval_s
        self._lock = threading.Lock()
        self.watcher: PortWatcher | None = None
        self.virtual_name: str | None = None
        self.reconnects = 0

    @property
    def connected_to(self) -> str | None:
        """The port connected to (None for a virtual port, or while unplugged)."""
        return None if self.watcher is None else self.watcher.connected

    def _connect(self, pattern: str) -> str:
        names = [str(n) for n in self._client.get_ports()]
        index = find_port(names, pattern)
        if index is None:
            raise PortNotFoundError(pattern, self.direction, names)
        self._client.open_port(index, self._port_name)
        self.watcher = PortWatcher(
            pattern, connected=names[index], poll_interval_s=self._poll_interval_s
        )
        log.info("connected to %s port %r", self.api, names[index])
        return names[index]

    def _open_virtual(self) -> str:
        """Open a virtual port and find its full name (the server may rename the client)."""
        other: Direction = "output" if self.direction == "input" else "input"
        probe = _client(self.api, other, f"{CLIENT_NAME}-probe")
        try:
            before = {str(n) for n in probe.get_ports()}
            self._client.open_virtual_port(self._port_name)
            new = [str(n) for n in probe.get_ports() if str(n) not in before]
        finally:
            probe.delete()
        mine = [n for n in new if self._port_name in n]
        self.virtual_name = mine[0] if mine else f"{CLIENT_NAME}:{self._port_name}"
        log.info("opened virtual %s port %r", self.api, self.virtual_name)
        return self.virtual_name

    def poll(self, now_s: float) -> PortChange | None:
        """Follow the port when unplugged and replugged; call often, it lists ports rarely."""
        if self.watcher is None or not self.watcher.due(now_s):
            return None
        names = [str(n) for n in self._client.get_ports()]
        change = self.watcher.update(names, now_s)
        if change is None:
            return None
        with self._lock:
            if change.disconnect is not None:
                log.warning("MIDI port %r is gone; waiting for it to come back", change.disconnect)
                self._client.close_port()
            if change.connect is not None and change.connect_index is not None:
                try:
                    self._client.open_port(change.connect_index, self._port_name)
                    self._reopened()
                except rtmidi.RtMidiError as exc:
                    log.warning("could not open MIDI port %r: %s", change.connect, exc)
                    self.watcher.forget()
                    return change
                self.reconnects += 1
                log.warning("MIDI port %r is back; connected", change.connect)
        return change

    def _reopened(self) -> None:
        """Hook run after the port is opened again by :meth:`poll`."""

    def close(self) -> None:
        with self._lock:
            self._client.close_port()
            self._client.delete()


class MidiInput(_Connection):
    """virja's MIDI input; ``handler(data, arrival_s)`` runs on the backend's thread.

    ``port``: a name pattern to connect to (case-insensitive substring of the
    source port's name), or None for a virtual port named ``virja`` that the
    keyboard (or ``jack_connect``) connects to.  ``name`` is the full name of the
    port connected to, or of the virtual port.
    """

    direction: Direction = "input"

    def __init__(
        self,
        api: str,
        handler: MessageHandler,
        clock: Clock,
        *,
        port: str | None = None,
        client_name: str = CLIENT_NAME,
        poll_interval_s: float = DEFAULT_POLL_INTERVAL_S,
    ) -> None:
        super().__init__(api, client_name, VIRTUAL_PORT_NAME, poll_interval_s)
        self._handler = handler
        self._clock = clock
        self.received = 0
        try:
            self._client.ignore_types(sysex=True, timing=True, active_sense=True)
            self._client.set_callback(self._on_message)
            self.name = self._open_virtual() if port is None else self._connect(port)
        except BaseException:
            self._client.delete()
            raise

    def _on_message(self, message: tuple[list[int], float], data: object = None) -> None:
        arrival_s = self._clock()
        self.received += 1
        try:
            self._handler(bytes(message[0]), arrival_s)
        except Exception:  # a bad handler must not kill the backend's thread
            log.exception("MIDI input handler failed")

    def _reopened(self) -> None:
        # python-rtmidi's close_port drops the callback (messages would pile up
        # in its queue unseen): set it again.
        self._client.cancel_callback()
        self._client.set_callback(self._on_message)

    def close(self) -> None:
        self._client.cancel_callback()
        super().close()


class MidiOutput(_Connection):
    """A MIDI output (the thru to a synth), connected to the first destination matching ``port``.

    :meth:`send` sends at once; :meth:`send_at` queues for a due time on the
    ``clock``, served by a thread started on first use.  :meth:`close` sends what
    is still queued (note-offs must reach the synth) before closing.
    """

    direction: Direction = "output"

    def __init__(
        self,
        api: str,
        port: str,
        clock: Clock,
        *,
        client_name: str = f"{CLIENT_NAME}-thru",
        port_name: str = "thru",
        poll_interval_s: float = DEFAULT_POLL_INTERVAL_S,
    ) -> None:
        super().__init__(api, client_name, port_name, poll_interval_s)
        self._clock = clock
        self._line = DelayLine()
        self._wake = threading.Condition()
        self._thread: threading.Thread | None = None
        self._closing = False
        self.sent = 0
        try:
            self.name = self._connect(port)
        except BaseException:
            self._client.delete()
            raise

    def send(self, data: bytes) -> None:
        """Send one message now (dropped while the synth is unplugged)."""
        with self._lock:
            if self.connected_to is None:
                return
            self._client.send_message(data)
            self.sent += 1

    def send_at(self, data: bytes, due_s: float) -> None:
        """Send one message at ``due_s`` on the clock."""
        with self._wake:
            if self._thread is None:
                self._thread = threading.Thread(target=self._serve, name="virja-thru", daemon=True)
                self._thread.start()
            if not self._line.push(data, due_s):
                log.warning("thru delay line full; message dropped")
            self._wake.notify()

    def _serve(self) -> None:
        while True:
            with self._wake:
                if self._closing:
                    return
                due = self._line.pop_due(self._clock())
                if not due:
                    next_s = self._line.next_due_s()
                    timeout = None if next_s is None else max(0.0, next_s - self._clock())
                    self._wake.wait(timeout)
                    continue
            for data in due:
                self.send(data)

    def close(self) -> None:
        with self._wake:
            self._closing = True
            left = self._line.drain()
            self._wake.notify()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        for data in left:
            self.send(data)
        super().close()
