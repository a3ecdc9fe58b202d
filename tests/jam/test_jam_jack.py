"""virja's MIDI ports against a real JACK server (dummy driver) and real JACK clients."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest
import rtmidi

from virja.events import NoteOff, NoteOn
from virja.jam.keyboard import KeyboardLayout
from virja.jam.live import KeyboardJam
from virja.jam.ports import (
    BackendUnavailableError,
    MidiInput,
    MidiOutput,
    PortNotFoundError,
    list_ports,
    probe_api,
    quiet_c_stderr,
)

pytestmark = pytest.mark.jack

if TYPE_CHECKING:
    from tests.jam.conftest import JackKeyboard, Recorder

from tests.jam.conftest import wait_connected, wait_until  # noqa: E402


class JackSynth:
    """A third client: a synth's input port that records what reaches it, with arrival times."""

    def __init__(self, client: str = "test-synth") -> None:
        with quiet_c_stderr():
            self.midi_in = rtmidi.MidiIn(rtmidi.API_UNIX_JACK, client)
        self.got: list[tuple[list[int], float]] = []
        self.midi_in.set_callback(self._on)
        self.midi_in.open_virtual_port("midi_in")

    def _on(self, message: tuple[list[int], float], data: object = None) -> None:
        self.got.append((message[0], time.monotonic()))

    def close(self) -> None:
        self.midi_in.close_port()
        self.midi_in.delete()


@pytest.fixture
def synth(jack_server: str) -> Iterator[JackSynth]:
    s = JackSynth()
    yield s
    s.close()


def test_probe_finds_jack_when_a_server_runs(jack_server: str) -> None:
    """With a JACK server up, the default backend probe picks JACK."""
    assert probe_api() == "jack"


def test_jack_without_server_is_a_clear_error(
    jack_server: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Asking JACK for a server that does not run raises BackendUnavailableError, saying why."""
    monkeypatch.setenv("JACK_DEFAULT_SERVER", "virja-no-such-server")
    with pytest.raises(BackendUnavailableError, match="JACK server running"):
        probe_api("jack")


def test_list_ports_shows_the_keyboard(keyboard: JackKeyboard) -> None:
    """--list-ports: the keyboard's output port is among the sources."""
    assert "kbd-sender:keys" in list_ports("jack", "input")


def test_virtual_port_reports_its_full_name(jack_server: str, recorder: Recorder) -> None:
    """Without --port virja opens a port named virja and reports its full JACK name."""
    port = MidiInput("jack", recorder, time.monotonic)
    try:
        assert port.name.endswith(":virja")
        assert port.name in list_ports("jack", "output")
    finally:
        port.close()


def test_notes_sent_to_the_virtual_port_arrive(jack_server: str, recorder: Recorder) -> None:
    """A second client connected to virja's virtual port delivers its notes, stamped on arrival."""
    port = MidiInput("jack", recorder, time.monotonic)
    with quiet_c_stderr():
        out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "kbd-direct")
    try:
        out.open_port(out.get_ports().index(port.name))
        wait_connected(port.name)
        before = time.monotonic()
        out.send_message([0x90, 40, 100])
        out.send_message([0x80, 40, 0])
        assert wait_until(lambda: len(recorder.messages) == 2)
        assert [m for m, _ in recorder.messages] == [b"\x90\x28\x64", b"\x80\x28\x00"]
        assert all(t >= before for _, t in recorder.messages)
    finally:
        out.delete()
        port.close()


def test_port_option_connects_to_a_matching_source(
    keyboard: JackKeyboard, recorder: Recorder
) -> None:
    """--port NAME connects to the first source whose name contains NAME (any case)."""
    port = MidiInput("jack", recorder, time.monotonic, port="KBD-SEND")
    try:
        assert port.name == "kbd-sender:keys"
        keyboard.send(0x99, 38, 90)
        assert wait_until(lambda: len(recorder.messages) == 1)
        assert recorder.messages[0][0] == bytes([0x99, 38, 90])
    finally:
        port.close()


def test_missing_port_raises_port_not_found(keyboard: JackKeyboard, recorder: Recorder) -> None:
    """--port with no match raises PortNotFoundError naming the pattern and the ports there."""
    with pytest.raises(PortNotFoundError, match="'no-such-keyboard'.*kbd-sender:keys"):
        MidiInput("jack", recorder, time.monotonic, port="no-such-keyboard")


def _jam_input(jam: KeyboardJam, port: str | None = "kbd-sender") -> MidiInput:
    return MidiInput("jack", jam.handle, time.monotonic, port=port)


def test_routing_and_split_through_jack(keyboard: JackKeyboard) -> None:
    """Channel 10 -> drums, keys below the split -> bass, keys from the split up -> nobody."""
    jam = KeyboardJam(KeyboardLayout(split=48))
    port = _jam_input(jam)
    got = []
    try:
        keyboard.send(0x99, 42, 80)  # channel 10: hi-hat
        keyboard.send(0x90, 47, 70)  # B2: below the split
        keyboard.send(0x90, 48, 70)  # C3: the pianist's
        keyboard.send(0x80, 47, 0)
        assert wait_until(lambda: got.extend(jam.drain()) or len(got) >= 3)
        assert port.received == 4
    finally:
        port.close()
    assert [(a.routed.performer, type(a.routed.event), a.routed.event.note) for a in got] == [
        ("drums", NoteOn, 42),
        ("bass", NoteOn, 47),
        ("bass", NoteOff, 47),
    ]


def test_upper_drums_through_jack(keyboard: JackKeyboard) -> None:
    """--upper drums turns an upper D into a snare stroke on channel 10."""
    jam = KeyboardJam(KeyboardLayout(split=48, upper="drums"))
    port = _jam_input(jam)
    got = []
    try:
        keyboard.send(0x90, 62, 100)  # D4
        assert wait_until(lambda: got.extend(jam.drain()) or len(got) >= 1)
    finally:
        port.close()
    assert got[0].routed.performer == "drums"
    assert (got[0].routed.event.channel, got[0].routed.event.note) == (9, 38)


def test_no_delay_stamps_arrival_and_delay_adds_it(keyboard: JackKeyboard) -> None:
    """Default: the event time is the arrival; --delay-ms D: arrival + D."""
    for delay_s in (0.0, 0.25):
        jam = KeyboardJam(KeyboardLayout(), delay_s=delay_s)
        port = _jam_input(jam)
        got = []
        try:
            keyboard.send(0x90, 30, 100)
            assert wait_until(lambda: got.extend(jam.drain()) or len(got) >= 1)  # noqa: B023
        finally:
            port.close()
        assert got[0].routed.event.time_s == pytest.approx(got[0].arrival_s + delay_s)


def test_thru_forwards_at_once_without_delay(keyboard: JackKeyboard, synth: JackSynth) -> None:
    """--thru: every note reaches the synth; upper-drum keys arrive as drum notes."""
    thru = MidiOutput("jack", "test-synth", time.monotonic)
    jam = KeyboardJam(KeyboardLayout(upper="drums"), thru=thru)
    port = _jam_input(jam)
    try:
        assert thru.name == "test-synth:midi_in"
        keyboard.send(0x90, 36, 100)  # bass
        keyboard.send(0x90, 64, 100)  # E4 -> closed hi-hat
        assert wait_until(lambda: len(synth.got) >= 2)
    finally:
        port.close()
        thru.close()
    assert [m for m, _ in synth.got] == [[0x90, 36, 100], [0x99, 42, 100]]


def test_thru_with_delay_is_never_early(keyboard: JackKeyboard, synth: JackSynth) -> None:
    """--delay-ms D: the synth gets each note no earlier than its arrival + D, in order."""
    delay_s = 0.15
    thru = MidiOutput("jack", "test-synth", time.monotonic)
    jam = KeyboardJam(KeyboardLayout(), delay_s=delay_s, thru=thru)
    arrivals: list[float] = []

    def handler(data: bytes, arrival_s: float) -> None:
        arrivals.append(arrival_s)
        jam.handle(data, arrival_s)

    port = MidiInput("jack", handler, time.monotonic, port="kbd-sender")
    try:
        keyboard.send(0x90, 40, 100)
        keyboard.send(0x80, 40, 0)
        assert wait_until(lambda: len(synth.got) >= 2)
    finally:
        port.close()
        thru.close()
    assert [m for m, _ in synth.got] == [[0x90, 40, 100], [0x80, 40, 0]]
    for (_, received), arrival in zip(synth.got, arrivals, strict=True):
        assert received >= arrival + delay_s


def test_unplug_and_replug_reconnects(keyboard: JackKeyboard, recorder: Recorder) -> None:
    """A keyboard that goes away and comes back plays again after the next port poll."""
    port = MidiInput("jack", recorder, time.monotonic, port="kbd-sender", poll_interval_s=0.5)
    try:
        now = 1000.0
        assert port.poll(now) is None  # plugged: nothing to do
        keyboard.unplug()
        now += 1.0
        change = port.poll(now)
        assert change is not None and change.disconnect == "kbd-sender:keys"
        assert port.connected_to is None
        now += 1.0
        assert port.poll(now) is None  # still unplugged: no crash, nothing to do
        keyboard.plug()
        now += 1.0
        change = port.poll(now)
        assert change is not None and change.connect == "kbd-sender:keys"
        assert port.reconnects == 1
        keyboard.send(0x90, 33, 64)
        assert wait_until(lambda: len(recorder.messages) == 1)
        assert recorder.messages[0][0] == bytes([0x90, 33, 64])
    finally:
        port.close()


def test_poll_lists_ports_only_when_due(keyboard: JackKeyboard, recorder: Recorder) -> None:
    """Between polls (poll_interval_s) an unplugged keyboard is not noticed: the rate is low."""
    port = MidiInput("jack", recorder, time.monotonic, port="kbd-sender", poll_interval_s=0.5)
    try:
        assert port.poll(10.0) is None
        keyboard.unplug()
        assert port.poll(10.4) is None
        assert port.poll(10.5) is not None
    finally:
        port.close()


def test_events_carry_the_routed_types(keyboard: JackKeyboard) -> None:
    """Note-on with velocity 0 from a real port becomes a NoteOff."""
    jam = KeyboardJam(KeyboardLayout())
    port = _jam_input(jam)
    got = []
    try:
        keyboard.send(0x90, 35, 0)
        assert wait_until(lambda: got.extend(jam.drain()) or len(got) >= 1)
    finally:
        port.close()
    assert isinstance(got[0].routed.event, NoteOff)
