"""The asyncio listener on real sockets (127.0.0.1, a free even port pair)."""

from __future__ import annotations

import asyncio
import threading

import pytest

from tests.rtpmidi.peer import Peer
from virja.clock import SessionClock
from virja.errors import ConfigError
from virja.rtpmidi.control import Command, FeedbackPacket, SessionPacket, SyncPacket
from virja.rtpmidi.host import Incoming
from virja.rtpmidi.transport import Listener, ListenerThread, parse_listen


def test_parse_listen() -> None:
    assert parse_listen("5004") == ("127.0.0.1", 5004)
    assert parse_listen("0.0.0.0:6000") == ("0.0.0.0", 6000)
    assert parse_listen("[::1]:6000") == ("::1", 6000)
    assert parse_listen("localhost") == ("localhost", 5004)
    with pytest.raises(ConfigError, match="PORT\\+1 would be past 65535"):
        parse_listen("65535")
    with pytest.raises(ConfigError, match="port must be"):
        parse_listen("70000")


def test_a_peer_joins_syncs_sends_and_leaves_over_udp() -> None:
    got: list[Incoming] = []

    async def main() -> tuple[object, ...]:
        listener = Listener(SessionClock(), lambda msgs, now: got.extend(msgs))
        _host, port = await listener.start("127.0.0.1", 0)
        assert port % 2 == 0
        peer = Peer("127.0.0.1", port)
        try:
            loop = asyncio.get_running_loop()
            joined = await loop.run_in_executor(None, peer.join)
            peer.send((0, [0x99, 36, 100]), (5, [0x99, 38, 100]))
            rs = await loop.run_in_executor(None, peer.recv_control)  # feedback within a tick
            peer.bye()
            await asyncio.sleep(0.1)
            sessions = len(listener.host.sessions)
        finally:
            await listener.close()
            peer.close()
        return (*joined, rs, sessions)

    ok1, ok2, ck1, rs, sessions = asyncio.run(main())
    assert isinstance(ok1, SessionPacket) and ok1.command is Command.OK
    assert isinstance(ok2, SessionPacket) and ok2.command is Command.OK
    assert isinstance(ck1, SyncPacket) and ck1.count == 1 and ck1.timestamps[0] == 7
    assert isinstance(rs, FeedbackPacket) and rs.seq == 101
    assert sessions == 0
    assert [m.data for m in got] == [b"\x99\x24\x64", b"\x99\x26\x64"]


def test_the_thread_listener_hands_messages_to_a_callback() -> None:
    got: list[tuple[bytes, float]] = []
    seen = threading.Event()

    def on_messages(msgs: list[Incoming], now_s: float) -> None:
        got.extend((m.data, m.time_s) for m in msgs)
        seen.set()

    thread = ListenerThread(SessionClock(), on_messages)
    _host, port = thread.start("127.0.0.1", 0)
    peer = Peer("127.0.0.1", port)
    try:
        peer.join()
        peer.send((0, [0x90, 40, 90]))
        assert seen.wait(5.0)
    finally:
        thread.close()
        replies = [peer.recv_control(), peer.recv_control()]  # RS, then BY on close
        peer.close()
    assert [d for d, _t in got] == [b"\x90\x28\x5a"]
    assert isinstance(replies[0], FeedbackPacket) and replies[0].seq == 101
    bye = replies[1]
    assert isinstance(bye, SessionPacket) and bye.command is Command.BY


def test_a_port_in_use_is_a_config_error() -> None:
    async def main() -> None:
        a = Listener(SessionClock(), lambda m, n: None)
        _h, port = await a.start("127.0.0.1", 0)
        try:
            b = Listener(SessionClock(), lambda m, n: None)
            with pytest.raises(ConfigError, match=f"cannot listen on 127.0.0.1:{port}"):
                await b.start("127.0.0.1", port)
        finally:
            await a.close()

    asyncio.run(main())
