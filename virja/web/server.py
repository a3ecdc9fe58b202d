"""HTTP and WebSocket on one port, in a thread of its own: the viewer page and its feed.

``GET /`` is the page, ``/viewer.js`` its script, ``/three/*`` the vendored
three.js, ``/solid.glsl`` the native renderer's own shader; ``/ws`` is the
WebSocket.  Nothing else is served (a fixed table of routes, no file system
paths from the request).  The server runs its own asyncio loop in a daemon
thread, so the daemon's receive and planning loop never waits on a viewer:
the host hands messages over with :meth:`WebServer.broadcast` (thread-safe,
never blocks) and each viewer's writer drains its own bounded queue
(:mod:`virja.web.fanout`).
"""

from __future__ import annotations

import asyncio
import contextlib
import gzip
import json
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from virja.errors import ConfigError
from virja.resources import shaders_dir
from virja.web.fanout import Message, ViewerQueue

log = logging.getLogger(__name__)

CONTENT_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".glsl": "text/plain; charset=utf-8",
    ".txt": "text/plain; charset=utf-8",
}
MAX_INCOMING = 4096  # bytes: viewers only send clock pings


def static_dir() -> Path:
    return Path(str(resources.files("virja.web"))) / "static"


def routes() -> dict[str, Path]:
    """URL path -> file: everything the page loads, all from the package."""
    s = static_dir()
    return {
        "/": s / "index.html",
        "/index.html": s / "index.html",
        "/viewer.js": s / "viewer.js",
        "/three/three.module.js": s / "three" / "three.module.js",
        "/three/three.core.js": s / "three" / "three.core.js",
        "/three/LICENSE.txt": s / "three" / "LICENSE",
        "/solid.glsl": shaders_dir() / "solid.glsl",
    }


@dataclass
class WebStats:
    viewers: int = 0
    viewers_total: int = 0
    messages: int = 0
    bytes_queued: int = 0
    dropped: int = 0


class WebServer:
    """The viewer page and WebSocket fan-out on ``host:port`` (port 0 picks one)."""

    def __init__(
        self,
        host: str,
        port: int,
        *,
        greeting: Callable[[], list[Message]],
        now_s: Callable[[], float],
    ) -> None:
        self.host = host
        self.port = port
        self.greeting = greeting
        self.now_s = now_s
        self.stats = WebStats()
        self.bound: tuple[str, int] | None = None
        self._queues: set[ViewerQueue] = set()
        self._files: dict[str, tuple[bytes, bytes | None, str]] = {}
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._run, name="virja-web", daemon=True)
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._stop: asyncio.Event | None = None

    # --- host side (any thread) ------------------------------------------
    def start(self) -> tuple[str, int]:
        """Bind and serve; returns the address bound.  A bad address raises ConfigError."""
        for path, file in routes().items():
            body = file.read_bytes()
            packed = gzip.compress(body, 6) if len(body) > 4096 else None
            self._files[path] = (body, packed, CONTENT_TYPES.get(file.suffix, "text/plain"))
        self._thread.start()
        self._ready.wait()
        if self._error is not None:
            raise ConfigError(
                f"--web {self.host}:{self.port}: cannot serve: "
                f"{getattr(self._error, 'strerror', None) or self._error}"
            )
        assert self.bound is not None
        return self.bound

    @property
    def viewers(self) -> int:
        return self.stats.viewers

    @property
    def dropped(self) -> int:
        """Frames dropped for slow viewers, gone ones included."""
        return self.stats.dropped + sum(q.dropped for q in list(self._queues))

    def broadcast(self, msg: Message, *, droppable: bool = True) -> None:
        """Give ``msg`` to every viewer (frames are droppable); returns at once."""
        if self._loop.is_closed():
            return
        self._loop.call_soon_threadsafe(self._fan, msg, droppable)

    def submit(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on the server's thread (encoding off the host's loop)."""
        if self._loop.is_closed():
            return
        self._loop.call_soon_threadsafe(fn, *args)

    def close(self) -> None:
        if self._stop is not None and not self._loop.is_closed():
            self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(timeout=5.0)

    # --- server thread -----------------------------------------------------
    def fan_here(self, msg: Message, droppable: bool = True) -> None:
        """:meth:`broadcast` from the server's own thread."""
        self._fan(msg, droppable)

    def _fan(self, msg: Message, droppable: bool) -> None:
        if not self._queues:
            return
        self.stats.messages += 1
        self.stats.bytes_queued += len(msg) * len(self._queues)
        for q in self._queues:
            q.put(msg, droppable=droppable)

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._loop.run_until_complete(self._main())
        finally:
            self._loop.close()
            self._ready.set()

    async def _main(self) -> None:
        from websockets.asyncio.server import serve

        self._stop = asyncio.Event()
        try:
            server = await serve(
                self._viewer,
                self.host,
                self.port,
                process_request=self._http,
                compression=None,  # frames barely compress; deflate would cost CPU per viewer
                max_size=MAX_INCOMING,
                server_header="virja",
            )
        except (OSError, UnicodeError) as exc:
            self._error = exc
            self._ready.set()
            return
        sock = next(iter(server.sockets))
        name = sock.getsockname()
        self.bound = (str(name[0]), int(name[1]))
        self._ready.set()
        async with server:
            await self._stop.wait()
            for q in list(self._queues):
                q.close()
            server.close()

    def _http(self, connection: Any, request: Any) -> Any:
        from websockets.datastructures import Headers
        from websockets.http11 import Response

        path = request.path.split("?", 1)[0]
        if path == "/ws":
            return None  # the WebSocket handshake goes on
        entry = self._files.get(path)
        if entry is None:
            return connection.respond(404, "not found\n")
        body, packed, ctype = entry
        headers = Headers([("Content-Type", ctype), ("Cache-Control", "no-cache")])
        if packed is not None and "gzip" in request.headers.get("Accept-Encoding", ""):
            headers["Content-Encoding"] = "gzip"
            body = packed
        headers["Content-Length"] = str(len(body))
        return Response(200, "OK", headers, body)

    async def _viewer(self, ws: Any) -> None:
        q = ViewerQueue()
        for msg in self.greeting():
            q.put(msg, droppable=False)
        self._queues.add(q)
        self.stats.viewers += 1
        self.stats.viewers_total += 1
        writer = asyncio.create_task(self._write(ws, q))
        try:
            async for text in ws:
                reply = self._answer(text)
                if reply is not None:
                    q.put(reply, droppable=False, urgent=True)
        except Exception as exc:  # a viewer's broken connection ends that viewer only
            log.debug("viewer gone: %s", exc)
        finally:
            self._queues.discard(q)
            self.stats.viewers -= 1
            self.stats.dropped += q.dropped
            q.close()
            writer.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await writer

    async def _write(self, ws: Any, q: ViewerQueue) -> None:
        while True:
            msg = await q.get()
            await ws.send(msg)

    def _answer(self, text: Any) -> str | None:
        """A viewer's clock ping -> the session time now (NTP-style, one stamp)."""
        if not isinstance(text, str):
            return None
        try:
            msg = json.loads(text)
        except ValueError:
            return None
        if not isinstance(msg, dict) or msg.get("type") != "ping":
            return None
        c = msg.get("c")
        if not isinstance(c, int | float):
            return None
        return json.dumps({"type": "pong", "c": c, "s": self.now_s()})
