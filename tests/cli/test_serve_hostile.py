"""`virja serve` under hostile traffic and a full disk: it obeys SIGTERM, summarises,
exits 0, and keeps planning another sender's notes (docs/reliability.md)."""

from __future__ import annotations

import json
import os
import signal
import socket
import time
from pathlib import Path

import pytest

from tests.cli.test_serve_signals import _start
from virja.clock import SessionClock
from virja.rmcp import wire


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_dense_flood_and_a_full_disk_plan_log_then_sigterm(tmp_path: Path) -> None:
    proc, port = _start(tmp_path, "--plan-log", "/dev/full", "--duration", "60")
    try:
        clock = SessionClock()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
            t0 = clock.now_us() + 1_000_000
            for i in range(4000):  # 10x D1: drum notes 1 ms apart inside the horizon
                tx.sendto(
                    bytes(wire.midi(9, i, t0 + i * 1000, bytes([0x99, 38, 100]))),
                    ("127.0.0.1", port),
                )
                if i % 500 == 0:
                    time.sleep(0.01)  # let the kernel buffer drain (bounded)
        time.sleep(0.3)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "virja serve: stopped" in out
    assert "plan log stopped early" in out
    assert "Traceback" not in err
    assert err.count("plan log stopped") == 1  # reported once


def test_recorder_write_error_stops_recording_not_receiving(tmp_path: Path) -> None:
    """In process: the recording's stream fails after its header; every datagram still
    reaches the receiver and the file holds whole records only."""
    import io

    from virja.rmcp.pcap import PcapWriter, read_capture
    from virja.rmcp.receiver import Receiver
    from virja.rmcp.transport import RmcpProtocol

    path = tmp_path / "rec.pcap"

    class FailingFile(io.FileIO):
        budget = 24 + 3 * 80  # the header and about three records, then ENOSPC

        def write(self, b: object) -> int:
            data = bytes(b)  # type: ignore[call-overload]
            room = self.budget - self.tell()
            if room < len(data):
                super().write(data[: max(room, 0)])  # a half record, as a full disk leaves
                raise OSError(28, "No space left on device")
            return super().write(data)

    stream = io.BufferedWriter(FailingFile(str(path), "w"), buffer_size=16)
    writer = PcapWriter(stream, local=("127.0.0.1", 50500), flush_interval_s=0.0)
    got: list[object] = []
    proto = RmcpProtocol(
        Receiver(), SessionClock(), lambda evs, now: got.extend(evs), recorder=writer
    )
    now = SessionClock().now_us()
    for i in range(50):
        data = bytes(wire.midi(2, i, now + 500_000, bytes([0x99, 38, 90])))
        proto.datagram_received(data, ("127.0.0.1", 40000))
    assert len(got) == 50
    assert writer.failed is not None
    cap = read_capture(path)
    assert 1 <= len(cap.datagrams) <= 3
    assert cap.warnings == []  # no half record at the end


def test_plan_log_write_error_is_reported_once_and_planning_goes_on() -> None:
    from virja.events import NoteOn
    from virja.plan import OnlinePlanner
    from virja.routing import Router
    from virja.session import Performance

    class Full:
        closed = False

        def write(self, s: str) -> int:
            raise OSError(28, "No space left on device")

        def flush(self) -> None:
            raise OSError(28, "No space left on device")

        def close(self) -> None:
            self.closed = True

    log = Full()
    perf = Performance(router=Router(), planner=OnlinePlanner(), plan_log=log)  # type: ignore[arg-type]
    for i in range(5):
        perf.feed(NoteOn(1.0 + i * 0.5, 9, 38, 90), now_s=0.0)
    planned = perf.finish()
    assert len(planned) == 5
    assert perf.plan_log is None and log.closed
    assert perf.plan_log_failed == "No space left on device"
    assert json.dumps(planned[0].to_json())


def test_a_failing_event_handler_does_not_close_the_socket() -> None:
    from virja.rmcp.receiver import Receiver
    from virja.rmcp.transport import RmcpProtocol

    calls: list[int] = []

    def boom(evs: object, now: float) -> None:
        calls.append(1)
        raise RuntimeError("a bug in a tick")

    proto = RmcpProtocol(Receiver(), SessionClock(), boom)
    now = SessionClock().now_us()
    for i in range(3):
        proto.datagram_received(
            bytes(wire.midi(2, i, now + 500_000, bytes([0x99, 38, 90]))), ("127.0.0.1", 4)
        )
    assert len(calls) == 3  # every datagram handled, nothing escaped to asyncio
