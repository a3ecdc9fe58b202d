"""Twenty viewers while the demo plays into `serve`: no note lost, no viewer held up by another."""

from __future__ import annotations

import asyncio
import re
import signal
import time
from pathlib import Path

from websockets.asyncio.client import connect

from tests.web.conftest import VIRJA, demo_excerpt, serve_web
from virja.web.frames import decode_frame

READERS = 16
STALLED = 3  # connect and never read: their queues drop, nobody else waits
VANISHING = 1  # gone mid-song without a closing handshake


async def watch(url: str, seconds: float, mid: Path, udp_port: int) -> list[list[float]]:
    ws_url = url.replace("http", "ws") + "ws"
    times: list[list[float]] = [[] for _ in range(READERS)]

    async def reader(i: int) -> None:
        async with connect(ws_url, max_size=None) as ws:
            deadline = time.monotonic() + seconds
            while (left := deadline - time.monotonic()) > 0:
                try:
                    msg = await asyncio.wait_for(ws.recv(), left)
                except TimeoutError:
                    break
                if isinstance(msg, bytes):
                    times[i].append(decode_frame(msg)[1])

    async def stalled() -> None:
        async with connect(ws_url, max_queue=1):
            await asyncio.sleep(seconds)

    async def vanishing() -> None:
        ws = await connect(ws_url)
        await asyncio.sleep(seconds / 3)
        ws.transport.abort()

    async def send() -> int:
        await asyncio.sleep(0.5)  # everyone connected
        p = await asyncio.create_subprocess_exec(
            *VIRJA, "send", str(mid), "--to", f"127.0.0.1:{udp_port}", "--start-in", "0.3"
        )
        return await p.wait()

    tasks = [reader(i) for i in range(READERS)] + [stalled() for _ in range(STALLED)]
    tasks += [vanishing() for _ in range(VANISHING)]
    *_, sent = await asyncio.gather(*tasks, send())
    assert sent == 0
    return times


def test_twenty_viewers_and_the_demo_plays_into_serve_without_a_lost_note(tmp_path: Path) -> None:
    mid = demo_excerpt(tmp_path / "excerpt.mid", 6.0)
    with serve_web() as served:
        times = asyncio.run(watch(served.url, 9.0, mid, served.udp_port))
        served.proc.send_signal(signal.SIGINT)
        out, err = served.proc.communicate(timeout=30)
    assert served.proc.returncode == 0, err
    assert "0 rejected" in out and "dropped on arrival, never planned: 0" in out, out
    # all 59 band notes of the excerpt (14 bass, 45 drums: `virja plan` of it), none late
    assert re.search(r"notes: 59 for the band .*, 59 planned \(0 arrived late", out), out
    assert "0 dropped by the scheduler" in out, out
    m = re.search(r"web: (\d+) viewers, (\d+) frames", out)
    assert m and int(m.group(1)) == READERS + STALLED + VANISHING, out
    for got in times:
        # every reader kept up with the feed's 30 fps over the 9 s it watched, in order
        assert len(got) >= 0.6 * 30 * 9, (len(got), out)
        assert all(b > a for a, b in zip(got, got[1:], strict=False))
