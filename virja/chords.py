"""Chord symbols <-> :class:`virja.events.Chord` (pure).

RMCP's CHORD message carries a root and bass pitch class and a quality string
(``""``, ``m``, ``7``, ``m7``, ``maj7``, ``m7b5``, ...).  MIDI files carry chord
symbols as text: MMA (``Lyric Chords=On``) and many notation programs write
them as lyric or marker events ("Dm7", "Bb7", "C/E"); :func:`parse_chord_symbol`
reads those, and :func:`chord_name` writes a chord for the heads-up display.
"""

from __future__ import annotations

import re

from virja.events import Chord

NOTE_NAMES = ("C", "Db", "D", "Eb", "E", "F", "Gb", "G", "Ab", "A", "Bb", "B")
_LETTER = {"C": 0, "D": 2, "E": 4, "F": 5, "G": 7, "A": 9, "B": 11}
_SYMBOL = re.compile(
    r"^(?P<root>[A-G])(?P<acc>[#b]?)(?P<quality>[A-Za-z0-9+#()\-ø°Δ]*?)"
    r"(?:/(?P<bass>[A-G])(?P<bacc>[#b]?))?$"
)
# words a quality may be built from: a lyric like "Dance" must not read as D + "ance"
_QUALITY = re.compile(r"^(?:m|min|maj|M|dim|aug|sus|add|alt|ø|°|Δ|[0-9]|b|#|\+|-|\(|\))*$")


def _pitch_class(letter: str, accidental: str) -> int:
    return (_LETTER[letter] + {"#": 1, "b": -1, "": 0}[accidental]) % 12


def parse_chord_symbol(text: str, time_s: float = 0.0) -> Chord | None:
    """``"Bb7"`` -> Chord(root=10, quality="7"); None when the text is not a chord symbol
    (a lyric, MMA's "/" repeat mark, an empty string)."""
    m = _SYMBOL.match(text.strip())
    if m is None or not _QUALITY.match(m["quality"]):
        return None
    root = _pitch_class(m["root"], m["acc"])
    bass = _pitch_class(m["bass"], m["bacc"]) if m["bass"] else None
    return Chord(time_s, root, None if bass == root else bass, m["quality"])


def chord_name(chord: Chord) -> str:
    """Chord(root=10, quality="7") -> "Bb7"; a slash chord "C/E"."""
    name = NOTE_NAMES[chord.root % 12] + chord.quality
    if chord.bass is not None and chord.bass != chord.root:
        name += "/" + NOTE_NAMES[chord.bass % 12]
    return name
