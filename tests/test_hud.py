"""The heads-up display's text: chord symbols, the time line of beats and chords."""

from __future__ import annotations

from pathlib import Path

import pytest

from virja.chords import chord_name, parse_chord_symbol
from virja.events import Beat, Chord
from virja.hud import KEEP_S, HudInfo, HudTimeline
from virja.midifile import read_midi

DEMO = Path(__file__).resolve().parents[1] / "virja" / "demo"


@pytest.mark.parametrize(
    ("text", "root", "bass", "quality"),
    [("Dm7", 2, None, "m7"), ("Bb7", 10, None, "7"), ("C/E", 0, 4, ""), ("F#m7b5", 6, None, "m7b5"),
     ("Ebmaj7 ", 3, None, "maj7"), ("G", 7, None, ""), ("C7(b9)", 0, None, "7(b9)")],
)  # fmt: skip
def test_chord_symbols_are_read(text: str, root: int, bass: int | None, quality: str) -> None:
    chord = parse_chord_symbol(text, 1.5)
    assert chord == Chord(1.5, root, bass, quality)


@pytest.mark.parametrize("text", ["", "/", "Dance", "la", "H7", "\r", "Created by MMA"])
def test_lyrics_that_are_not_chords_are_not(text: str) -> None:
    assert parse_chord_symbol(text) is None


def test_chord_names_round_trip() -> None:
    for text in ("Dm7", "Bb7", "C/E", "Ebmaj7", "Gbm7b5"):
        chord = parse_chord_symbol(text)
        assert chord is not None and chord_name(chord) == text


def test_mma_demos_carry_their_chords() -> None:
    session = read_midi(DEMO / "bossa.mid")
    names = [chord_name(c) for c in session.chords]
    assert names[:4] == ["Dm7", "G7", "Cmaj7", "Cmaj7"]
    assert len(session.chords) == 18  # one per bar, Em7 A7 and Dm7 G7 split
    assert read_midi(DEMO / "blues.mid").chords == []


def beat(t: float, bar: int, n: int, tempo_us: int = 500_000) -> Beat:
    return Beat(t, bar, n, 4, 0, tempo_us)


def test_the_timeline_answers_for_the_moment_asked() -> None:
    hud = HudTimeline()
    # known ahead, in any order
    hud.add(beat(1.0, 0, 3))
    hud.add(beat(0.5, 0, 2))
    hud.add(Chord(0.0, 5, None, "7"))
    hud.add(Chord(1.0, 10, None, "7"))
    assert hud.at(-0.1) == HudInfo(None, None, None, None)
    assert hud.at(0.7) == HudInfo(120.0, 1, 2, "F7")
    assert hud.at(1.2).text() == "120 bpm   bar 1.3   Bb7"
    assert HudInfo(None, None, None, "F7").text() == "F7"


def test_the_timeline_stays_bounded() -> None:
    hud = HudTimeline()
    for i in range(10_000):
        hud.add(beat(i * 0.5, i // 4, i % 4 + 1))
        if i % 100 == 0:
            hud.at(i * 0.5)
    assert len(hud) <= KEEP_S / 0.5 + 110
    assert hud.at(4999.9).bar == 2500
