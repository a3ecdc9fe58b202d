"""The asyncio loop of ``virja send``: sleep until each send time, send, answer clocks.

All decisions are made by :func:`virja.rmcp.sender.schedule_pass`; this loop
only waits on the session clock, signs if a key is given and sends.  CLOCK_REQUESTs
arriving on the sending socket are answered (the sender is a clock server).
"""

from __future__ import annotations

import asyncio
import logging
import socket
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

from virja.clock import SessionClock
from virja.errors import ConfigError
from virja.events import Beat, Event
from virja.rmcp.receiver import Receiver, ReceiverConfig
from virja.rmcp.sender import Route, Scheduled, SendOptions, schedule_pass
from virja.rmcp.signing import sign
from virja.tempo import Tempo

log = logging.getLogger(__name__)


@dataclass
class StreamStats:
    datagrams: int = 0
    passes: int = 0
    clock_replies: int = 0


class _SendProtocol(asyncio.DatagramProtocol):
    """Answers CLOCK_REQUESTs that reach the sending socket; ignores the rest."""

    def __init__(
        self, clock: SessionClock, key: bytes | None, sender_id: int, stats: StreamStats
    ) -> None:
        self.clock = clock
        self.stats = stats
        self.receiver = Receiver(ReceiverConfig(key=key, sender_id=sender_id, horizon_s=0.0))
        self.transport: asyncio.DatagramTransport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        # the selector loop's datagram transport does not subclass DatagramTransport
        self.transport = cast(asyncio.DatagramTransport, transport)

    def datagram_received(self, data: bytes, addr: Any) -> None:
        self.receiver.receive_datagram(data, addr, now_us=self.clock.now_us())
        self.receiver.drain_events()
        assert self.transport is not None
        for out, to in self.receiver.datagrams_to_send(now_us=self.clock.now_us()):
            self.transport.sendto(out, to)
            self.stats.clock_replies += 1


@dataclass(frozen=True)
class SendSettings:
    """Where and how a performance is streamed, parsed once from `virja send`'s options.

    ``to``: the receiver; ``options``: lead and sender id (the pure schedule's);
    ``start_in_s``: the first pass starts this long after the call; ``loop``: pass
    after pass until cancelled (``max_passes`` at most, for tests); ``key``: HMAC
    signing; ``bind``: the local address clock requests are answered on.
    """

    to: tuple[str, int]
    options: SendOptions = field(default_factory=SendOptions)
    start_in_s: float = 1.0
    loop: bool = False
    key: bytes | None = None
    bind: tuple[str, int] | None = None
    max_passes: int | None = None


async def stream(
    settings: SendSettings,
    *,
    events: Sequence[Event],
    tempo: Tempo,
    beats: Sequence[Beat],
    duration_s: float,
    route_factory: Callable[[], Route],
    clock: SessionClock,
    on_sent: Callable[[Scheduled], None] | None = None,
    on_bound: Callable[[tuple[str, int]], None] | None = None,
) -> StreamStats:
    """Stream the performance to ``settings.to``; returns when done (or runs forever
    with ``settings.loop``)."""
    to, options, key, bind = settings.to, settings.options, settings.key, settings.bind
    start_in_s, loop, max_passes = settings.start_in_s, settings.loop, settings.max_passes
    stats = StreamStats()
    aloop = asyncio.get_running_loop()
    infos = socket.getaddrinfo(to[0], to[1], type=socket.SOCK_DGRAM)
    family, _, _, _, sockaddr = infos[0]
    sock = socket.socket(family, socket.SOCK_DGRAM)
    if family == socket.AF_INET:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
    # the socket clock requests are answered on: --bind, else any address, a free port
    try:
        sock.bind(
            bind if bind is not None else ("::" if family == socket.AF_INET6 else "0.0.0.0", 0)
        )
    except (OSError, OverflowError) as exc:
        sock.close()
        where = f"{bind[0]}:{bind[1]}" if bind is not None else "a local port"
        raise ConfigError(f"cannot bind {where}: {getattr(exc, 'strerror', None) or exc}") from None
    if on_bound is not None:
        name = sock.getsockname()
        on_bound((str(name[0]), int(name[1])))
    sock.setblocking(False)
    transport, _ = await aloop.create_datagram_endpoint(
        lambda: _SendProtocol(clock, key, options.conductor, stats), sock=sock
    )
    try:
        start_us = clock.now_us() + round(start_in_s * 1_000_000)
        period_us = max(1, round(duration_s * 1_000_000))
        seqs: dict[int, int] = {}
        # Sequence numbers start from the clock (milliseconds, modulo 2^32), so a
        # restarted sender keeps numbering upwards: its datagrams are neither taken
        # for repeats (last 4096) nor, with a key, for replays (at or below the last).
        seq_start = (clock.now_us() // 1000) & 0xFFFFFFFF
        n = 0
        while max_passes is None or n < max_passes:
            items, seqs = schedule_pass(
                events,
                tempo,
                beats,
                options,
                start_us + n * period_us,
                route=route_factory(),
                seqs=seqs,
                seq_start=seq_start,
            )
            for item in items:
                wait_us = item.send_us - clock.now_us()
                if wait_us > 0:
                    await asyncio.sleep(wait_us / 1_000_000)
                d = sign(item.datagram, key) if key is not None else item.datagram
                transport.sendto(bytes(d), sockaddr)
                stats.datagrams += 1
                if on_sent is not None:
                    on_sent(item)
            n += 1
            stats.passes = n
            if not loop:
                break
        # let the last notes sound before closing (clock requests are still answered)
        end_us = start_us + n * period_us
        wait_us = end_us - clock.now_us()
        if wait_us > 0 and max_passes is None:
            await asyncio.sleep(wait_us / 1_000_000)
    finally:
        transport.close()
    return stats
