"""The viewer's server on loopback: the page and its libraries from the package, the feed."""

from __future__ import annotations

import argparse
import gzip
import json
import time
import urllib.error
import urllib.request
from collections.abc import Iterator

import pytest
from websockets.sync.client import connect

from virja.cli.web_option import add_web_arguments
from virja.errors import ConfigError
from virja.events import Beat, Chord, NoteOn
from virja.motion.band import BandAnimator
from virja.plan.config import load_plan_config
from virja.plan.planner import OnlinePlanner
from virja.routing import Router, RoutingConfig
from virja.session import Performance
from virja.web.feed import WebFeed, chord_name
from virja.web.frames import decode_frame


@pytest.fixture
def feed() -> Iterator[WebFeed]:
    f = WebFeed("127.0.0.1", 0, lambda: 1000.0 + time.monotonic(), fps=60)
    f.start()
    yield f
    f.close()


def get(url: str, gz: bool = False) -> tuple[int, dict[str, str], bytes]:
    req = urllib.request.Request(url, headers={"Accept-Encoding": "gzip"} if gz else {})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, dict(r.headers), r.read()
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read()


def base(feed: WebFeed) -> str:
    host, port = feed.server.bound or ("", 0)
    return f"http://{host}:{port}"


def test_the_page_and_everything_it_loads_come_from_virja(feed: WebFeed) -> None:
    status, headers, body = get(base(feed) + "/?camera=drums")
    assert status == 200 and headers["Content-Type"].startswith("text/html")
    assert b'src="/viewer.js"' in body and b"http" not in body.replace(b"http-equiv", b"")
    status, _, js = get(base(feed) + "/viewer.js")
    assert status == 200 and b"from '/three/three.module.js'" in js
    status, headers, packed = get(base(feed) + "/three/three.module.js", gz=True)
    assert status == 200 and headers["Content-Encoding"] == "gzip"
    assert b"from './three.core.js'" in gzip.decompress(packed)
    assert get(base(feed) + "/three/three.core.js")[0] == 200
    assert b"MIT License" in get(base(feed) + "/three/LICENSE.txt")[2]
    assert b"FRAGMENT_SHADER" in get(base(feed) + "/solid.glsl")[2]


def test_only_the_routes_in_the_table_are_served(feed: WebFeed) -> None:
    for path in (
        "/pyproject.toml",
        "/../pyproject.toml",
        "/three/../server.py",
        "/static/viewer.js",
    ):
        assert get(base(feed) + path)[0] == 404, path


def test_a_viewer_gets_hello_then_beats_chords_and_frames_and_its_clock_pings_answered(
    feed: WebFeed,
) -> None:
    perf = Performance(
        router=Router(RoutingConfig()),
        planner=OnlinePlanner(load_plan_config(None)),
        animator=BandAnimator(),
    )
    feed.attach(perf)
    perf.feed(Beat(1.0, 2, 3, 4, 0, 500_000), now_s=0.5)  # told to viewers who come later
    with connect(base(feed).replace("http", "ws") + "/ws", max_queue=None) as ws:
        hello = json.loads(ws.recv(timeout=10))
        assert hello["type"] == "hello" and hello["fps"] == 60
        beat = json.loads(ws.recv(timeout=10))
        assert beat == {"type": "beat", "t": 1.0, "bar": 3, "beat": 3, "bpb": 4, "bpm": 120.0}
        perf.feed(Chord(2.0, 10, None, "7"), now_s=1.0)
        assert json.loads(ws.recv(timeout=10))["name"] == "Bb7"
        ws.send(json.dumps({"type": "ping", "c": 12.5}))
        pong = json.loads(ws.recv(timeout=10))
        assert pong["type"] == "pong" and pong["c"] == 12.5 and pong["s"] > 1000.0
        perf.feed(NoteOn(2.0, 9, 38, 100), now_s=1.0)
        got = []
        for k in range(30):
            perf.advance(1.0 + k / 60)
            feed.publish(perf, 1.0 + k / 60)
            time.sleep(1 / 120)
        while len(got) < 5:
            msg = ws.recv(timeout=10)
            if isinstance(msg, bytes):
                got.append(decode_frame(msg))
        # sampled ahead of the clock by lead_s, in order
        assert all(b[1] > a[1] for a, b in zip(got, got[1:], strict=False))
        assert got[0][1] == pytest.approx(1.0 + feed.lead_s, abs=0.02)
    assert feed.server.stats.viewers_total == 1


def test_nothing_is_sampled_while_nobody_watches(feed: WebFeed) -> None:
    class NoPose:
        def pose(self, t: float) -> None:
            raise AssertionError("sampled with no viewer")

    feed.publish(NoPose(), 5.0)  # type: ignore[arg-type]
    assert feed.frames == 0


def test_a_busy_port_is_a_one_line_error(feed: WebFeed) -> None:
    _, port = feed.server.bound or ("", 0)
    other = WebFeed("127.0.0.1", port, time.monotonic)
    with pytest.raises(ConfigError, match=r"--web 127\.0\.0\.1:\d+: cannot serve"):
        other.start()


def test_chord_names_read_as_a_musician_writes_them() -> None:
    assert chord_name(Chord(0.0, 10, None, "7")) == "Bb7"
    assert chord_name(Chord(0.0, 0, 7, "m7")) == "Cm7/G"
    assert chord_name(Chord(0.0, 2, 2, "")) == "D"


def test_web_without_an_address_binds_loopback_port_8080() -> None:
    p = argparse.ArgumentParser()
    add_web_arguments(p)
    assert p.parse_args(["--web"]).web == "127.0.0.1:8080"
    assert p.parse_args([]).web is None


def test_each_impact_gets_a_frame_at_its_own_instant(feed: WebFeed) -> None:
    perf = Performance(
        router=Router(RoutingConfig()),
        planner=OnlinePlanner(load_plan_config(None)),
        animator=BandAnimator(),
    )
    feed.attach(perf)
    with connect(base(feed).replace("http", "ws") + "/ws", max_queue=None) as ws:
        while feed.server.viewers == 0:
            time.sleep(0.01)
        perf.feed(NoteOn(1.3083, 9, 38, 100), now_s=1.0)
        for k in range(31):
            now = 1.0 + k / 60
            perf.advance(now)
            feed.publish(perf, now)
            time.sleep(1 / 60)
        times = []
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and not any(abs(t - 1.3083) < 1e-9 for t in times):
            msg = ws.recv(timeout=10)
            if isinstance(msg, bytes):
                times.append(decode_frame(msg)[1])
    assert any(abs(t - 1.3083) < 1e-9 for t in times), times
