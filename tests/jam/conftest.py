"""A private JACK server (dummy driver) for the jam tests, and small helpers.

The server is started once per test session under a unique name, which every
JACK client of the process finds through ``JACK_DEFAULT_SERVER``; it needs no
sound card and no realtime rights.  Tests that need it are skipped only where
the ``jackd`` binary is absent (CI installs the ``jackd2`` package); a jackd
that is present but fails to start fails the tests.
"""

from __future__ import annotations

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


def wait_until(predicate: Callable[[], object], timeout_s: float = WAIT_S) -> bool:
    """Poll ``predicate`` until true or ``timeout_s`` passes (bounded); its last value."""
    end = time.monotonic() + timeout_s
    while True:
        if predicate():
            return True
        if time.monotonic() > end:
            return False
        time.sleep(0.005)


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
            [jackd, "-n", name, "--no-realtime", "-d", "dummy", "-r", "48000", "-p", "256"],
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

    def plug(self) -> None:
        with quiet_c_stderr():
            self.out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, self.client_name)
        self.out.open_virtual_port(self.port_name)

    def unplug(self) -> None:
        if self.out is not None:
            self.out.close_port()
            self.out.delete()
            self.out = None

    def send(self, *message: int) -> None:
        assert self.out is not None
        self.out.send_message(list(message))


@pytest.fixture
def keyboard(jack_server: str) -> Iterator[JackKeyboard]:
    kb = JackKeyboard()
    kb.plug()
    yield kb
    kb.unplug()
