"""Kernel arrival stamps: a datagram read late (the process was busy) keeps the time
it arrived, so its note is not judged late."""

from __future__ import annotations

import asyncio
import contextlib
import socket
import struct
import sys
import time
from collections.abc import Iterator

import pytest

from virja.clock import SessionClock
from virja.rmcp import wire
from virja.rmcp.receiver import Received, Receiver, ReceiverConfig
from virja.rmcp.stamped import arrival_us, open_stamped_listener
from virja.rmcp.transport import RmcpProtocol


def test_arrival_is_now_less_the_age_of_the_stamp_and_bounded() -> None:
    clock = SessionClock(wall_ns=lambda: 1_000_000_000_000, monotonic_ns=lambda: 0)
    now_us = clock.now_us()
    assert arrival_us(clock, None, 5) == now_us
    assert arrival_us(clock, 2_000_000_000, 2_300_000_000) == now_us - 300_000
    assert arrival_us(clock, 2_000_000_000, 1_000_000_000) == now_us  # a stamp from the future
    assert arrival_us(clock, 0, 10**12) == now_us - 10_000_000  # at most 10 s back


@contextlib.contextmanager
def _kernel_stamping_on_arrival() -> Iterator[None]:
    """Hold a socket with arrival stamps open, and wait until the kernel stamps on arrival.

    Linux turns arrival stamping on for every socket a moment after the first socket
    asks for it (``net_enable_timestamp`` defers it to a work item); a datagram that
    arrives in that moment is stamped when it is read.  On a loaded machine the moment
    lasted past this test's send (CI: the note read 1.5 s on was judged late).  A
    datagram that sat 30 ms unread and is stamped at least 20 ms before the read shows
    it is on; the socket held open keeps it on for the test (bounded tries)."""
    with (
        socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx,
        socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx,
    ):
        rx.setsockopt(socket.SOL_SOCKET, getattr(socket, "SO_TIMESTAMPNS", 35), 1)
        rx.bind(("127.0.0.1", 0))
        for _ in range(40):
            tx.sendto(b"probe", rx.getsockname())
            time.sleep(0.03)
            _data, anc, _flags, _addr = rx.recvmsg(64, socket.CMSG_SPACE(16))
            read_ns = time.time_ns()
            stamps = [struct.unpack("qq", d[:16]) for _l, _k, d in anc if len(d) >= 16]
            if stamps and read_ns - (stamps[0][0] * 1_000_000_000 + stamps[0][1]) >= 20_000_000:
                break
        else:
            pytest.skip("the kernel did not stamp datagrams on arrival within 40 tries")
        yield


@pytest.mark.skipif(sys.platform != "linux", reason="SO_TIMESTAMPNS is Linux's")
def test_a_datagram_read_late_keeps_its_arrival_time() -> None:
    async def attempt() -> tuple[float, float, int, list[tuple[list[Received], float]]]:
        got: list[tuple[list[Received], float]] = []
        clock = SessionClock()
        receiver = Receiver(ReceiverConfig(lateness_s=0.06))
        protocol = RmcpProtocol(receiver, clock, lambda ev, now: got.append((ev, now)))
        listener = await open_stamped_listener("127.0.0.1", 0, protocol, clock)
        assert listener.stamped
        port = listener.get_extra_info("sockname")[1]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
            sent_s = clock.now_s()
            # a note due 500 ms from now: in time when it arrives, 1 s late when read
            data = wire.midi(3, 1, clock.now_us() + 500_000, bytes([0x99, 38, 100]))
            tx.sendto(bytes(data), ("127.0.0.1", port))
            after_send_s = clock.now_s()
            time.sleep(1.5)  # the loop is busy (a long plan, a starved process)
            for _ in range(50):
                await asyncio.sleep(0.01)
                if got:
                    break
        listener.close()
        return sent_s, after_send_s, receiver.stats.dropped["too_late"], got

    for _ in range(3):
        with _kernel_stamping_on_arrival():
            sent_s, after_send_s, too_late, got = asyncio.run(attempt())
        # the premise: the note was sent well before it was due.  A machine busy enough
        # to pause this thread between the due time and the send (it happened in CI,
        # even with 500 ms of room) makes it late on arrival: try again (bounded)
        if after_send_s - sent_s < 0.25:
            break
    else:
        pytest.skip("this thread was paused over 250 ms before each send: too busy to test")
    assert too_late == 0
    assert len(got) == 1
    events, now_s = got[0]
    assert len(events) == 1 and not events[0].late
    assert 0 <= now_s - sent_s < 0.5  # when it arrived, not when it was read (1.5 s on)
