"""The thin asyncio layer: UDP endpoints around the sans-IO receiver.

:class:`RmcpProtocol` forwards each datagram with the session clock's time to
:class:`~virja.rmcp.receiver.Receiver`, records it to an optional pcap writer,
hands the events to ``on_events(list, now_s)`` and sends the clock replies the
receiver owes.  :func:`open_listener` binds ``HOST:PORT`` (IPv4 or IPv6) and
optionally joins a multicast group with SO_REUSEADDR/SO_REUSEPORT so several
receivers share it.  :class:`ClockClient` asks a clock server periodically and
feeds a :class:`~virja.clock.ClockEstimator`.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
import random
import socket
import struct
from collections.abc import Callable
from typing import Any, cast

from virja.clock import ClockEstimator, ClockGuard, SessionClock
from virja.errors import ConfigError
from virja.faults import survive_tick
from virja.rmcp import DEFAULT_PORT
from virja.rmcp.bodies import ClockReplyBody
from virja.rmcp.errors import RmcpError
from virja.rmcp.pcap import PcapWriter
from virja.rmcp.receiver import Received, Receiver
from virja.rmcp.seqnum import seq_add
from virja.rmcp.signing import sign, verify
from virja.rmcp.wire import Datagram, clock_request

log = logging.getLogger(__name__)

OnEvents = Callable[[list[Received], float], None]


def parse_hostport(text: str, default_port: int = DEFAULT_PORT) -> tuple[str, int]:
    """``HOST:PORT``, ``[v6]:PORT``, ``HOST``, ``[v6]`` or a bare IPv6 address."""
    t = text.strip()
    host, port_s = t, ""
    if t.startswith("["):
        end = t.find("]")
        if end < 0:
            raise ConfigError(f"bad address {text!r}: missing ']'")
        host, rest = t[1:end], t[end + 1 :]
        if rest and not rest.startswith(":"):
            raise ConfigError(f"bad address {text!r}: expected ':PORT' after ']'")
        port_s = rest[1:]
    elif t.count(":") == 1:
        host, port_s = t.split(":")
    elif ":" in t:
        try:
            ipaddress.ip_address(t.split("%")[0])
        except ValueError:
            raise ConfigError(
                f"bad address {text!r}: write an IPv6 address with a port as [ADDR]:PORT, "
                "e.g. [::1]:50500"
            ) from None
    if not host:
        raise ConfigError(f"bad address {text!r}: no host")
    if not port_s:
        return host, default_port
    try:
        port = int(port_s)
    except ValueError:
        raise ConfigError(f"bad address {text!r}: port {port_s!r} is not a number") from None
    if not 0 <= port <= 65535:
        raise ConfigError(f"bad address {text!r}: port must be 0-65535")
    return host, port


def _family(host: str) -> socket.AddressFamily:
    try:
        return (
            socket.AF_INET6
            if ipaddress.ip_address(host.split("%")[0]).version == 6
            else socket.AF_INET
        )
    except ValueError:
        try:
            infos = socket.getaddrinfo(host, None, type=socket.SOCK_DGRAM)
        except (OSError, UnicodeError) as exc:
            raise ConfigError(
                f"cannot resolve {host!r}: {getattr(exc, 'strerror', None) or exc}"
            ) from None
        if not infos:
            raise ConfigError(f"cannot resolve {host!r}") from None
        return infos[0][0]


def make_socket(host: str, port: int, *, group: str | None = None) -> socket.socket:
    """A bound, non-blocking UDP socket; joins ``group`` (IPv4 or IPv6 multicast) if given."""
    if group is not None:
        try:
            is_multicast = ipaddress.ip_address(group.split("%")[0]).is_multicast
        except ValueError:
            is_multicast = False
        if not is_multicast:
            raise ConfigError(
                f"--group {group}: not a multicast address (IPv4 224.0.0.0/4, IPv6 ff00::/8)"
            )
    fam = _family(group or host)
    sock = socket.socket(fam, socket.SOCK_DGRAM)
    try:
        if group is not None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if hasattr(socket, "SO_REUSEPORT"):
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            bind_host = group if fam == socket.AF_INET else "::"
            sock.bind((bind_host, port))
            _join(sock, fam, group, host)
        else:
            if fam == socket.AF_INET6 and host in ("::", ""):
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 0)
            sock.bind((host, port))
    except OSError as exc:
        sock.close()
        raise ConfigError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    _grow_receive_buffer(sock)
    sock.setblocking(False)
    return sock


RECEIVE_BUFFER_BYTES = 4 * 1024 * 1024


def _grow_receive_buffer(sock: socket.socket) -> None:
    """Ask for a 4 MiB receive buffer, so bursts (thousands of datagrams a second)
    ride out a busy moment of the event loop; the kernel may grant less
    (net.core.rmem_max), which is logged."""
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECEIVE_BUFFER_BYTES)
    except OSError as exc:
        log.info("could not set the receive buffer: %s", exc)
        return
    got = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
    if got < RECEIVE_BUFFER_BYTES:
        log.info(
            "receive buffer %d bytes (asked %d; raise net.core.rmem_max for more)",
            got,
            RECEIVE_BUFFER_BYTES,
        )


def _join(sock: socket.socket, fam: socket.AddressFamily, group: str, iface_host: str) -> None:
    if fam == socket.AF_INET:
        # join on the interface of the --listen address: 127.0.0.1 (the default)
        # keeps the group on this host; 0.0.0.0 lets the kernel pick the default one
        iface = iface_host if iface_host not in ("", "0.0.0.0") else "0.0.0.0"
        mreq = socket.inet_aton(group) + socket.inet_aton(iface)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
    else:
        mreq6 = socket.inet_pton(socket.AF_INET6, group) + struct.pack("@I", 0)
        sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_JOIN_GROUP, mreq6)


class RmcpProtocol(asyncio.DatagramProtocol):
    """Receives RMCP datagrams into a Receiver and forwards its events."""

    def __init__(
        self,
        receiver: Receiver,
        clock: SessionClock,
        on_events: OnEvents,
        *,
        recorder: PcapWriter | None = None,
    ) -> None:
        self.receiver = receiver
        self.clock = clock
        self.on_events = on_events
        self.recorder = recorder
        self.on_arrival: Callable[[int], None] | None = None  # each datagram's arrival (µs)
        self.transport: asyncio.DatagramTransport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        # the selector loop's datagram transport does not subclass DatagramTransport
        self.transport = cast(asyncio.DatagramTransport, transport)

    def datagram_received(self, data: bytes, addr: Any) -> None:
        self.receive(data, addr, now_us=self.clock.now_us())

    def receive(self, data: bytes, addr: Any, *, now_us: int) -> None:
        """One datagram that arrived at ``now_us`` (session clock; the kernel's
        stamp of its arrival where :mod:`virja.rmcp.stamped` has one)."""
        if self.on_arrival is not None:
            self.on_arrival(now_us)
        if self.recorder is not None:
            try:  # PcapWriter stops itself on a disk fault; anything else stops it here
                self.recorder.write(data, addr, time_us=now_us)
            except Exception:
                log.exception("recording stopped by an internal error; receiving goes on")
                self.recorder = None
        self.receiver.receive_datagram(data, addr, now_us=now_us)
        events = self.receiver.drain_events()
        if events:
            # an exception here would make asyncio close the socket: report it, go on
            with survive_tick():
                self.on_events(events, now_us / 1_000_000)
        if self.transport is not None:
            for out, to in self.receiver.datagrams_to_send(now_us=self.clock.now_us()):
                self.transport.sendto(out, to)

    def error_received(self, exc: Exception) -> None:
        log.warning("UDP error: %s", exc)


async def open_listener(
    host: str,
    port: int,
    protocol: RmcpProtocol,
    *,
    group: str | None = None,
) -> asyncio.DatagramTransport:
    """Bind ``host:port`` (and join ``group``) and attach ``protocol``."""
    loop = asyncio.get_running_loop()
    sock = make_socket(host, port, group=group)
    transport, _ = await loop.create_datagram_endpoint(lambda: protocol, sock=sock)
    return transport


class _ClockClientProtocol(asyncio.DatagramProtocol):
    def __init__(self, client: ClockClient) -> None:
        self.client = client

    def datagram_received(self, data: bytes, addr: Any) -> None:
        self.client.reply_received(data, t3_us=self.client.clock.local_us())


class ClockClient:
    """Sends CLOCK_REQUESTs to a clock server every ``interval_s`` and keeps an estimate.

    After each reply the clock's ``offset_us`` is set from the estimate when
    :class:`~virja.clock.ClockGuard` allows it, so ``clock.now_us()`` follows the
    server but no single reply can move it far; each kind of refusal is logged
    once as a warning and counted in ``refused``.
    """

    def __init__(
        self,
        server: tuple[str, int],
        clock: SessionClock,
        *,
        sender_id: int = 0,
        key: bytes | None = None,
        interval_s: float = 1.0,
        estimator: ClockEstimator | None = None,
        guard: ClockGuard | None = None,
    ) -> None:
        self.server = server
        self.clock = clock
        self.sender_id = sender_id
        self.key = key
        self.interval_s = interval_s
        self.estimator = estimator or ClockEstimator()
        self.guard = guard or ClockGuard()
        self.refused: dict[str, int] = {}
        self._pending: dict[int, int] = {}
        self._seq = random.getrandbits(32)
        self._transport: asyncio.DatagramTransport | None = None

    def request(self) -> bytes:
        """The next request's bytes (t0 = the uncorrected local clock)."""
        nonce = random.getrandbits(32)
        t0 = self.clock.local_us()
        self._pending[nonce] = t0
        while len(self._pending) > 16:
            self._pending.pop(next(iter(self._pending)))
        d = clock_request(
            self.sender_id, self._seq, nonce=nonce, t0_us=t0, time_us=self.clock.now_us()
        )
        self._seq = seq_add(self._seq, 1)
        return bytes(sign(d, self.key) if self.key is not None else d)

    def reply_received(self, data: bytes, *, t3_us: int) -> bool:
        """Feed one reply; returns whether it was a valid answer to a pending request."""
        try:
            d = Datagram.parse(data)
        except RmcpError as exc:
            log.debug("clock client: bad datagram: %s", exc)
            return False
        body = d.body
        if not isinstance(body, ClockReplyBody) or self._pending.get(body.nonce) != body.t0_us:
            return False
        if self.key is not None and not verify(d, self.key):
            return False
        del self._pending[body.nonce]
        if self.estimator.add(body.t0_us, body.t1_us, body.t2_us, t3_us) is None:
            return False
        est = self.estimator.estimate(t3_us)
        if est is not None:
            recent = self.estimator.recent_offsets(self.guard.agree)
            offset, refusal = self.guard.decide(self.clock.offset_us, est.offset_us, recent)
            if offset is not None:
                self.clock.offset_us = offset
            elif refusal is not None:
                if refusal not in self.refused:
                    (log.warning if refusal == "panic" else log.info)(
                        "clock server %s: offset %+.3f s refused (%s); the clock keeps %+.3f s",
                        self.server[0],
                        est.offset_us / 1e6,
                        "beyond the panic threshold"
                        if refusal == "panic"
                        else "a step not yet confirmed",
                        self.clock.offset_us / 1e6,
                    )
                self.refused[refusal] = self.refused.get(refusal, 0) + 1
        return True

    async def run(self) -> None:
        """Ask forever (cancel the task to stop)."""
        loop = asyncio.get_running_loop()
        transport, _ = await loop.create_datagram_endpoint(
            lambda: _ClockClientProtocol(self), remote_addr=self.server
        )
        self._transport = transport
        try:
            while True:
                try:
                    transport.sendto(self.request())
                except Exception as exc:  # one failed request must not stop the asking
                    log.warning("clock client: request not sent: %s", exc)
                await asyncio.sleep(self.interval_s)
        finally:
            transport.close()
