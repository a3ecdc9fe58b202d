"""The viewer in a real browser (Debian's chromium through Playwright) while `virja send` plays.

Three pages at once: the default view, the drummer's camera, and a transparent
overlay without the status line.  Each must connect, follow the clock, show a
band that moves, and log no console error.
"""

from __future__ import annotations

import base64
import re
import shutil
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.web.conftest import ENV, VIRJA, demo_excerpt, serve_web

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
PAGES = {
    "front": "?fps=12",
    "drums": "?camera=drums&fps=12",
    "overlay": "?camera=bass&transparent=1&status=0&fps=12",
}
pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(
        not Path(CHROMIUM).exists(), reason="chromium not installed (tools/setup.sh)"
    ),
]


def grab(page: Any) -> np.ndarray:
    """The canvas as drawn, every second pixel: (h, w, 4) RGBA."""
    px = page.evaluate("() => window.virjaPixels(2)")
    rgba = np.frombuffer(base64.b64decode(px["rgba"]), dtype=np.uint8)
    return rgba.astype(np.int16).reshape(px["h"], px["w"], 4)


def test_three_browsers_watch_the_band_play_what_send_sends(tmp_path: Path) -> None:
    from playwright.sync_api import sync_playwright

    mid = demo_excerpt(tmp_path / "excerpt.mid", 6.0)
    errors: list[str] = []
    with serve_web() as served, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            pages = {}
            for name, query in PAGES.items():
                page = browser.new_page(viewport={"width": 320, "height": 180})
                page.on(
                    "console",
                    lambda m, n=name: m.type == "error" and errors.append(f"{n}: {m.text}"),
                )
                page.on("pageerror", lambda e, n=name: errors.append(f"{n}: {e}"))
                page.goto(served.url + query)
                pages[name] = page
            for page in pages.values():
                try:
                    page.wait_for_function(
                        "() => window.virjaStats && window.virjaStats.frames > 5", timeout=90_000
                    )
                except Exception as exc:
                    raise AssertionError(f"no frames drawn: {errors or exc}") from None
            sender = subprocess.Popen(
                [
                    *VIRJA,
                    "send",
                    str(mid),
                    "--to",
                    f"127.0.0.1:{served.udp_port}",
                    "--start-in",
                    "0.3",
                    "--loop",
                ],
                env=ENV,
            )
            shots: dict[str, list[np.ndarray]] = {n: [] for n in pages}
            time.sleep(1.0)
            for k in range(4):
                time.sleep(0.5)
                for name, page in pages.items():
                    # a picture drawn since the last one (a loaded machine may draw slowly)
                    drawn = page.evaluate("() => window.virjaStats.draws")
                    page.wait_for_function(
                        f"() => window.virjaStats.draws > {drawn + 1}", timeout=60_000
                    )
                    shots[name].append(grab(page))
                    if k == 2:
                        page.screenshot(path=str(tmp_path / f"{name}.png"))
            status = pages["front"].inner_text("#status")
            stats = {n: p.evaluate("() => window.virjaStats") for n, p in pages.items()}
            # the page's session clock (serve without --clock-server: this machine's Unix time)
            before = time.time()
            page_now = pages["front"].evaluate(
                "() => performance.now() / 1000 + window.virjaStats.offset"
            )
            after = time.time()
            overlay_hidden = pages["overlay"].evaluate(
                "() => document.getElementById('status').classList.contains('hidden')"
            )
            assert sender.poll() is None  # still playing (--loop)
            sender.terminate()
            sender.wait(timeout=30)
        finally:
            browser.close()
    assert not errors, errors
    for name, frames in shots.items():
        moved = [
            np.abs(b[..., :3] - a[..., :3]).mean() for a, b in zip(frames, frames[1:], strict=False)
        ]
        assert min(moved) > 0.05, (name, moved)  # the band moves between every pair of shots
        assert stats[name]["connected"] and stats[name]["frames"] > 30, stats[name]
        assert stats[name]["rtt"] is not None and stats[name]["rtt"] < 0.5
    # the three cameras differ
    assert np.abs(shots["front"][-1] - shots["drums"][-1]).mean() > 5
    # the overlay: see-through where nothing is drawn, opaque where the band is
    alpha = shots["overlay"][-1][..., 3]
    assert (alpha == 0).mean() > 0.3 and (alpha == 255).mean() > 0.05
    assert overlay_hidden
    assert before - 0.05 < page_now < after + 0.05, (before, page_now, after)
    assert re.search(r"♩ = \d+\s+bar \d+\.\d\s+\S+\s+connected", status), status
