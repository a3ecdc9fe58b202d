"""`virja jam --rtp-midi`: network keys are played as the keyboard's (split, channel 10)."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import pytest

from tests.jam.conftest import wait_until
from tests.rtpmidi.peer import Peer
from virja.cli.main import main


@pytest.mark.jack
def test_rtp_midi_keys_are_planned_like_keyboard_keys(
    jack_server: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "jam.jsonl"
    argv = ["jam", "--api", "jack", "--headless", "--duration", "3", "--plan-log", str(log)]
    argv += ["--rtp-midi", "0"]
    result: list[int] = []
    thread = threading.Thread(target=lambda: result.append(main(argv)))
    thread.start()
    port = 0
    try:

        def bound() -> bool:
            nonlocal port
            out = capsys.readouterr().out
            if "RTP-MIDI session 'virja' on 127.0.0.1:" in out:
                port = int(out.split("127.0.0.1:")[1].split()[0])
            return port != 0

        assert wait_until(bound)
        peer = Peer("127.0.0.1", port)
        try:
            peer.join()
            before = time.time()
            peer.send((0, [0x90, 40, 100]), (0, [0x99, 38, 100]), (0, [0x90, 72, 100]))
        finally:
            peer.close()
    finally:
        thread.join(timeout=15)
    assert result == [0]
    planned = [json.loads(line) for line in log.read_text().splitlines()]
    # E2 below the split: bass; the snare on channel 10; C5 is the pianist's own
    assert sorted((p["performer"], p["note"]) for p in planned) == [("bass", 40), ("drums", 38)]
    for p in planned:
        assert before - 0.5 <= p["session_time"] <= before + 2.0
        assert 0.0 <= p["time"] <= 3.0 + 1.0  # from the jam's start
