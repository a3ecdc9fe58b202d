"""Stream a MIDI file as RMCP/1 over UDP in real time: a stand-in performance generator.

Each note is sent --lead-beats beats before it sounds (at the file's tempo at
that point), stamped with the session time it must sound at; a BEAT message
goes out for every beat (level 2 on bar heads).  Each performer gets its own
sender id (bass 1, drums 2, anything else 3; --sender forces one).  The sender
also answers CLOCK_REQUESTs, so receivers can use it as --clock-server.

Example:  virja send song.mid --to 127.0.0.1:50500 --start-in 2
"""

from __future__ import annotations

import argparse
import asyncio

from virja.cli.common import finite_float
from virja.errors import ConfigError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="MIDI file (type 0 or 1)")
    parser.add_argument(
        "--to",
        default="127.0.0.1:50500",
        metavar="HOST:PORT",
        help="destination: unicast, broadcast or multicast address; [v6]:PORT for IPv6 "
        "(default 127.0.0.1:50500)",
    )
    parser.add_argument(
        "--lead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="send each note B beats before it sounds (default 1)",
    )
    parser.add_argument(
        "--sender", type=int, default=None, metavar="N", help="one sender id for all"
    )
    parser.add_argument("--key-file", default=None, metavar="PATH", help="sign with this HMAC key")
    parser.add_argument("--loop", action="store_true", help="start again at the end, forever")
    parser.add_argument(
        "--bind",
        default=None,
        metavar="HOST:PORT",
        help="local address to send from and answer clock requests on "
        "(default: any address, a free port); give it to `virja serve --clock-server`",
    )
    parser.add_argument(
        "--start-in",
        type=finite_float,
        default=1.0,
        metavar="SECONDS",
        help="the file starts this long after launch (default 1)",
    )


def run(args: argparse.Namespace) -> int:
    from virja.clock import SessionClock
    from virja.midifile import read_midi
    from virja.rmcp.sender import Route, SendOptions
    from virja.rmcp.signing import load_key
    from virja.rmcp.streamer import SendSettings, stream
    from virja.rmcp.transport import parse_hostport
    from virja.routing import Router

    if args.lead_beats < 0:
        raise ConfigError("--lead-beats must be >= 0")
    if args.start_in < 0:
        raise ConfigError("--start-in must be >= 0")
    if args.sender is not None and not 0 <= args.sender <= 65535:
        raise ConfigError("--sender must be 0-65535")
    host, port = parse_hostport(args.to)
    if port == 0:
        raise ConfigError(f"--to {args.to}: port 0 is not a destination")
    bind = parse_hostport(args.bind) if args.bind else None
    key = load_key(args.key_file) if args.key_file else None
    session = read_midi(args.file)
    options = SendOptions(lead_beats=args.lead_beats, sender=args.sender)

    def route_factory() -> Route:
        return Router.for_session(session).route

    print(
        f"virja send: {args.file}: {len(session.notes)} notes, {session.duration_s:.1f} s "
        f"-> {host}:{port}{' (signed)' if key else ''}{' (looping)' if args.loop else ''}"
    )
    try:
        stats = asyncio.run(
            stream(
                SendSettings(
                    (host, port),
                    options,
                    start_in_s=args.start_in,
                    loop=args.loop,
                    key=key,
                    bind=bind,
                ),
                # chord symbols the file carries go out as CHORD messages
                events=sorted([*session.events, *session.chords], key=lambda e: e.time_s),
                tempo=session.tempo_map,
                beats=session.beats,
                duration_s=session.duration_s,
                route_factory=route_factory,
                clock=SessionClock(),
                on_bound=lambda a: print(
                    f"virja send: answering clock requests on {a[0]}:{a[1]}", flush=True
                ),
            )
        )
    except OSError as exc:
        raise ConfigError(f"cannot send to {host}:{port}: {exc.strerror or exc}") from None
    print(
        f"virja send: sent {stats.datagrams} datagrams in {stats.passes} pass(es), "
        f"answered {stats.clock_replies} clock requests"
    )
    return 0
