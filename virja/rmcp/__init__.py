"""RMCP/1: the UDP protocol the performance generators speak (docs/rmcp.md).

``wire`` and ``bodies`` are the sans-IO codec, ``receiver`` the sans-IO
receiver state, ``signing`` the HMAC tags, ``pcap`` recordings, ``transport``
the thin asyncio layer and ``sender`` the stand-in generator behind
``virja send``.
"""

from __future__ import annotations

DEFAULT_PORT = 50500
DEFAULT_GROUP_V4 = "239.255.50.50"
DEFAULT_BIND = "127.0.0.1"
