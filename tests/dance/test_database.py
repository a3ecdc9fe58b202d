"""Tests of virja.dance.database (teaching, saving, loading)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from virja.dance.database import (
    DanceDatabase,
    DanceError,
    load_database,
    merge,
    save_database,
    teach,
)
from virja.dance.synth_capture import Teacher
from virja.errors import InputFileError


def test_teaching_stores_one_segment_per_pair_of_boundaries(
    bounce: Teacher, bounce_db: DanceDatabase
) -> None:
    assert bounce_db.spans == np.diff(bounce.boundaries).tolist()  # exact: true beats, no smoothing


def test_segments_keep_both_cut_frames(bounce: Teacher, bounce_db: DanceDatabase) -> None:
    s = bounce_db.segments[2]
    assert s.rotations.shape == (s.span + 1, len(bounce.bvh.joints), 4)
    np.testing.assert_array_equal(
        s.rotations, bounce.bvh.rotations[s.start_frame : s.start_frame + s.span + 1]
    )
    np.testing.assert_array_equal(
        s.root_positions[:, 1],
        bounce.bvh.positions[s.start_frame : s.start_frame + s.span + 1, 0, 1],
    )


def test_sound_parameters_follow_the_phrase_colour(
    bounce: Teacher, bounce_db: DanceDatabase, bounce_colours: list[int]
) -> None:
    """Segments whose music starts with the low rumble (colour 0) have a_1 > 1.5; others < 1."""
    beat_frames = [round(b * 30) for b in bounce.beats_s]
    colour = [bounce_colours[beat_frames.index(s.start_frame)] for s in bounce_db.segments]
    a1 = [s.sound[0] for s in bounce_db.segments]
    pure_rumble = [
        a for a, s, c in zip(a1, bounce_db.segments, colour, strict=True) if c == 0 and s.span < 24
    ]  # no off-beat inside: one colour only
    pure_other = [
        a for a, s, c in zip(a1, bounce_db.segments, colour, strict=True) if c != 0 and s.span < 24
    ]
    assert pure_rumble and pure_other
    assert min(pure_rumble) > 1.5 > 1.0 > max(pure_other)


def test_save_and_load_round_trip(tmp_path: Path, bounce_db: DanceDatabase) -> None:
    save_database(bounce_db, tmp_path / "db")
    back = load_database(tmp_path / "db")
    assert back.spans == bounce_db.spans and back.fps == bounce_db.fps and back.parts == "legs"
    assert [j.name for j in back.joints] == [j.name for j in bounce_db.joints]
    assert back.joints == bounce_db.joints
    for a, b in zip(back.segments, bounce_db.segments, strict=True):
        np.testing.assert_array_equal(a.rotations, b.rotations)
        np.testing.assert_array_equal(a.root_positions, b.root_positions)
        np.testing.assert_allclose(a.sound, b.sound)
        assert (a.source, a.start_frame) == (b.source, b.start_frame)


def test_manifest_is_versioned(tmp_path: Path, bounce_db: DanceDatabase) -> None:
    save_database(bounce_db, tmp_path / "db")
    m = json.loads((tmp_path / "db" / "manifest.json").read_text())
    assert m["format"] == "virja-dance-db" and m["version"] == 1


def test_newer_version_is_refused(tmp_path: Path, bounce_db: DanceDatabase) -> None:
    save_database(bounce_db, tmp_path / "db")
    mp = tmp_path / "db" / "manifest.json"
    m = json.loads(mp.read_text())
    m["version"] = 99
    mp.write_text(json.dumps(m))
    with pytest.raises(InputFileError, match="version 99"):
        load_database(tmp_path / "db")


def test_missing_folder_is_an_input_file_error(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="no manifest.json"):
        load_database(tmp_path / "none")


def test_truncated_npz_is_an_input_file_error(tmp_path: Path, bounce_db: DanceDatabase) -> None:
    save_database(bounce_db, tmp_path / "db")
    (tmp_path / "db" / "segments.npz").write_bytes(b"PK\x03\x04garbage")
    with pytest.raises(InputFileError, match="corrupt"):
        load_database(tmp_path / "db")


def test_merge_concatenates_segments(bounce_db: DanceDatabase) -> None:
    assert merge([bounce_db, bounce_db]).spans == bounce_db.spans * 2


def test_merge_refuses_different_parts(bounce_db: DanceDatabase) -> None:
    other = DanceDatabase(bounce_db.joints, bounce_db.fps, "arms", bounce_db.segments)
    with pytest.raises(DanceError):
        merge([bounce_db, other])


def test_capture_without_leg_joints_is_refused(bounce: Teacher, bounce_music: np.ndarray) -> None:
    from dataclasses import replace

    from virja.motion.bvh import Bvh

    joints = [replace(j, name=f"J{i}") for i, j in enumerate(bounce.bvh.joints)]
    bvh = Bvh(joints, bounce.bvh.frame_time_s, bounce.bvh.rotations, bounce.bvh.positions)
    with pytest.raises(DanceError, match="no joint"):
        teach(bvh, bounce_music, "legs", beats_s=bounce.beats_s)


def test_segments_shorter_than_the_minimum_span_are_merged(
    bounce: Teacher, bounce_music: np.ndarray
) -> None:
    db = teach(bounce.bvh, bounce_music, "legs", beats_s=bounce.beats_s, q_over_r=None, min_span=20)
    assert min(db.spans) >= 20
    assert sum(db.spans) <= bounce.bvh.n_frames


def test_a_silent_phrase_is_left_out_and_said(bounce: Teacher, bounce_music: np.ndarray) -> None:
    b = bounce.beats_s
    full = teach(bounce.bvh, bounce_music, "legs", beats_s=b, q_over_r=None)
    seg = full.segments[2]
    x = bounce_music.copy()
    t0, t1 = seg.start_frame / 30, (seg.start_frame + seg.span) / 30
    x[int(t0 * 8000) - 8 : int(t1 * 8000) + 8] = 0.0  # that phrase is silent
    db = teach(bounce.bvh, x, "legs", beats_s=b, q_over_r=None)
    assert len(db.notes) == 1 and "not fitted" in db.notes[0]
    assert len(db.segments) == len(full.segments) - 1
