"""``--web [HOST:PORT]`` for serve, replay and jam: the browser viewer (docs/web.md)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from virja.errors import ConfigError

if TYPE_CHECKING:
    from virja.live.outputs import WebSettings

DEFAULT_WEB = "127.0.0.1:8080"


def add_web_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--web",
        nargs="?",
        const=DEFAULT_WEB,
        metavar="HOST:PORT",
        help=f"serve a browser viewer at http://HOST:PORT/ (default {DEFAULT_WEB}; "
        "0.0.0.0:8080 lets other machines watch)",
    )
    p.add_argument(
        "--web-fps",
        type=float,
        default=30.0,
        metavar="FPS",
        help="frames per second sent to each browser (default 30; the page interpolates)",
    )
    p.add_argument(
        "--web-lead-ms",
        type=float,
        default=100.0,
        metavar="MS",
        help="sample frames this far ahead of the clock, to arrive in time (default 100)",
    )


def web_settings(args: argparse.Namespace) -> WebSettings | None:
    """The browser viewer's settings when --web is given; a one-line ConfigError for bad
    values."""
    if not getattr(args, "web", None):
        return None
    from virja.live.outputs import WebSettings
    from virja.rmcp.transport import parse_hostport

    host, port = parse_hostport(args.web, default_port=8080)
    if not 0.0 <= args.web_lead_ms <= 2000.0:
        raise ConfigError(f"--web-lead-ms must be 0-2000, got {args.web_lead_ms:g}")
    return WebSettings(host, port, fps=args.web_fps, lead_s=args.web_lead_ms / 1000)
