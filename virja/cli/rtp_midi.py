"""``--rtp-midi [HOST:]PORT`` for ``virja serve`` and ``virja jam``: the glue
between the CLI and :mod:`virja.rtpmidi` (the commands keep a few lines each)."""

from __future__ import annotations

import argparse
from typing import Any

from virja.rtpmidi import DEFAULT_PORT


def add_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--rtp-midi",
        metavar="[HOST:]PORT",
        help=f"also accept RTP-MIDI (Apple network MIDI) sessions on PORT (control) and "
        f"PORT+1 (data), e.g. {DEFAULT_PORT}; host 127.0.0.1 unless given (docs/rtp-midi.md)",
    )
    p.add_argument(
        "--rtp-midi-name",
        default="virja",
        metavar="NAME",
        help="the session name peers see (default virja)",
    )
    p.add_argument(
        "--announce",
        action="store_true",
        help="announce the RTP-MIDI session over mDNS/Bonjour (_apple-midi._udp)",
    )


def check(args: argparse.Namespace) -> tuple[str, int] | None:
    """The address to bind, or None without --rtp-midi; ConfigError for bad input."""
    from virja.errors import ConfigError
    from virja.rtpmidi.transport import parse_listen

    if args.rtp_midi is None:
        if args.announce:
            raise ConfigError("--announce announces an RTP-MIDI session: give --rtp-midi too")
        return None
    return parse_listen(args.rtp_midi)


def listening_line(command: str, listener: Any, bound: tuple[str, int]) -> str:
    name = listener.host.config.name
    announced = ", announced over mDNS" if listener.announcement is not None else ""
    return (
        f"virja {command}: RTP-MIDI session {name!r} on {bound[0]}:{bound[1]} "
        f"(control) and {bound[1] + 1} (data){announced}"
    )


async def start_serve(args: argparse.Namespace, clock: Any, daemon: Any) -> Any:
    """The listener for ``virja serve``: its notes go to ``daemon.on_events``."""
    from virja.rtpmidi.host import HostConfig
    from virja.rtpmidi.recording import to_received
    from virja.rtpmidi.transport import Listener

    where = check(args)
    if where is None:
        return None

    def on_messages(messages: list[Any], now_s: float) -> None:
        received = to_received(messages)
        if received:
            daemon.on_events(received, now_s)

    listener = Listener(clock, on_messages, config=HostConfig(name=args.rtp_midi_name))
    listener.on_arrival = daemon.arrived  # the first datagram is the session's start
    bound = await listener.start(*where)
    if args.announce:
        try:
            await listener.announce()
        except BaseException:
            await listener.close()
            raise
    print(listening_line("serve", listener, bound), flush=True)
    return listener


def start_jam(args: argparse.Namespace, clock: Any, handle: Any) -> Any:
    """The listener for ``virja jam``, on its own thread: every message goes to
    ``handle(data, time_s)`` as a keyboard's does."""
    from virja.rtpmidi.host import HostConfig
    from virja.rtpmidi.transport import ListenerThread

    where = check(args)
    if where is None:
        return None

    def on_messages(messages: list[Any], now_s: float) -> None:
        for m in messages:
            handle(m.data, m.time_s)

    thread = ListenerThread(clock, on_messages, config=HostConfig(name=args.rtp_midi_name))
    bound = thread.start(*where, announce=args.announce)
    print(listening_line("jam", thread.listener, bound), flush=True)
    return thread
