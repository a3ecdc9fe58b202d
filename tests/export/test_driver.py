"""export_performance: what the input says (tempo changes, metre, tuning, kit map) reaches the files."""

from __future__ import annotations

from pathlib import Path

import mido
import music21
import pytest

from tests.conftest import save_midi
from virja.errors import VirjaError
from virja.export import export_file, export_performance


def _song(path: Path) -> Path:
    """Two bars of 4/4 at 100 bpm, then 3/4 at 150 bpm: bass low B then E, kick and snare."""
    tpb = 480
    meta: list[mido.Message | mido.MetaMessage] = [
        mido.MetaMessage("set_tempo", tempo=600_000, time=0),
        mido.MetaMessage("time_signature", numerator=4, denominator=4, time=0),
        mido.MetaMessage("set_tempo", tempo=400_000, time=8 * tpb),
        mido.MetaMessage("time_signature", numerator=3, denominator=4, time=0),
    ]
    bass: list[mido.Message | mido.MetaMessage] = [
        mido.MetaMessage("track_name", name="Bass", time=0),
        mido.Message("program_change", program=32, channel=1, time=0),
    ]
    for i in range(14):
        note = 23 if i % 2 == 0 else 28  # B0 (five-string) and E1
        bass.append(
            mido.Message(
                "note_on", note=note, velocity=90, channel=1, time=0 if i == 0 else tpb // 2
            )
        )
        bass.append(mido.Message("note_off", note=note, velocity=0, channel=1, time=tpb // 2))
    drums: list[mido.Message | mido.MetaMessage] = []
    for i in range(14):
        drums.append(
            mido.Message(
                "note_on",
                note=36 if i % 2 == 0 else 38,
                velocity=100,
                channel=9,
                time=0 if i == 0 else tpb,
            )
        )
        drums.append(
            mido.Message("note_off", note=36 if i % 2 == 0 else 38, velocity=0, channel=9, time=0)
        )
    return save_midi(path, [meta, bass, drums], tpb)


def test_tempo_and_metre_changes_reach_the_score(tmp_path: Path) -> None:
    out = tmp_path / "s.musicxml"
    export_performance(_song(tmp_path / "s.mid"), musicxml=out)
    score = music21.converter.parse(out)
    tempos = {start: round(mark.number) for start, _, mark in score.metronomeMarkBoundaries()}
    assert tempos == {0.0: 100, 8.0: 150}  # quarter-note offsets: 150 bpm from bar 3
    metres = [t.ratioString for t in score.parts[-1].flatten().getElementsByClass("TimeSignature")]
    assert metres == ["4/4", "3/4"]
    bars = score.parts[-1].getElementsByClass("Measure")
    assert [b.duration.quarterLength for b in bars[:4]] == [4.0, 4.0, 3.0, 3.0]


def test_five_string_tuning_gets_five_tab_lines(tmp_path: Path) -> None:
    cfg = tmp_path / "five.toml"
    cfg.write_text('[plan]\nbass_tuning = "five"\n')
    out = tmp_path / "s.musicxml"
    export_file(_song(tmp_path / "s.mid"), musicxml=out, config=cfg)
    text = out.read_text()
    assert "<staff-lines>5</staff-lines>" in text
    score = music21.converter.parse(out)
    low_b = [n for n in score.toSoundingPitch().parts[0].flatten().notes if n.pitch.midi == 23]
    assert len(low_b) == 7
    assert all(
        {type(a).__name__: a.number for a in n.articulations}
        == {"StringIndication": 5, "FretIndication": 0}
        for n in low_b
    )


def test_motion_the_figures_cannot_play_is_a_one_line_error(tmp_path: Path) -> None:
    cfg = tmp_path / "five.toml"
    cfg.write_text('[plan]\nbass_tuning = "five"\n')
    try:
        export_file(_song(tmp_path / "s.mid"), gltf=tmp_path / "s.glb", config=cfg)
    except VirjaError as exc:  # until the bassist's clips cover a low B string
        assert "\n" not in str(exc) and "string" in str(exc)
        assert not (tmp_path / "s.glb").exists()
    else:  # the bassist plays five strings: the low B is animated
        assert (tmp_path / "s.glb").stat().st_size > 0


def test_kit_map_names_every_drum_instrument(tmp_path: Path) -> None:
    out = tmp_path / "s.musicxml"
    export_performance(_song(tmp_path / "s.mid"), musicxml=out)
    text = out.read_text()
    assert "<instrument-name>Bass Drum 1</instrument-name>" in text
    assert "<instrument-name>Acoustic Snare</instrument-name>" in text
    assert "<midi-unpitched>37</midi-unpitched>" in text  # GM 36, 1-based


def test_library_function_returns_the_files_written(tmp_path: Path) -> None:
    paths = export_file(_song(tmp_path / "s.mid"), gltf=tmp_path / "a.gltf", end_s=2.0)
    assert paths == [tmp_path / "a.gltf", tmp_path / "a.bin"]
    with pytest.raises(VirjaError, match="nothing to export"):
        export_file(tmp_path / "s.mid")
