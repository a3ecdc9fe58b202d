"""Real sockets on loopback only: IPv6 listening, and several receivers sharing a multicast
group and port (joined on 127.0.0.1, sent with TTL 0: nothing leaves the host)."""

from __future__ import annotations

import asyncio
import socket
from typing import Any

import pytest

from virja.clock import SessionClock
from virja.events import NoteOn
from virja.rmcp import wire
from virja.rmcp.receiver import Receiver
from virja.rmcp.transport import RmcpProtocol, make_socket, open_listener, parse_hostport

GROUP = "239.255.50.50"


def _note_datagram(seq: int) -> bytes:
    return bytes(wire.midi(2, seq, SessionClock().now_us() + 500_000, bytes([0x99, 38, 100])))


def test_ipv6_listen_address_parses() -> None:
    assert parse_hostport("[::1]:50500") == ("::1", 50500)


def test_ipv6_loopback_receives_a_note() -> None:
    if not socket.has_ipv6:
        pytest.skip("no IPv6 in this Python")

    async def run() -> list[Any]:
        got: list[Any] = []
        proto = RmcpProtocol(Receiver(), SessionClock(), lambda evs, now: got.extend(evs))
        transport = await open_listener("::1", 0, proto)
        port = transport.get_extra_info("sockname")[1]
        with socket.socket(socket.AF_INET6, socket.SOCK_DGRAM) as tx:
            tx.sendto(_note_datagram(0), ("::1", port))
        for _ in range(100):
            if got:
                break
            await asyncio.sleep(0.01)
        transport.close()
        return got

    got = asyncio.run(run())
    assert len(got) == 1 and isinstance(got[0].event, NoteOn)


def test_two_receivers_share_one_multicast_group_and_port() -> None:
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
    probe.close()

    async def run() -> tuple[list[Any], list[Any]]:
        got_a: list[Any] = []
        got_b: list[Any] = []
        loop = asyncio.get_running_loop()
        transports = []
        for sink in (got_a, got_b):
            proto = RmcpProtocol(Receiver(), SessionClock(), lambda evs, now, s=sink: s.extend(evs))
            sock = make_socket("127.0.0.1", port, group=GROUP)
            t, _ = await loop.create_datagram_endpoint(lambda p=proto: p, sock=sock)
            transports.append(t)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
            tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
            tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)  # never leaves the host
            tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            tx.sendto(_note_datagram(0), (GROUP, port))
        for _ in range(200):
            if got_a and got_b:
                break
            await asyncio.sleep(0.01)
        for t in transports:
            t.close()
        return got_a, got_b

    a, b = asyncio.run(run())
    assert len(a) == 1 and len(b) == 1
