"""A minimal blocking RTP-MIDI initiator built on virja's own codec (for socket tests;
the independent peer is node-rtpmidi, tests/cli/test_rtp_midi_node.py)."""

from __future__ import annotations

import socket

from virja.rtpmidi.control import Command, SessionPacket, SyncPacket, parse_control
from virja.rtpmidi.payload import midi_packet


class Peer:
    def __init__(self, host: str, port: int, ssrc: int = 0x5EED) -> None:
        self.target = (host, port)
        self.ssrc = ssrc
        self.seq = 100
        self.control = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.data = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for s in (self.control, self.data):
            s.bind(("127.0.0.1", 0))
            s.settimeout(5.0)

    def _ask(self, sock: socket.socket, to: tuple[str, int], data: bytes) -> object:
        sock.sendto(data, to)
        reply, _ = sock.recvfrom(2048)
        return parse_control(reply)

    def join(self) -> tuple[object, object, object]:
        inv = bytes(SessionPacket(Command.IN, 4242, self.ssrc, "py-peer"))
        ok1 = self._ask(self.control, self.target, inv)
        ok2 = self._ask(self.data, (self.target[0], self.target[1] + 1), inv)
        ck1 = self._ask(
            self.data,
            (self.target[0], self.target[1] + 1),
            bytes(SyncPacket(self.ssrc, 0, (7, 0, 0))),
        )
        return ok1, ok2, ck1

    def send(self, *commands: tuple[int, list[int]]) -> None:
        self.seq += 1
        pkt = midi_packet(self.ssrc, self.seq, 0, *commands)
        self.data.sendto(pkt, (self.target[0], self.target[1] + 1))

    def send_raw(self, data: bytes, *, control: bool = False) -> None:
        port = self.target[1] + (0 if control else 1)
        (self.control if control else self.data).sendto(data, (self.target[0], port))

    def recv_control(self) -> object:
        reply, _ = self.control.recvfrom(2048)
        return parse_control(reply)

    def bye(self) -> None:
        self.control.sendto(bytes(SessionPacket(Command.BY, 4242, self.ssrc, "")), self.target)

    def close(self) -> None:
        self.control.close()
        self.data.close()
