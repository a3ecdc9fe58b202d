"""Valid but hostile input (docs/reliability.md, "Hostile traffic, clocks and disks").

Drawn by hypothesis: dense notes, floods marked act now and many senders' state
through the receiver and the planner; clock replies with any i64 times; a disk
that fills at any byte of a recording; recordings spanning years.  The contracts:
nothing raises, the work and the state stay under their bounds (counted, never
timed), the clock never leaves the panic threshold, a recording stays readable.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz.mutate import time_limit
from virja.clock import SessionClock
from virja.plan import drums
from virja.plan.planner import OnlinePlanner
from virja.rmcp import wire
from virja.rmcp.bodies import ClockReplyBody, ClockRequestBody
from virja.rmcp.pcap import PcapWriter, read_capture
from virja.rmcp.receiver import Receiver
from virja.routing import Router
from virja.session import Performance

NOW = 1_700_000_000_000_000
I64 = st.integers(-(1 << 63), (1 << 63) - 1)


traffic = st.lists(
    st.tuples(
        st.sampled_from(["dense", "act_now", "program", "bass"]),
        st.integers(0, 65535),  # sender id
        st.integers(0, 3),  # source port index
        st.integers(0, 2_000),  # arrival step (us x 100)
        st.integers(1, 400),  # notes in the datagram
    ),
    min_size=1,
    max_size=60,
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(batch=traffic)
def test_hostile_traffic_is_bounded_and_never_raises(
    batch: list[tuple[str, int, int, int, int]],
) -> None:
    solves: list[int] = []
    real = drums.solve

    def spy(*a: object, **kw: object) -> drums.HandSolution:
        solves.append(len(a[3]))  # type: ignore[arg-type]
        return real(*a, **kw)  # type: ignore[arg-type]

    receiver = Receiver()
    planner = OnlinePlanner()
    perf = Performance(router=Router(), planner=planner)
    now = NOW
    drums.solve = spy  # type: ignore[assignment]
    try:
        with time_limit(20):
            for seq, (kind, sender, port, step, n) in enumerate(batch):
                now += step * 100
                if kind == "dense":  # notes 1 ms apart inside the horizon
                    msgs = [bytes([0x99, 38 + i % 3, 100]) for i in range(min(n, 390))]
                    data = wire.midi(sender, seq, now + 1_000_000, *msgs)
                elif kind == "act_now":
                    msgs = [bytes([0x99, 36 + i % 10, 100]) for i in range(min(n, 390))]
                    data = wire.midi(sender, seq, now, *msgs, flags=wire.Flags.IMMEDIATE)
                elif kind == "program":
                    data = wire.midi(sender, seq, now, *(bytes([0xC0 | c, 33]) for c in range(16)))
                else:
                    data = wire.midi(sender, seq, now + 500_000, bytes([0x90, 28 + n % 40, 90]))
                receiver.receive_datagram(bytes(data), ("127.0.0.1", 40000 + port), now_us=now)
                for rec in receiver.drain_events():
                    perf.feed(rec.event, now_s=rec.arrival_s)
                perf.advance(now / 1e6)
            perf.finish()
    finally:
        drums.solve = real  # type: ignore[assignment]
    assert receiver.stats.dropped["internal_error"] == 0
    assert all(s <= planner.bounds.window_groups for s in solves)
    assert planner.pending_count == 0
    assert receiver.tracked_senders <= receiver.config.max_senders
    assert len(perf.router._programs) <= perf.router.max_programs


@settings(max_examples=200, deadline=None)
@given(times=st.lists(st.tuples(I64, I64, st.integers(0, 10**7)), min_size=1, max_size=12))
def test_any_clock_replies_never_stop_the_client_nor_move_it_past_panic(
    times: list[tuple[int, int, int]],
) -> None:
    from virja.rmcp.transport import ClockClient

    clock = SessionClock(wall_ns=lambda: NOW * 1000, monotonic_ns=lambda: 0)
    client = ClockClient(("127.0.0.1", 1), clock)
    for t1, t2, back in times:
        req = wire.Datagram.parse(client.request())
        body = req.body
        assert isinstance(body, ClockRequestBody)
        reply = wire.Datagram(5, 1, NOW, ClockReplyBody(body.nonce, body.t0_us, t1, t2))
        client.reply_received(bytes(reply), t3_us=body.t0_us + back)
        assert abs(clock.offset_us) <= client.guard.panic_us
        clock.now_us()  # still in range: the recorder and the requests can use it
        client.request()


class _FillingFile(io.FileIO):
    """A file on a disk that is full after ``room`` bytes (a short write, then ENOSPC)."""

    room = 0

    def write(self, b: object) -> int:
        data = bytes(b)  # type: ignore[call-overload]
        left = self.room - self.tell()
        if left < len(data):
            super().write(data[: max(left, 0)])
            raise OSError(28, "No space left on device")
        return super().write(data)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(room=st.integers(24, 4000), n=st.integers(1, 60), flush_s=st.sampled_from([0.0, 0.1]))
def test_a_disk_full_at_any_byte_leaves_a_readable_recording(
    tmp_path: Path, room: int, n: int, flush_s: float
) -> None:
    path = tmp_path / "full.pcap"
    raw = _FillingFile(str(path), "w")
    raw.room = room
    writer = PcapWriter(
        io.BufferedWriter(raw, buffer_size=64), local=("127.0.0.1", 50500), flush_interval_s=flush_s
    )
    for i in range(n):
        payload = bytes(wire.midi(2, i, NOW, bytes([0x99, 38, 90])))
        writer.write(payload, ("127.0.0.1", 40000), time_us=NOW + i * 50_000)
    writer.close()
    if path.stat().st_size == 24:  # the header alone: nothing was recorded whole
        assert writer.failed is not None
        return
    cap = read_capture(path)
    assert cap.warnings == []  # whole records only
    assert len(cap.datagrams) <= n
    assert (writer.failed is None) == (len(cap.datagrams) == n)


@pytest.mark.parametrize("gap_years", [1, 10, 80])
def test_a_recording_spanning_years_is_refused_by_render_in_one_line(
    tmp_path: Path, gap_years: int, capsys: pytest.CaptureFixture[str]
) -> None:
    """D7: two datagrams years apart; render says so at once, not after building
    billions of frame times."""
    from virja.cli.main import main

    path = tmp_path / "span.pcap"
    with PcapWriter.open(path, local=("127.0.0.1", 50500)) as w:
        for i, t in enumerate((NOW, NOW + gap_years * 365 * 86_400 * 1_000_000)):
            data = bytes(wire.midi(2, i, t + 500_000, bytes([0x99, 38, 90])))
            w.write(data, ("127.0.0.1", 9), time_us=t)
    with time_limit(30):
        rc = main(["render", str(path), "--out", str(tmp_path / "frames")])
    err = capsys.readouterr().err
    assert rc != 0
    assert "--start and --end" in err and "Traceback" not in err
    assert not (tmp_path / "frames").exists() or not any((tmp_path / "frames").iterdir())


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(room=st.integers(0, 3000))
def test_a_plan_log_on_a_disk_full_at_any_byte_keeps_whole_lines(tmp_path: Path, room: int) -> None:
    import json

    from virja.events import NoteOn

    path = tmp_path / "plan.jsonl"
    raw = _FillingFile(str(path), "w")
    raw.room = room
    log = io.TextIOWrapper(io.BufferedWriter(raw, buffer_size=128), encoding="utf-8")
    perf = Performance(router=Router(), planner=OnlinePlanner(), plan_log=log)
    for i in range(20):
        perf.feed(NoteOn(1.0 + i * 0.25, 9, 38, 90), now_s=0.0)
        perf.advance(0.8 + i * 0.25)
    planned = perf.finish()
    assert len(perf.planner.report.dropped) + len(planned) <= 20
    text = path.read_bytes()
    assert text == b"" or text.endswith(b"\n")
    for line in text.decode().splitlines():
        json.loads(line)
    assert (perf.plan_log_failed is None) == (len(text.splitlines()) == 20)
