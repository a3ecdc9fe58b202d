"""serve's summary reads true: datagrams rejected apart from notes dropped after acceptance."""

from __future__ import annotations

from virja.cli.cmd_serve import Daemon
from virja.clock import SessionClock
from virja.plan.planner import OnlinePlanner
from virja.rmcp import wire
from virja.rmcp.receiver import Receiver, ReceiverConfig
from virja.routing import Router
from virja.session import Performance


def test_late_notes_are_not_counted_as_rejected_datagrams() -> None:
    clock = SessionClock(wall_ns=lambda: 10**18, monotonic_ns=lambda: 0)
    now = clock.now_us()
    rx = Receiver(ReceiverConfig(lateness_s=0.06))
    perf = Performance(router=Router(), planner=OnlinePlanner())
    daemon = Daemon(perf=perf, receiver=rx, clock=clock)
    rx.receive_datagram(
        bytes(wire.midi(1, 1, now + 500_000, bytes([0x99, 38, 90]))), ("h", 1), now_us=now
    )
    rx.receive_datagram(
        bytes(wire.midi(1, 2, now - 200_000, bytes([0x99, 42, 90]))), ("h", 1), now_us=now
    )
    rx.receive_datagram(b"garbage", ("h", 1), now_us=now)
    daemon.on_events(rx.drain_events(), now / 1e6)
    perf.finish()
    lines = daemon.summary()
    assert lines[0].startswith("datagrams: 3 received, 2 accepted, 1 rejected: ")
    notes = next(line for line in lines if line.startswith("notes: "))
    assert "1 for the band (0 bass, 1 drums), 1 planned" in notes
    assert "0 dropped by the scheduler" in notes
    dropped = next(line for line in lines if line.startswith("dropped on arrival"))
    assert dropped.startswith("dropped on arrival, never planned: 1: too_late 1")
