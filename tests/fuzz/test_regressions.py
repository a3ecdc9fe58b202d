"""Bugs the fuzzing (and the review around it) found, one regression test each.

Each test states the contract the code must meet.  A new bug gets its test here
marked ``xfail(strict=True, raises=<the escaping exception>)`` naming the file
and function at fault, and an entry in ``mutate.KNOWN_BUGS``; when the owner
fixes it the test passes, strict xfail turns that into a failure, and the marker
(and the entry) must be removed so the test guards the fix from then on.  Every
bug listed in docs/reliability.md is fixed: no test here is marked.
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from tests.fuzz.mutate import time_limit
from tests.fuzz.test_pcap_fuzz import idb_options_cut
from virja.errors import ConfigError, InputFileError

# -- virja/rmcp/pcap.py ----------------------------------------------------------------


@pytest.mark.parametrize("order", ["<", ">"])
def test_pcapng_tsoffset_option_cut_short_is_input_file_error(tmp_path: Path, order: str) -> None:
    """An IDB whose if_tsoffset option claims 8 bytes but the block ends first is refused."""
    from virja.rmcp.pcap import read_capture

    p = tmp_path / "cut.pcapng"
    p.write_bytes(idb_options_cut(order, 20))
    with pytest.raises(InputFileError):
        read_capture(p)


@pytest.mark.parametrize("order", ["<", ">"])
def test_pcapng_tsresol_option_without_value_is_input_file_error(
    tmp_path: Path, order: str
) -> None:
    """An IDB whose if_tsresol option has no value byte left in the block is refused."""
    from virja.rmcp.pcap import read_capture

    p = tmp_path / "cut.pcapng"
    p.write_bytes(idb_options_cut(order, 12))
    with pytest.raises(InputFileError):
        read_capture(p)


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (struct.pack("<HH", 9, 2) + b"\x06\x00\x00\x00", "if_tsresol has 2 bytes, not 1"),
        (struct.pack("<HH", 14, 4) + bytes(4), "if_tsoffset has 4 bytes, not 8"),
        (struct.pack("<HH", 14, 200) + bytes(8), "option 14 claims 200 bytes, 8 left"),
    ],
)
def test_pcapng_idb_option_of_wrong_length_names_it(
    tmp_path: Path, option: bytes, message: str
) -> None:
    """An IDB option whose length is wrong for it, or runs past the block, is refused
    with an InputFileError naming the file, the block's byte offset and the option."""
    from tests.fuzz.test_pcap_fuzz import FRAMES, block
    from virja.rmcp.pcap import read_capture

    shb = block("<", 0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    idb = block("<", 1, struct.pack("<HHI", 101, 0, 0) + option)
    f = FRAMES[0]
    epb = block("<", 6, struct.pack("<IIIII", 0, 0, 1000, len(f), len(f)) + f)
    p = tmp_path / "opt.pcapng"
    p.write_bytes(shb + idb + epb)
    with pytest.raises(InputFileError, match=r"opt\.pcapng: .*interface block at byte 28") as info:
        read_capture(p)
    assert message in str(info.value)


# -- virja/motion/bvh.py ------------------------------------------------------------------

BVH_ONE_JOINT = """HIERARCHY
ROOT Hips
{{
  OFFSET 0 0 0
  CHANNELS {count} Xrotation Yrotation Zrotation
}}
MOTION
Frames: {frames}
Frame Time: 0.04
0 0 0
"""


def test_bvh_superscript_channel_count_is_bvh_error() -> None:
    """A channel count written '²' (a Unicode digit int() refuses) gives BvhError naming the line."""
    from virja.motion.bvh import BvhError, parse_bvh

    with pytest.raises(BvhError):
        parse_bvh(BVH_ONE_JOINT.format(count="²", frames=1))


def test_bvh_superscript_frame_count_is_bvh_error() -> None:
    """A frame count written '²' gives BvhError naming the line."""
    from virja.motion.bvh import BvhError, parse_bvh

    with pytest.raises(BvhError):
        parse_bvh(BVH_ONE_JOINT.format(count=3, frames="²"))


def test_bvh_huge_frame_count_is_bvh_error() -> None:
    """'Frames: 10^17' with one frame line is a BvhError, not a 2 EiB allocation."""
    from virja.motion.bvh import BvhError, parse_bvh

    with pytest.raises(BvhError):
        parse_bvh(BVH_ONE_JOINT.format(count=3, frames=10**17))


def test_bvh_deeply_nested_joints_is_bvh_error_or_bvh() -> None:
    """5000 nested JOINTs (a hostile file) give a BvhError or a Bvh, not RecursionError."""
    from virja.motion.bvh import BvhError, parse_bvh

    n = 5000
    text = (
        "HIERARCHY\nROOT r\n"
        + "".join(f"{{\nOFFSET 0 0 0\nCHANNELS 0\nJOINT j{i}\n" for i in range(n))
        + "{\nOFFSET 0 0 0\nCHANNELS 0\n}\n"
        + "}\n" * n
        + "MOTION\nFrames: 0\nFrame Time: 0.04\n"
    )
    try:
        bvh = parse_bvh(text)
    except BvhError:
        return
    assert len(bvh.joints) == n + 1


# -- virja/midifile.py ------------------------------------------------------------------


def smf(track: bytes, tpb: int = 96) -> bytes:
    """A type 0 SMF of one raw track."""
    return (
        b"MThd"
        + struct.pack(">IHHH", 6, 0, 1, tpb)
        + b"MTrk"
        + struct.pack(">I", len(track))
        + track
    )


def test_midi_tempo_zero_is_input_file_error(tmp_path: Path) -> None:
    """A set_tempo of 0 µs per beat is refused with InputFileError naming the file."""
    from virja.midifile import read_midi

    p = tmp_path / "tempo0.mid"
    p.write_bytes(
        smf(b"\x00\xff\x51\x03\x00\x00\x00\x00\x90\x3c\x40\x60\x80\x3c\x00\x00\xff\x2f\x00")
    )
    with pytest.raises(InputFileError):
        read_midi(p)


def test_midi_huge_delta_time_does_not_hang(tmp_path: Path) -> None:
    """A 23-byte file whose one delta is 2^28-1 ticks at 1 tick per beat is read or refused
    within 15 s (before the fix: 268 million Beat objects, minutes and gigabytes; it takes
    about 1 s here, and the bound leaves room for a loaded machine, not for a hang)."""
    from virja.midifile import read_midi

    p = tmp_path / "long.mid"
    p.write_bytes(smf(b"\x00\x90\x3c\x40\xff\xff\xff\x7f\x80\x3c\x00\x00\xff\x2f\x00", tpb=1))
    try:
        with time_limit(15.0):
            read_midi(p)
    except InputFileError:
        pass


# -- virja/plan/config.py ---------------------------------------------------------------


def load_table(tmp_path: Path, key: str, text: str) -> object:
    from virja.plan.config import plan_config_from_table

    (tmp_path / "t.toml").write_text(text)
    return plan_config_from_table({key: "t.toml"}, tmp_path)


def test_drum_kit_priority_not_a_table_is_config_error(tmp_path: Path) -> None:
    """drum_kit.toml with ``priority = 0`` (not a table) is a ConfigError."""
    with pytest.raises(ConfigError):
        load_table(tmp_path, "drum_kit", 'priority = 0\n[notes]\n38 = { piece = "snare" }\n')


def test_drum_costs_rows_not_a_table_is_config_error(tmp_path: Path) -> None:
    """drum_costs.toml with the 14 motions but ``rows = 1`` is a ConfigError."""
    from virja.plan.config import HAND_PIECES, HANDS

    motions = ", ".join(f'"{p}_{h}"' for p in HAND_PIECES for h in HANDS)
    with pytest.raises(ConfigError):
        load_table(tmp_path, "drum_costs", f"motions = [{motions}]\nrows = 1\n")


def test_timing_motion_not_a_table_is_config_error(tmp_path: Path) -> None:
    """timing.toml with ``motion = 3`` is a ConfigError."""
    with pytest.raises(ConfigError):
        load_table(tmp_path, "timing", "reference_bpm = 120.0\nrest_s = 1.5\nmotion = 3\n")


def test_timing_reference_bpm_zero_is_config_error(tmp_path: Path) -> None:
    """The shipped timing.toml with ``reference_bpm = 0`` is a ConfigError."""
    from virja.resources import motions_dir

    text = (motions_dir() / "timing.toml").read_text()
    text = text.replace("reference_bpm = 120.0", "reference_bpm = 0.0")
    assert "reference_bpm = 0.0" in text
    with pytest.raises(ConfigError):
        load_table(tmp_path, "timing", text)


def test_plan_bass_frets_inf_is_config_error(tmp_path: Path) -> None:
    """A user config with ``[plan] bass_frets = inf`` is a ConfigError."""
    from virja.plan.config import load_plan_config

    p = tmp_path / "virja.toml"
    p.write_text("[plan]\nbass_frets = inf\n")
    with pytest.raises(ConfigError):
        load_plan_config(p)


# -- virja/motion/clip.py ---------------------------------------------------------------


def test_sidecar_not_utf8_is_clip_error(tmp_path: Path) -> None:
    """A sidecar that is not UTF-8 is a ClipError naming the file."""
    from virja.motion.clip import ClipError, read_sidecar

    p = tmp_path / "clip.toml"
    p.write_bytes(b'performer = "drums\xff"\n')
    with pytest.raises(ClipError, match=r"clip\.toml: clip sidecar is not UTF-8"):
        read_sidecar(p)


@pytest.mark.parametrize("value", ["inf", "nan", "-0.1"])
def test_sidecar_impact_must_be_finite_and_not_negative(tmp_path: Path, value: str) -> None:
    """impact_s of inf, nan or below 0 is a ClipError naming the key."""
    from virja.motion.clip import ClipError, read_sidecar

    p = tmp_path / "clip.toml"
    p.write_text(
        'performer = "drums"\nkind = "stroke"\nlimb = "left_hand"\n'
        f'impact_s = {value}\njoints = ["LeftHand"]\n'
    )
    with pytest.raises(ClipError, match="impact_s must be finite"):
        read_sidecar(p)


def test_bvh_repeated_rotation_channel_is_bvh_error() -> None:
    """Found by the BVH fuzzer: 'Yrotation Yrotation Zrotation' reached the Euler
    conversion and raised a plain ValueError there."""
    from virja.motion.bvh import BvhError, parse_bvh

    text = (
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Yrotation Yrotation Zrotation\n"
        "  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n"
    )
    with pytest.raises(BvhError, match="channel twice"):
        parse_bvh(text, "dup.bvh")
