"""Golden RTP-MIDI packets: a node-rtpmidi session captured by `virja serve --record`."""

from __future__ import annotations

from pathlib import Path

from virja.rmcp.pcap import CapturedDatagram, read_capture

DATA = Path(__file__).resolve().parents[1] / "data" / "rtpmidi"
NODE_SESSION = DATA / "node_session.pcap"


def node_datagrams() -> list[CapturedDatagram]:
    return read_capture(NODE_SESSION, port=None).datagrams


def node_payloads() -> list[bytes]:
    return [d.payload for d in node_datagrams()]
