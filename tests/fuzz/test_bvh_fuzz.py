"""Fuzzing the BVH loader: mutated BVH text gives BvhError (an InputFileError) or a Bvh.

Mutations work on whitespace tokens (a vocabulary of BVH keywords, braces,
channel names and odd numbers) and lines, so most inputs get past the first
keyword; a second test flips raw bytes of the file (invalid UTF-8 included).
Each parse runs under a 2 s alarm (a hang fails).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings

from tests.fuzz.mutate import (
    apply_byte_edits,
    apply_token_edits,
    byte_edits,
    raise_unless_known_bug,
    time_limit,
    token_edits,
)
from virja.errors import InputFileError
from virja.motion.bvh import Bvh, BvhError, parse_bvh, read_bvh

SEED = """HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0.0 0.1 0.0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0.0 0.2 0.0
    }
  }
  JOINT Leg
  {
    OFFSET 0.1 -0.1 0.0
    CHANNELS 3 Xrotation Yrotation Zrotation
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0.0 0.9 0.0 0.0 0.0 0.0 10.0 0.0 0.0 5.0 0.0 0.0
0.1 0.9 0.0 1.0 0.0 0.0 12.0 0.0 0.0 6.0 0.0 0.0
0.2 0.9 0.0 2.0 0.0 0.0 14.0 0.0 0.0 7.0 0.0 0.0
"""

# "²" (a digit to str.isdigit(), not to int()), "٣" (a digit to float()) and a frame count
# too large to allocate were bugs (test_regressions.py); they are in the vocabulary now.
VOCABULARY = (
    "{", "}", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "HIERARCHY", "MOTION",
    "Frames:", "Frame", "Time:", "0", "1", "2", "3", "6", "7", "-1", "0.0", "1e308", "-1e308",
    "nan", "inf", "٣", "x", "Hips", "Spine", "Xrotation", "Yrotation", "Zrotation", "Xposition",
    "Yposition", "Zposition", "Wrotation", "²", "100000000000000000", "1_0", "1e999",
)  # fmt: skip


def parse_or_bvh_error(text: str) -> Bvh | BvhError | None:
    """A Bvh or its BvhError; None for the open bugs of KNOWN_BUGS; anything else raises."""
    try:
        with time_limit(2.0):
            return parse_bvh(text, "fuzz.bvh")
    except BvhError as exc:
        return exc
    except Exception as exc:
        raise_unless_known_bug(exc)
        return None


def test_seed_is_valid() -> None:
    """The unmutated text parses to 3 frames of 3 joints (else the fuzzing tests nothing)."""
    bvh = parse_bvh(SEED)
    assert bvh.names == ["Hips", "Spine", "Leg"] and bvh.n_frames == 3


@settings(max_examples=200, deadline=2000)
@given(edits=token_edits(VOCABULARY))
def test_mutated_bvh_text_gives_bvh_error_or_bvh(edits: list[tuple[int, int, int]]) -> None:
    """Token- and line-mutated BVH text never raises anything but BvhError; a result is whole."""
    result = parse_or_bvh_error(apply_token_edits(SEED, edits, VOCABULARY))
    if result is None:
        return
    if isinstance(result, BvhError):
        assert result.line >= 1 and "fuzz.bvh" in str(result)
        return
    n = len(result.joints)
    assert result.rotations.shape == (result.n_frames, n, 4)
    assert result.positions.shape == (result.n_frames, n, 3)
    assert all(-1 <= j.parent < i for i, j in enumerate(result.joints))
    finite = np.isfinite(result.rotations).all(axis=(1, 2))
    norms = np.linalg.norm(result.rotations[finite], axis=-1)
    assert np.allclose(norms, 1.0)  # where the angles were finite, unit quaternions


@settings(
    max_examples=100, deadline=2000, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(edits=byte_edits())
def test_byte_mutated_bvh_file_gives_input_file_error_or_bvh(
    tmp_path: Path, edits: list[tuple[int, int, int]]
) -> None:
    """Raw byte edits (invalid UTF-8 too) of a BVH file: InputFileError or a Bvh."""
    p = tmp_path / "fuzz.bvh"
    p.write_bytes(apply_byte_edits(SEED.encode(), edits))
    try:
        with time_limit(2.0):
            read_bvh(p)
    except InputFileError:
        pass
    except Exception as exc:
        raise_unless_known_bug(exc)
