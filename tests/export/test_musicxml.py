"""MusicXML export, read by music21: pitches, strings and frets, sticking, tempo and metre."""

from __future__ import annotations

from pathlib import Path

import music21
import pytest

from tests.export.conftest import GMD_TAKES, gmd_take
from virja.export import Export, export_performance
from virja.export.musicxml import NOTATION, notation
from virja.vocab import PIECES


@pytest.fixture(scope="module")
def demo_score(demo_export: Export) -> music21.stream.Score:
    path = next(p for p in demo_export.outputs if p.suffix == ".musicxml")
    assert b'version="4.0"' in path.read_bytes()[:400]
    return music21.converter.parse(path)


def test_bass_part_is_written_an_octave_above_sounding_with_string_and_fret(
    demo_export: Export, demo_score: music21.stream.Score
) -> None:
    bass = [p for p in demo_export.planned if p.performer == "bass"]
    bass.sort(key=lambda p: p.time)
    staff, tab = demo_score.parts[0], demo_score.parts[1]
    written = list(staff.flatten().notes)
    assert len(written) == len(bass) == len(tab.flatten().notes)
    sounding = list(demo_score.toSoundingPitch().parts[0].flatten().notes)
    names = ["E", "A", "D", "G"]
    for w, s, p in zip(written, sounding, bass, strict=True):
        assert w.pitch.midi == p.note + 12
        assert s.pitch.midi == p.note
        marks = {type(a).__name__: a.number for a in w.articulations}
        assert marks["FretIndication"] == p.fret
        assert marks["StringIndication"] == 4 - names.index(p.string or "")  # 1 = G, the highest
    clefs = [c.sign for c in tab.flatten().getElementsByClass("Clef")]
    assert clefs and clefs[0] == "TAB"


def test_drum_part_has_kit_noteheads_and_the_schedulers_sticking(
    demo_export: Export, demo_score: music21.stream.Score
) -> None:
    drums = demo_score.parts[2]
    hands = [p for p in demo_export.planned if p.performer == "drums" and p.limb.endswith("hand")]
    sticking = "".join(ly.text for n in drums.flatten().notes for ly in (n.lyrics or []) if ly.text)
    assert set(sticking) <= {"R", "L"}
    # every hand stroke of the demo has its letter, as the scheduler chose the hand
    assert len(sticking) == len(hands)
    assert sticking.count("R") == sum(p.limb == "right_hand" for p in hands)
    heads = {
        getattr(u, "notehead", "normal")
        for n in drums.flatten().notes
        for u in (n.notes if hasattr(n, "notes") else [n])
    }
    assert "x" in heads and "normal" in heads  # cymbals crossed, drums round
    assert {k for k in NOTATION if k[0] == "ride"}


def test_every_kit_piece_has_its_own_staff_place() -> None:
    """Each piece is written where drum charts put it, crash 2 apart from crash 1."""
    assert all((p, None) in NOTATION for p in PIECES)
    places = {p: notation(p, None)[:2] for p in PIECES if p != "hihat"}
    assert len(set(places.values())) == len(places), places
    assert notation("crash2", None) == ("B", 5, "x")


def test_tempo_and_time_signature_come_from_the_file(demo_score: music21.stream.Score) -> None:
    marks = demo_score.metronomeMarkBoundaries()
    assert round(marks[0][2].number) == 132
    ts = demo_score.parts[0].flatten().getElementsByClass("TimeSignature")[0]
    assert ts.ratioString == "4/4"


def test_gmd_six_eight_take_keeps_its_metre(tmp_path: Path) -> None:
    take = gmd_take(GMD_TAKES[0])
    out = tmp_path / "take.musicxml"
    export_performance(take, musicxml=out)
    score = music21.converter.parse(out)
    ts = score.parts[-1].flatten().getElementsByClass("TimeSignature")[0]
    assert ts.ratioString == "6/8"
    bars = score.parts[-1].getElementsByClass("Measure")
    assert all(b.duration.quarterLength == pytest.approx(3.0) for b in bars)
    assert round(score.metronomeMarkBoundaries()[0][2].number) == 70
