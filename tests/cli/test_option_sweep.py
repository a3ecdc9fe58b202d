"""Every option of every subcommand, each given a bad value: never a traceback.

The options are read from the parsers themselves, so an option added later is
swept too.  Each command runs in-process from a small, valid invocation (a
four-note MIDI file, a four-datagram recording, a one-frame render) with one
option replaced by a bad value: a number that is not one, NaN, a negative, a
choice that does not exist, a path that does not exist or cannot be written.
What must hold: no exception escapes ``main`` (argparse's exit is fine), and
stderr holds no traceback.  Bounded: each case has a time limit.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
from collections.abc import Iterator
from pathlib import Path

import mido
import pytest

from virja.cli.common import finite_float
from virja.cli.main import COMMANDS, build_parser, main
from virja.rmcp import wire
from virja.rmcp.pcap import PcapWriter

# commands not swept: bench runs for a minute by design (its two flags are switches)
NOT_SWEPT = {"bench"}
CASE_LIMIT_S = 60
UNWRITABLE = "/proc/virja-no-such-dir/out"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    root = tmp_path_factory.mktemp("sweep")
    mid = mido.MidiFile(type=0)
    track = mido.MidiTrack()
    for i in range(4):
        track.append(
            mido.Message("note_on", channel=9, note=38, velocity=90, time=0 if i == 0 else 240)
        )
        track.append(mido.Message("note_on", channel=1, note=40 + i, velocity=80, time=0))
        track.append(mido.Message("note_off", channel=1, note=40 + i, velocity=0, time=120))
    mid.tracks.append(track)
    tiny = root / "tiny.mid"
    mid.save(tiny)
    corpus = root / "corpus"
    corpus.mkdir()
    (corpus / "tiny.mid").write_bytes(tiny.read_bytes())
    rec = root / "tiny.pcap"
    t0 = 1_700_000_000_000_000
    with PcapWriter.open(rec, local=("127.0.0.1", 50500)) as w:
        for i in range(4):
            sound = t0 + 500_000 + i * 125_000
            w.write(
                bytes(wire.midi(2, i, sound, bytes([0x99, 38, 100]))),
                ("127.0.0.1", 4000),
                time_us=sound - 500_000,
            )
    wav = root / "click.wav"
    import numpy as np
    import soundfile

    audio = np.zeros(8000 * 2, dtype=np.float32)
    audio[::4000] = 1.0
    soundfile.write(wav, audio, 8000)
    return {
        "mid": str(tiny),
        "pcap": str(rec),
        "corpus": str(corpus),
        "wav": str(wav),
        "root": str(root),
    }


def base_args(command: str, inputs: dict[str, str], out: Path) -> list[str]:
    """A valid, quick invocation of ``command`` (the options under test are added to it)."""
    return {
        "serve": ["--headless", "--duration", "0.3", "--listen", "127.0.0.1:0", "--quiet"],
        "send": [inputs["mid"], "--to", "127.0.0.1:9", "--start-in", "0"],
        "plan": [inputs["mid"]],
        "render": [inputs["mid"], "--out", str(out / "x.png"), "--at", "0.2", "--size", "32x18"],
        "replay": [inputs["pcap"], "--headless"],
        "jam": ["--headless", "--duration", "0.2"],
        "batch": [inputs["corpus"], "--out", str(out / "batch"), "--workers", "1"],
        "motion-report": [inputs["mid"], "--max-seconds", "0.5"],
        "beats": [inputs["wav"]],
        "teach": [str(out / "capture.bvh"), inputs["wav"], "--out", str(out / "db")],
        "dance": [inputs["wav"], "--db", str(out / "db"), "--out", str(out / "d.bvh")],
        "export": [inputs["mid"], "--musicxml", str(out / "x.musicxml")],
    }.get(command, [])


def bad_values(action: argparse.Action) -> list[str]:
    if action.choices:
        return ["no-such-choice"]
    if action.type is int:
        return ["x", "-1", "99999999999999999999"]
    if action.type is finite_float:
        return ["x", "nan", "-1"]
    meta = f"{action.metavar or ''} {action.dest}".upper()
    if any(
        w in meta for w in ("FILE", "PATH", "OUT", "DB", "DIR", ".", "AUDIO", "MUSIC", "CAPTURE")
    ):
        return ["/nonexistent/virja/x.y", UNWRITABLE + "/x.y", "/"]
    return ["", "x", ":::"]


def cases() -> Iterator[tuple[str, str, str]]:
    for command in COMMANDS:
        if command in NOT_SWEPT:
            continue
        parser = build_parser(command)
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        for action in sub.choices[command]._actions:
            if (
                not action.option_strings
                or action.nargs == 0
                or isinstance(action, argparse._HelpAction)
            ):
                continue
            for value in bad_values(action):
                yield command, action.option_strings[-1], value


class CaseTimeout(Exception):
    pass


@contextlib.contextmanager
def time_limit(seconds: int) -> Iterator[None]:
    def stop(signum: int, frame: object) -> None:
        raise CaseTimeout(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize(("command", "option", "value"), list(cases()))
def test_a_bad_value_is_never_a_traceback(
    command: str,
    option: str,
    value: str,
    inputs: dict[str, str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = [command, *base_args(command, inputs, tmp_path)]
    if option in argv:  # replace the base's own value of this option
        i = argv.index(option)
        del argv[i : i + 2]
    argv += [option, value]
    try:
        with time_limit(CASE_LIMIT_S):
            code = main(argv)
    except SystemExit as exc:  # argparse refused the value: its usage line and message
        code = exc.code if isinstance(exc.code, int) else 2
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert isinstance(code, int)
