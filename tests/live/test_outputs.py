"""The live outputs opened in one place: which sinks the performance gets, the web feed
on loopback, and what is closed again."""

from __future__ import annotations

import urllib.request

import pytest

from virja.errors import ConfigError
from virja.events import NoteOn
from virja.live.outputs import LiveOutputs, LiveSettings, WebSettings
from virja.motion.band import BandAnimator
from virja.pipeline import PerformanceSettings, build_performance

NOW = 1000.0


def test_headless_without_web_gives_no_animator() -> None:
    perf = build_performance(PerformanceSettings())
    outputs = LiveOutputs.open(perf, LiveSettings(), lambda: NOW)
    assert perf.animator is None and outputs.viewer is None and outputs.web is None
    outputs.close()


def test_web_poses_with_an_animator_of_its_own_and_serves_the_page() -> None:
    perf = build_performance(PerformanceSettings())
    outputs = LiveOutputs.open(perf, LiveSettings(web=WebSettings(port=0, fps=20)), lambda: NOW)
    try:
        assert outputs.web is not None and outputs.web.url.startswith("http://127.0.0.1:")
        assert perf.animator is outputs.sinks
        assert [type(s) for s in outputs.sinks.sinks] == [BandAnimator]
        perf.feed(NoteOn(NOW + 1.0, 9, 38, 100), now_s=NOW)
        assert perf.finish() and perf.pose(NOW + 1.0) is not None  # posed here, for browsers
        with urllib.request.urlopen(outputs.web.url, timeout=10) as r:
            assert r.status == 200
        assert outputs.web.fps == 20
    finally:
        web = outputs.web
        outputs.close()
    assert outputs.web is None and web is not None
    with pytest.raises(OSError):
        urllib.request.urlopen(web.url, timeout=2)


def test_an_animator_already_there_is_the_web_one() -> None:
    """A jam builds its performance with an animator (for its kit map and tuning)."""
    perf = build_performance(PerformanceSettings(), animate=True)
    mine = perf.animator
    outputs = LiveOutputs.open(perf, LiveSettings(web=WebSettings(port=0)), lambda: NOW)
    try:
        assert outputs.sinks.sinks == [mine]
    finally:
        outputs.close()


def test_a_bad_web_rate_is_one_line_and_nothing_stays_open() -> None:
    perf = build_performance(PerformanceSettings())
    with pytest.raises(ConfigError, match="--web-fps: web frame rate must be 1-120 fps"):
        LiveOutputs.open(perf, LiveSettings(web=WebSettings(port=0, fps=500)), lambda: NOW)
    assert not perf.taps


def test_the_web_options_parse_once() -> None:
    from virja.cli.main import build_parser
    from virja.cli.web_option import web_settings

    args = build_parser().parse_args(["replay", "x.pcap", "--web", "127.0.0.1:0"])
    assert web_settings(args) == WebSettings("127.0.0.1", 0, 30.0, 0.1)
    args = build_parser().parse_args(["replay", "x.pcap", "--web-lead-ms", "9000", "--web"])
    with pytest.raises(ConfigError, match="--web-lead-ms must be 0-2000"):
        web_settings(args)
    assert web_settings(build_parser().parse_args(["replay", "x.pcap"])) is None
