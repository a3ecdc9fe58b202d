"""A UDP listener whose datagrams carry the kernel's stamp of their arrival.

asyncio's datagram transport stamps a datagram when the process gets round to
reading it; a process that is busy (planning a long phrase) or short of CPU
(a loaded machine) then judges notes late that arrived in time.  Here the
socket asks the kernel for SO_TIMESTAMPNS (Linux) and each datagram is given
to :meth:`~virja.rmcp.transport.RmcpProtocol.receive` at its arrival on the
session clock: ``now - (wall now - kernel stamp)``.  Where the option is
missing the read time is used, as asyncio would.

Linux turns arrival stamping on a moment after the first socket asks for it (a
deferred work item): a datagram in that moment, right after ``virja serve`` opens
its socket, is stamped when read (tests/rmcp/test_stamped.py waits for it).
"""

from __future__ import annotations

import asyncio
import logging
import socket
import struct
import sys
import time
from typing import Any

from virja.clock import SessionClock
from virja.rmcp.transport import RmcpProtocol, make_socket

log = logging.getLogger(__name__)

# SO_TIMESTAMPNS (= SCM_TIMESTAMPNS) on Linux; the socket module does not name it
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35 if sys.platform == "linux" else None)
MAX_DATAGRAM = 65535
MAX_PER_WAKE = 256  # datagrams read per wake-up before the loop runs other work
MAX_AGE_NS = 10 * 1_000_000_000  # a stamp further back than this is not believed


def arrival_us(clock: SessionClock, stamp_ns: int | None, wall_now_ns: int) -> int:
    """Session time of an arrival the kernel stamped at ``stamp_ns`` (Unix ns)."""
    now_us = clock.now_us()
    if stamp_ns is None:
        return now_us
    age_ns = min(max(wall_now_ns - stamp_ns, 0), MAX_AGE_NS)
    return now_us - age_ns // 1000


def _stamp(ancdata: list[tuple[int, int, bytes]]) -> int | None:
    for level, kind, data in ancdata:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(data) >= 16:
            sec, nsec = struct.unpack("qq", data[:16])
            return int(sec * 1_000_000_000 + nsec)
    return None


class StampedListener:
    """Reads ``sock`` on the running loop into ``protocol``; a minimal transport
    (``sendto``, ``get_extra_info``, ``close``) for the protocol's clock replies."""

    def __init__(self, sock: socket.socket, protocol: RmcpProtocol, clock: SessionClock) -> None:
        self.sock = sock
        self.protocol = protocol
        self.clock = clock
        self.stamped = False
        if SO_TIMESTAMPNS is not None:
            try:
                sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
                self.stamped = True
            except OSError:
                log.info("no kernel receive timestamps: datagrams are stamped when read")
        self._anc = socket.CMSG_SPACE(16)
        self._loop = asyncio.get_running_loop()
        self._closed = False
        self._loop.add_reader(sock.fileno(), self._readable)
        protocol.connection_made(self)  # type: ignore[arg-type]

    def _readable(self) -> None:
        for _ in range(MAX_PER_WAKE):
            try:
                data, anc, _flags, addr = self.sock.recvmsg(MAX_DATAGRAM, self._anc)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                self.protocol.error_received(exc)
                return
            now_us = arrival_us(self.clock, _stamp(anc), time.time_ns())
            self.protocol.receive(data, addr, now_us=now_us)
            if self._closed:
                return

    # -- the transport the protocol sees -----------------------------------------
    def sendto(self, data: bytes, addr: Any = None) -> None:
        try:
            self.sock.sendto(data, addr)
        except OSError as exc:
            self.protocol.error_received(exc)

    def get_extra_info(self, name: str, default: Any = None) -> Any:
        if name == "sockname":
            return self.sock.getsockname()
        if name == "socket":
            return self.sock
        return default

    def is_closing(self) -> bool:
        return self._closed

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._loop.remove_reader(self.sock.fileno())
            self.sock.close()


async def open_stamped_listener(
    host: str, port: int, protocol: RmcpProtocol, clock: SessionClock, *, group: str | None = None
) -> StampedListener:
    """Bind ``host:port`` (and join ``group``) and read it with kernel arrival stamps."""
    return StampedListener(make_socket(host, port, group=group), protocol, clock)
