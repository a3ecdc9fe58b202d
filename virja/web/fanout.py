"""One bounded outgoing queue per viewer: a slow viewer loses its oldest frames, nobody waits.

The feed puts every message into every viewer's :class:`ViewerQueue` and never
blocks; each connection's writer takes from its own queue at the pace its
socket drains.  Frames are droppable (each stands alone); the few small
status messages (beats, chords, clock replies) are kept unless a viewer has
stopped reading altogether, when the queue's hard cap drops them too.
"""

from __future__ import annotations

import asyncio
from collections import deque

Message = bytes | str

MAX_FRAMES = 3  # frames waiting per viewer: 0.1 s at 30 fps
MAX_MESSAGES = 256  # anything waiting, frames or not


class ViewerQueue:
    """Messages waiting for one viewer; :meth:`put` never blocks, :meth:`get` waits."""

    def __init__(self, max_frames: int = MAX_FRAMES, max_messages: int = MAX_MESSAGES) -> None:
        if max_frames < 1 or max_messages < max_frames:
            raise ValueError(
                "a viewer queue holds at least one frame and max_messages >= max_frames"
            )
        self.max_frames = max_frames
        self.max_messages = max_messages
        self._items: deque[tuple[bool, Message]] = deque()
        self._frames = 0
        self._ready = asyncio.Event()
        self.dropped = 0
        self.closed = False

    def __len__(self) -> int:
        return len(self._items)

    def put(self, msg: Message, *, droppable: bool = True, urgent: bool = False) -> None:
        """Queue ``msg``; an ``urgent`` one goes first (clock replies); drop-oldest when full."""
        if self.closed:
            return
        if urgent:
            self._items.appendleft((droppable, msg))
        else:
            self._items.append((droppable, msg))
        if droppable:
            self._frames += 1
            if self._frames > self.max_frames:
                self._drop_oldest_frame()
        while len(self._items) > self.max_messages:
            gone, _ = self._items.popleft()
            self._frames -= gone
            self.dropped += 1
        self._ready.set()

    def _drop_oldest_frame(self) -> None:
        for i, (droppable, _) in enumerate(self._items):
            if droppable:
                del self._items[i]
                self._frames -= 1
                self.dropped += 1
                return

    async def get(self) -> Message:
        """The next message, waiting for one; raises ``asyncio.CancelledError`` when closed."""
        while not self._items:
            if self.closed:
                raise asyncio.CancelledError
            self._ready.clear()
            await self._ready.wait()
        droppable, msg = self._items.popleft()
        self._frames -= droppable
        return msg

    def close(self) -> None:
        self.closed = True
        self._items.clear()
        self._frames = 0
        self._ready.set()
