"""A private JACK server (dummy driver) for the jam tests, and small helpers.

The server is started once per test session under a unique name, which every
JACK client of the process finds through ``JACK_DEFAULT_SERVER``; it needs no
sound card and no realtime rights.  Tests that need it are skipped only where
the ``jackd`` binary is absent (CI installs the ``jackd2`` package); a jackd
that is present but fails to start fails the tests.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import shutil
import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import rtmidi

from virja.jam.ports import quiet_c_stderr

WAIT_S = 10.0  # upper bound of every wait; a healthy server answers in milliseconds
# The dummy driver's cycle: 2048 frames at 48 kHz (43 ms).  With 256 frames (5 ms) a
# client that a loaded machine does not schedule within the cycle is an xrun, and
# the MIDI it wrote in that cycle can be lost.  No test bounds a latency, so a long
# cycle costs nothing.
RATE_HZ = 48000
PERIOD_FRAMES = 2048
# A connection that the server reports is used from the next cycle on: a message
# sent before that cycle goes to nobody.  Two cycles after it is reported is safe.
SETTLE_S = 2 * PERIOD_FRAMES / RATE_HZ + 0.01


def wait_until(predicate: Callable[[], object], timeout_s: float = WAIT_S) -> bool:
    """Poll ``predicate`` until true or ``timeout_s`` passes (bounded); its last value."""
    end = time.monotonic() + timeout_s
    while True:
        if predicate():
            return True
        if time.monotonic() > end:
            return False
        time.sleep(0.005)


class _Jack:
    """libjack through ctypes, for what python-rtmidi does not say: a port's connections."""

    NO_START_SERVER = 0x01

    def __init__(self) -> None:
        self.lib = ctypes.CDLL(ctypes.util.find_library("jack") or "libjack.so.0")
        self.lib.jack_client_open.restype = ctypes.c_void_p
        self.lib.jack_port_by_name.restype = ctypes.c_void_p
        self.lib.jack_port_by_name.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
        self.lib.jack_port_connected.argtypes = [ctypes.c_void_p]
        self.lib.jack_client_close.argtypes = [ctypes.c_void_p]
        status = ctypes.c_int(0)
        with quiet_c_stderr():
            client = self.lib.jack_client_open(
                b"virja-test-watch", ctypes.c_int(self.NO_START_SERVER), ctypes.byref(status)
            )
        if not client:
            raise RuntimeError(f"jack_client_open failed (status {status.value:#x})")
        self.client = ctypes.c_void_p(client)

    def connections(self, port_name: str) -> int:
        port = self.lib.jack_port_by_name(self.client, port_name.encode())
        return int(self.lib.jack_port_connected(ctypes.c_void_p(port))) if port else 0

    def close(self) -> None:
        self.lib.jack_client_close(self.client)


_watch: list[_Jack] = []  # one watching client per test session, opened on first use


def wait_connected(port_name: str) -> None:
    """Return once ``port_name`` (``client:port``) is connected and the server's graph
    uses the connection (bounded by WAIT_S); fail the test if it never connects."""
    if not _watch:
        _watch.append(_Jack())
    watch = _watch[0]
    if not wait_until(lambda: watch.connections(port_name) > 0):
        pytest.fail(f"JACK port {port_name} was never connected")
    time.sleep(SETTLE_S)


def _jack_answers() -> bool:
    try:
        with quiet_c_stderr():
            client = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "virja-test-ping")
    except rtmidi.RtMidiError:
        return False
    client.delete()
    return True


@pytest.fixture(scope="session")
def jack_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The name of a running JACK server (dummy driver) that this process's clients use."""
    jackd = shutil.which("jackd")
    if jackd is None:
        pytest.skip("jackd is not installed (apt-get install jackd2)")
    name = f"virja-test-{os.getpid()}"
    log_path: Path = tmp_path_factory.mktemp("jack") / "jackd.log"
    env = dict(os.environ, JACK_NO_AUDIO_RESERVATION="1", JACK_NO_START_SERVER="1")
    saved = {k: os.environ.get(k) for k in ("JACK_DEFAULT_SERVER", "JACK_NO_START_SERVER")}
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            [jackd, "-n", name, "--no-realtime", "-d", "dummy", "-r", "48000", "-p", "2048"],
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env=env,
        )
    os.environ["JACK_DEFAULT_SERVER"] = name
    os.environ["JACK_NO_START_SERVER"] = "1"
    try:
        up = wait_until(lambda: proc.poll() is not None or _jack_answers())
        if proc.poll() is not None or not up:
            pytest.fail(f"jackd did not start: {log_path.read_text(errors='replace')[-2000:]}")
        yield name
    finally:
        while _watch:
            _watch.pop().close()
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=5)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


class Recorder:
    """A MIDI handler that keeps what it gets (called on the backend's thread)."""

    def __init__(self) -> None:
        self.messages: list[tuple[bytes, float]] = []

    def __call__(self, data: bytes, arrival_s: float) -> None:
        self.messages.append((data, arrival_s))


@pytest.fixture
def recorder() -> Recorder:
    return Recorder()


class JackKeyboard:
    """A stand-in keyboard: a second JACK client with an output port to play from."""

    def __init__(self, client: str = "kbd-sender", port: str = "keys") -> None:
        self.client_name = client
        self.port_name = port
        self.out: rtmidi.MidiOut | None = None
        self.live = False  # its port's connection is known to be in use

    def plug(self) -> None:
        with quiet_c_stderr():
            self.out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, self.client_name)
        self.out.open_virtual_port(self.port_name)

    def unplug(self) -> None:
        if self.out is not None:
            self.out.close_port()
            self.out.delete()
            self.out = None
        self.live = False

    def send(self, *message: int) -> None:
        """Send once the port is connected (a keyboard played before that is not heard)."""
        assert self.out is not None
        if not self.live:
            wait_connected(f"{self.client_name}:{self.port_name}")
            self.live = True
        self.out.send_message(list(message))


@pytest.fixture
def keyboard(jack_server: str) -> Iterator[JackKeyboard]:
    kb = JackKeyboard()
    kb.plug()
    yield kb
    kb.unplug()
