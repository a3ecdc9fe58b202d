"""A viewer's queue never blocks the feed: the oldest frame goes, status messages stay."""

from __future__ import annotations

import asyncio

import pytest

from virja.web.fanout import ViewerQueue


def drain(q: ViewerQueue) -> list[object]:
    async def go() -> list[object]:
        return [await q.get() for _ in range(len(q))]

    return asyncio.run(go())


def test_a_full_queue_drops_its_oldest_frames_and_keeps_the_newest() -> None:
    q = ViewerQueue(max_frames=3)
    for i in range(10):
        q.put(b"frame%d" % i)
    assert q.dropped == 7
    assert drain(q) == [b"frame7", b"frame8", b"frame9"]


def test_status_messages_are_not_dropped_for_frames_and_keep_their_order() -> None:
    q = ViewerQueue(max_frames=2)
    q.put('{"type":"beat"}', droppable=False)
    for i in range(5):
        q.put(b"f%d" % i)
    q.put('{"type":"chord"}', droppable=False)
    q.put('{"type":"pong"}', droppable=False, urgent=True)
    assert drain(q) == ['{"type":"pong"}', '{"type":"beat"}', b"f3", b"f4", '{"type":"chord"}']


def test_a_viewer_that_never_reads_holds_at_most_max_messages() -> None:
    q = ViewerQueue(max_frames=2, max_messages=8)
    for _ in range(100):
        q.put("beat", droppable=False)
        q.put(b"frame")
    assert len(q) == 8


def test_a_closed_queue_wakes_its_reader() -> None:
    async def go() -> None:
        q = ViewerQueue()
        reader = asyncio.create_task(q.get())
        await asyncio.sleep(0)
        q.close()
        with pytest.raises(asyncio.CancelledError):
            await reader

    asyncio.run(go())


def test_bad_bounds_are_refused() -> None:
    with pytest.raises(ValueError, match="at least one frame"):
        ViewerQueue(max_frames=0)
