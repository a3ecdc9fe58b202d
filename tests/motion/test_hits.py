"""The kit and string state from impacts (virja.motion.hits) equals the plain loops
over the hits of the last seconds it replaced, on the demo's impacts and at ties."""

from __future__ import annotations

import math

import numpy as np

from tests.conftest import DEMO_MID
from tests.motion.test_band_batch import _animate
from virja.motion.band import AnimationSettings
from virja.motion.hits import Hit, HitTable
from virja.vocab import BASS_STRINGS, DRUM_PIECES


def plain_state(
    hits: list[Hit], t: float, s: AnimationSettings
) -> tuple[dict[str, float], dict[str, float], dict[str, float]]:
    """(swings, head hits, strings) as the animator computed them before."""

    def recent(window: float) -> list[Hit]:
        return [h for h in hits if t - window <= h.time <= t]

    swings = {}
    for piece, amp, tau, freq in s.swing:
        a = 0.0
        for h in recent(8.0):
            if h.what == piece:
                dt = t - h.time
                a += (
                    amp * h.velocity / 127 * math.exp(-dt / tau) * math.sin(2 * math.pi * freq * dt)
                )
        swings[piece] = a
    heads = dict.fromkeys(DRUM_PIECES, 0.0)
    for h in recent(8 * s.head_decay_s):
        if h.what in heads:
            heads[h.what] = max(
                heads[h.what], h.velocity / 127 * math.exp(-(t - h.time) / s.head_decay_s)
            )
    strings = dict.fromkeys(BASS_STRINGS, 0.0)
    latest: dict[str, Hit] = {}
    for h in recent(8 * s.string_decay_s):
        if h.what in strings:
            latest[h.what] = h
    for name, h in latest.items():
        strings[name] = (
            s.string_amp_m * h.velocity / 127 * math.exp(-(t - h.time) / s.string_decay_s)
        )
    return swings, heads, strings


def _state(table: HitTable, t: float, s: AnimationSettings) -> tuple[dict[str, float], ...]:
    return (
        table.swings(t, s.swing),
        table.head_hits(t, DRUM_PIECES, s.head_decay_s),
        table.strings(t, BASS_STRINGS, s.string_amp_m, s.string_decay_s),
    )


def _close(a: dict[str, float], b: dict[str, float]) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert abs(a[k] - b[k]) < 1e-12, (k, a[k], b[k])


def test_state_equals_the_plain_loops_on_the_demo() -> None:
    animator, (t0, t1) = _animate(DEMO_MID)
    table = animator._hits
    hits = list(table._hits)
    s = animator.settings
    assert {"ride", "crash", "hihat", "snare", "kick"} <= {h.what for h in hits}
    moving = 0
    for t in np.arange(t0, t1, 1 / 30).tolist():
        got, want = _state(table, t, s), plain_state(hits, t, s)
        for g, w in zip(got, want, strict=True):
            _close(g, w)
        moving += any(abs(v) > 1e-4 for v in got[0].values())
    assert moving > 100  # cymbals really swing in many frames


def test_ties_latest_added_wins_and_forgetting() -> None:
    s = AnimationSettings()
    table = HitTable()
    hits = [Hit(1.0, "E", 50), Hit(1.0, "E", 120), Hit(1.0, "ride", 90), Hit(3.0, "snare", 100)]
    for h in hits:
        table.add(h)
    for t in (0.5, 1.0, 1.3, 3.0, 12.0):
        for g, w in zip(_state(table, t, s), plain_state(hits, t, s), strict=True):
            _close(g, w)
    assert table.strings(1.0, ["E"], 1.0, 1.0)["E"] == 120 / 127
    table.forget_before(2.0)
    assert len(table) == 1
    assert table.strings(3.0, ["E"], 1.0, 1.0)["E"] == 0.0
    assert table.head_hits(3.0, ["snare"], 0.15)["snare"] == 100 / 127
