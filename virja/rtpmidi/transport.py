"""The thin asyncio layer: two UDP endpoints (PORT control, PORT+1 data) around
the sans-IO :class:`~virja.rtpmidi.host.SessionHost`.

Each datagram is stamped with the session clock, recorded if a recorder is
set (``write(data, addr, time_us=..., dst=(host, port))``, the port it came
in on), fed to the host, and the MIDI that came out handed to
``on_messages(list[Incoming], now_s)``; the answers the host owes go out from
the port they belong to.  A task ticks the host every ``TICK_S`` (timeouts,
receiver feedback).  :class:`ListenerThread` runs the same listener on its own
event loop in a thread, for callers without one (``virja jam``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import random
import threading
from collections.abc import Callable
from typing import Any, cast

from virja.clock import SessionClock
from virja.errors import ConfigError
from virja.rmcp.transport import make_socket, parse_hostport
from virja.rtpmidi import DEFAULT_BIND, DEFAULT_PORT
from virja.rtpmidi.host import Channel, HostConfig, Incoming, SessionHost

log = logging.getLogger(__name__)

OnMessages = Callable[[list[Incoming], float], None]
TICK_S = 0.25
PORT_TRIES = 64


def parse_listen(text: str) -> tuple[str, int]:
    """``PORT``, ``HOST:PORT``, ``[v6]:PORT`` or ``HOST`` (port 5004); host 127.0.0.1 by default."""
    t = text.strip()
    if t.isdigit():
        host, port = DEFAULT_BIND, int(t)
        if port > 65535:
            raise ConfigError(f"--rtp-midi {text}: port must be 0-65534")
    else:
        host, port = parse_hostport(t, default_port=DEFAULT_PORT)
    if port == 65535:
        raise ConfigError(f"--rtp-midi {text}: the data port PORT+1 would be past 65535")
    return host, port


class _Endpoint(asyncio.DatagramProtocol):
    def __init__(self, listener: Listener, channel: Channel) -> None:
        self.listener = listener
        self.channel = channel
        self.transport: asyncio.DatagramTransport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = cast(asyncio.DatagramTransport, transport)

    def datagram_received(self, data: bytes, addr: Any) -> None:
        self.listener.received(data, addr, self.channel)

    def error_received(self, exc: Exception) -> None:
        log.warning("RTP-MIDI UDP error: %s", exc)


class Listener:
    """An RTP-MIDI session listener on ``host:port`` and ``host:port+1``."""

    def __init__(
        self,
        clock: SessionClock,
        on_messages: OnMessages,
        *,
        config: HostConfig | None = None,
        recorder: Any = None,
    ) -> None:
        self.clock = clock
        self.on_messages = on_messages
        self.host = SessionHost(config)
        self.recorder = recorder
        self.on_arrival: Callable[[int], None] | None = None  # each datagram's arrival (µs)
        self.address: tuple[str, int] = ("", 0)
        self.announcement: Any = None  # an mDNS registration, withdrawn on close
        self.bound: tuple[str, int] = ("", 0)
        self._endpoints: dict[Channel, _Endpoint] = {}
        self._task: asyncio.Task[None] | None = None

    async def start(self, host: str, port: int) -> tuple[str, int]:
        """Bind both ports (port 0: a free even pair) and start ticking; the bound control address."""
        loop = asyncio.get_running_loop()
        socks = _bind_pair(host, port)
        for channel, sock in zip((Channel.CONTROL, Channel.DATA), socks, strict=True):
            ep = _Endpoint(self, channel)
            await loop.create_datagram_endpoint(lambda ep=ep: ep, sock=sock)  # type: ignore[misc]
            self._endpoints[channel] = ep
        bound = socks[0].getsockname()
        wildcard = bound[0] in ("0.0.0.0", "::")
        local = ("::1" if ":" in bound[0] else "127.0.0.1") if wildcard else bound[0]
        self.address = (local, bound[1])
        self._task = asyncio.create_task(self._ticker())
        self.bound = (bound[0], bound[1])
        return self.bound

    def received(self, data: bytes, addr: Any, channel: Channel) -> None:
        now_us = self.clock.now_us()
        if self.on_arrival is not None:
            self.on_arrival(now_us)
        if self.recorder is not None:
            port = self.address[1] + (1 if channel is Channel.DATA else 0)
            self.recorder.write(data, addr, time_us=now_us, dst=(self.address[0], port))
        self.host.receive_datagram(data, addr, channel=channel, now_us=now_us)
        messages = self.host.drain_messages()
        if messages:
            self.on_messages(messages, now_us / 1e6)
        self.flush(now_us)

    def flush(self, now_us: int) -> None:
        for data, addr, channel in self.host.datagrams_to_send(now_us=now_us):
            ep = self._endpoints.get(channel)
            if ep is not None and ep.transport is not None:
                ep.transport.sendto(data, addr)

    async def _ticker(self) -> None:
        while True:
            await asyncio.sleep(TICK_S)
            self.flush(self.clock.now_us())

    async def close(self) -> None:
        """Say BY to every peer, stop ticking, close both ports."""
        if self.announcement is not None:
            with contextlib.suppress(Exception):
                await self.announcement.close()
            self.announcement = None
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task
        self.host.close()
        self.flush(self.clock.now_us())
        for ep in self._endpoints.values():
            if ep.transport is not None:
                ep.transport.close()

    async def announce(self) -> None:
        """Announce the bound session over mDNS (``_apple-midi._udp``)."""
        from virja.rtpmidi.announce import announce

        self.announcement = await announce(self.host.config.name, self.bound)

    def summary(self) -> list[str]:
        st = self.host.stats
        dropped = ", ".join(f"{k} {v}" for k, v in sorted(st.dropped.items())) or "none"
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(st.by_kind.items())) or "none"
        return [
            f"RTP-MIDI: {st.datagrams} datagrams ({kinds}), {st.messages} MIDI messages, "
            f"{st.sessions_opened} sessions opened, {st.sessions_ended} ended, "
            f"{st.sessions_timed_out} timed out",
            f"RTP-MIDI dropped: {dropped}; {st.sysex_skipped} SysEx skipped, "
            f"{st.journals_ignored} journals ignored, {st.lost_packets} packets lost",
        ]


def _bind_pair(host: str, port: int) -> tuple[Any, Any]:
    """Sockets on ``port`` and ``port + 1``; for port 0 an even pair that is free."""
    if port != 0:
        if port % 2:
            log.warning("RTP-MIDI control port %d is odd; peers expect an even one", port)
        control = make_socket(host, port)
        try:
            return control, make_socket(host, port + 1)
        except ConfigError:
            control.close()
            raise
    for _ in range(PORT_TRIES):
        p = random.randrange(20000, 60000, 2)
        try:
            control = make_socket(host, p)
        except ConfigError:
            continue
        try:
            return control, make_socket(host, p + 1)
        except ConfigError:
            control.close()
    raise ConfigError(f"cannot find two free adjacent ports on {host}")


class ListenerThread:
    """A :class:`Listener` on its own event loop in a daemon thread.

    ``on_messages`` is called on that thread (as a MIDI backend calls its callback).
    """

    def __init__(self, clock: SessionClock, on_messages: OnMessages, **kwargs: Any) -> None:
        self.listener = Listener(clock, on_messages, **kwargs)
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True, name="rtp-midi")

    def start(self, host: str, port: int, *, announce: bool = False) -> tuple[str, int]:
        self._thread.start()

        async def start() -> tuple[str, int]:
            bound = await self.listener.start(host, port)
            if announce:
                try:
                    await self.listener.announce()
                except BaseException:
                    await self.listener.close()
                    raise
            return bound

        fut = asyncio.run_coroutine_threadsafe(start(), self._loop)
        try:
            return fut.result(timeout=30)
        except BaseException:
            self._stop_loop()
            raise

    def close(self) -> None:
        if not self._thread.is_alive():
            return
        fut = asyncio.run_coroutine_threadsafe(self.listener.close(), self._loop)
        with contextlib.suppress(Exception):
            fut.result(timeout=5)
        self._stop_loop()

    def _stop_loop(self) -> None:
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(timeout=5)
        self._loop.close()
