"""RTP-MIDI recordings and events: the node session read back as the live daemon got it,
next to RMCP in one capture; messages to events; the CLI glue's errors."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from tests.rtpmidi.conftest import NODE_SESSION, node_datagrams
from virja.errors import ConfigError, InputFileError
from virja.events import NoteOff, NoteOn, ProgramChange
from virja.input import pcap_input
from virja.rmcp import wire
from virja.rmcp.pcap import PcapWriter
from virja.routing import RoutingConfig
from virja.rtpmidi.host import Incoming
from virja.rtpmidi.recording import control_port, replay, to_received


def test_messages_become_the_bands_events_at_their_times() -> None:
    msgs = [
        Incoming(b"\x99\x24\x64", 10.002, 10.0, 7),
        Incoming(b"\x90\x28\x00", 10.0, 10.0, 7),  # velocity 0: a note-off
        Incoming(b"\xc0\x20", 10.0, 10.0, 7),
        Incoming(b"\xe0\x00\x40", 10.0, 10.0, 7),  # pitch bend: not the band's
        Incoming(b"\xf8", 10.0, 10.0, 7),
    ]
    got = to_received(msgs)
    assert [type(r.event) for r in got] == [NoteOn, NoteOff, ProgramChange]
    assert got[0].event.time_s == 10.002 and got[0].arrival_s == 10.0 and not got[0].late
    assert got[0].event.sender == 7


def test_the_node_session_replays_to_its_events() -> None:
    out = replay(node_datagrams())
    assert out.control_port == node_datagrams()[0].dst[1]
    notes = [r.event for r in out.received if isinstance(r.event, NoteOn)]
    assert [(n.channel, n.note) for n in notes] == [(9, 36), (9, 38), (9, 42), (0, 40), (0, 43)]
    assert out.stats.sysex_skipped == 1 and out.stats.sessions_opened == 1


def test_a_capture_with_rmcp_and_rtp_midi_gives_both_in_time_order(tmp_path: Path) -> None:
    dgrams = node_datagrams()
    t_mid = dgrams[5].time_us  # between two MIDI packets
    p = tmp_path / "both.pcap"
    rmcp = bytes(wire.midi(1, 0, t_mid + 1, b"\x99\x31\x50"))  # an RMCP note in between
    with PcapWriter.open(p, local=("127.0.0.1", 50500)) as w:
        for d in dgrams:
            w.write(d.payload, d.src, time_us=d.time_us, dst=d.dst)
            if d.time_us == t_mid:
                w.write(rmcp, ("127.0.0.1", 40000), time_us=t_mid + 1)
    src = pcap_input(p, RoutingConfig.from_dict({"channels": {"1": "bass"}}, "[routing]"))
    notes = [r.event.note for r in src.schedule if isinstance(r.event, NoteOn)]
    assert notes == [36, 38, 42, 40, 49, 43]
    assert [r.at_s for r in src.schedule] == sorted(r.at_s for r in src.schedule)
    assert src.immediate and src.note_count == 6
    assert any(line.startswith("RTP-MIDI on ports") for line in src.report)


def test_a_capture_with_neither_is_one_clear_error(tmp_path: Path) -> None:
    p = tmp_path / "other.pcap"
    with PcapWriter.open(p, local=("127.0.0.1", 9999)) as w:
        w.write(b"hello", ("127.0.0.1", 1234), time_us=1)
    with pytest.raises(InputFileError, match="no UDP datagrams to port 50500 .* no RTP-MIDI"):
        pcap_input(p, RoutingConfig())


def test_no_invitation_no_control_port() -> None:
    later = [d for d in node_datagrams() if d.payload[:4] != b"\xff\xffIN"]
    assert control_port(later) is None and replay(later).received == []
    assert NODE_SESSION.is_file()


def test_cli_glue_errors_are_config_errors() -> None:
    from virja.cli import rtp_midi

    args = argparse.Namespace(rtp_midi=None, announce=True)
    with pytest.raises(ConfigError, match="--announce announces an RTP-MIDI session"):
        rtp_midi.check(args)
    with pytest.raises(ConfigError, match="bad address"):
        rtp_midi.check(argparse.Namespace(rtp_midi="a:b:c", announce=False))


def test_the_announcement_names_the_service_and_the_control_port() -> None:
    from virja.rtpmidi.announce import service_info

    info = service_info("virja", ("192.168.1.20", 5004))
    assert info.type == "_apple-midi._udp.local."
    assert info.name == "virja._apple-midi._udp.local."
    assert info.port == 5004 and info.parsed_addresses() == ["192.168.1.20"]
