"""Figures for docs/web.md: what the browser viewer costs per viewer, and how early frames arrive.

Starts `virja serve --headless --web 127.0.0.1:0`, connects VIEWERS WebSocket
clients (and, with --browser, one chromium page through Playwright), plays
the demo into it with `virja send`, and prints per viewer: bytes per second,
frames per second, bytes per frame, and the delivery delay (arrival on this
machine's clock, which is the session clock here, minus the time the frame
was sampled: frame time - lead).  The browser's own figures are its margin
(frame time - arrival on its synced clock: > 0 means in time to be drawn at
its moment) and the share of draws that found no frame ahead of them.

    .venv/bin/python tools/web_bench.py [--viewers 3] [--browser]
"""

from __future__ import annotations

import argparse
import asyncio
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from websockets.asyncio.client import connect

from virja.web.frames import decode_frame

ROOT = Path(__file__).resolve().parents[1]
VIRJA = [sys.executable, "-m", "virja"]


async def viewer(url: str, seconds: float, lead_s: float) -> dict[str, float]:
    frames = bytes_ = 0
    delays: list[float] = []
    async with connect(url, max_size=None) as ws:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            try:
                msg = await asyncio.wait_for(ws.recv(), left)
            except TimeoutError:
                break
            if isinstance(msg, bytes):
                now = time.time()
                _, t, _ = decode_frame(msg)
                frames += 1
                bytes_ += len(msg)
                delays.append(now - (t - lead_s))
    delays.sort()
    return {
        "frames_per_s": frames / seconds,
        "bytes_per_s": bytes_ / seconds,
        "bytes_per_frame": bytes_ / max(frames, 1),
        "delay_median_ms": 1000 * statistics.median(delays),
        "delay_p95_ms": 1000 * delays[int(0.95 * (len(delays) - 1))],
    }


def browser_figures(url: str, seconds: float) -> dict[str, float]:
    from playwright.sync_api import sync_playwright

    args = [
        "--no-sandbox",
        "--use-gl=angle",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
    ]
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path="/usr/bin/chromium", args=args)
        page = b.new_page(viewport={"width": 640, "height": 360})
        page.goto(url)
        time.sleep(seconds)
        s = page.evaluate("() => window.virjaStats")
        b.close()
    margins = sorted(s["margins"])
    return {
        "margin_median_ms": 1000 * statistics.median(margins),
        "margin_p5_ms": 1000 * margins[int(0.05 * (len(margins) - 1))],
        "late_draw_share": s["lateDraws"] / max(s["draws"], 1),
        "draws_per_s": s["draws"] / seconds,
        "clock_rtt_ms": 1000 * s["rtt"],
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--viewers", type=int, default=3)
    ap.add_argument("--browser", action="store_true")
    ap.add_argument("--midi", default=str(ROOT / "virja" / "demo" / "blues.mid"))
    a = ap.parse_args()
    serve = subprocess.Popen(
        [*VIRJA, "serve", "--headless", "--quiet", "--listen", "127.0.0.1:0"]
        + ["--web", "127.0.0.1:0"],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert serve.stdout is not None
    udp = int(re.findall(r":(\d+)", serve.stdout.readline())[-1])
    web = re.findall(r"(http://\S+)", serve.stdout.readline())[0]
    seconds = 20.0
    send = subprocess.Popen(
        [*VIRJA, "send", a.midi, "--to", f"127.0.0.1:{udp}", "--start-in", "1", "--loop"],
        stdout=subprocess.DEVNULL,
    )
    try:

        async def all_viewers() -> list[dict[str, float]]:
            ws = web.replace("http", "ws") + "ws"
            return await asyncio.gather(*(viewer(ws, seconds, 0.1) for _ in range(a.viewers)))

        if a.browser:
            import threading

            out: dict[str, object] = {}
            th = threading.Thread(target=lambda: out.update(browser_figures(web, seconds)))
            th.start()
            results = asyncio.run(all_viewers())
            th.join()
        else:
            out, results = {}, asyncio.run(all_viewers())
        for i, r in enumerate(results):
            print(f"viewer {i}: " + ", ".join(f"{k} {v:.1f}" for k, v in r.items()))
        if out:
            print("browser: " + ", ".join(f"{k} {v:.3f}" for k, v in out.items()))  # type: ignore[str-format]
    finally:
        send.terminate()
        serve.terminate()
        serve.wait()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
