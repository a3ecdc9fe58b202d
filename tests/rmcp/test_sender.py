"""``virja send``'s pure schedule, and one loopback run sender -> transport -> events."""

from __future__ import annotations

import asyncio

from virja.clock import SessionClock
from virja.events import Beat, ControlChange, Event, NoteOff, NoteOn, ProgramChange
from virja.rmcp.bodies import BeatBody, MidiBody
from virja.rmcp.receiver import Received, Receiver, ReceiverConfig
from virja.rmcp.sender import SendOptions, beats_of, schedule_pass
from virja.rmcp.streamer import SendSettings, stream
from virja.rmcp.transport import RmcpProtocol, open_listener, parse_hostport
from virja.tempo import TempoMap

START = 1_700_000_000_000_000


def route(ev: Event) -> str | None:
    if isinstance(ev, NoteOn | NoteOff):
        return "drums" if ev.channel == 9 else "bass" if ev.channel == 1 else None
    return None


EVENTS: list[Event] = [
    ProgramChange(0.0, 1, 33),
    NoteOn(0.0, 1, 40, 90),
    NoteOn(0.0, 9, 36, 100),
    NoteOn(0.0, 9, 42, 80),
    NoteOff(0.4, 1, 40, 0),
    NoteOn(1.0, 0, 60, 70),
    ControlChange(1.0, 1, 64, 127),
]


def test_notes_sent_one_beat_ahead_at_the_tempo_there() -> None:
    tempo = TempoMap([(0.0, 0.5), (1.0, 0.25)])
    items, _ = schedule_pass(EVENTS, tempo, [], SendOptions(), START, route=route)
    by_time = {(s.datagram.sender, s.datagram.time_us): s.send_us for s in items}
    assert by_time[(1, START)] == START - 500_000
    assert by_time[(3, START + 1_000_000)] == START + 1_000_000 - 250_000


def test_one_sender_id_per_performer_and_simultaneous_events_share_a_datagram() -> None:
    items, seqs = schedule_pass(EVENTS, TempoMap(), [], SendOptions(), START, route=route)
    drums = [s.datagram for s in items if s.datagram.sender == 2]
    assert len(drums) == 1 and isinstance(drums[0].body, MidiBody)
    assert drums[0].body.messages == (bytes([0x99, 36, 100]), bytes([0x99, 42, 80]))
    bass0 = [s.datagram for s in items if s.datagram.sender == 1 and s.datagram.time_us == START]
    assert bass0[0].body == MidiBody((bytes([0xC1, 33]), bytes([0x91, 40, 90])))
    # the controller of the bass channel goes with the bass
    assert any(
        bytes([0xB1, 64, 127]) in d.datagram.body.messages for d in items if d.datagram.sender == 1
    )  # type: ignore[union-attr]
    assert seqs == {1: 3, 2: 1, 3: 1}


def test_sequence_numbers_run_per_sender_in_send_order_and_carry_over() -> None:
    items, seqs = schedule_pass(EVENTS, TempoMap(), [], SendOptions(), START, route=route)
    items2, _ = schedule_pass(
        EVENTS, TempoMap(), [], SendOptions(), START + 2_000_000, route=route, seqs=seqs
    )
    bass = [s.datagram.seq for s in items + items2 if s.datagram.sender == 1]
    assert bass == list(range(6))
    assert [s.send_us for s in items] == sorted(s.send_us for s in items)


def test_forced_sender_id() -> None:
    items, _ = schedule_pass(EVENTS, TempoMap(), [], SendOptions(sender=9), START, route=route)
    assert {s.datagram.sender for s in items} == {9}


def test_beats_every_beat_with_bar_heads_level_2() -> None:
    beats = beats_of(TempoMap(), 4.0, 4)
    assert [(b.bar, b.beat, b.level) for b in beats] == [
        (0, 1, 2),
        (0, 2, 0),
        (0, 3, 1),
        (0, 4, 0),
        (1, 1, 2),
        (1, 2, 0),
        (1, 3, 1),
        (1, 4, 0),
    ]
    items, _ = schedule_pass([], TempoMap(), beats, SendOptions(), START, route=route)
    assert len(items) == 8
    first = items[0].datagram
    assert first.body == BeatBody(0, 1, 4, 2, 500_000) and first.time_us == START
    assert items[0].send_us == START - 500_000 and first.sender == 3


def test_schedule_is_pure() -> None:
    a = schedule_pass(EVENTS, TempoMap(), [], SendOptions(), START, route=route)
    b = schedule_pass(EVENTS, TempoMap(), [], SendOptions(), START, route=route)
    assert a == b


def test_parse_hostport_forms() -> None:
    assert parse_hostport("[::1]:50501") == ("::1", 50501)
    assert parse_hostport("127.0.0.1:9") == ("127.0.0.1", 9)
    assert parse_hostport("localhost") == ("localhost", 50500)
    assert parse_hostport("::1") == ("::1", 50500)


def test_loopback_sender_to_transport_to_events() -> None:
    """Real sockets on 127.0.0.1 port 0: what the sender sends arrives as events."""

    async def main() -> list[Received]:
        clock = SessionClock()
        got: list[Received] = []
        proto = RmcpProtocol(Receiver(), clock, lambda evs, now_s: got.extend(evs))
        listener = await open_listener("127.0.0.1", 0, proto)
        port = listener.get_extra_info("sockname")[1]
        events: list[Event] = [NoteOn(0.0, 9, 36, 100), NoteOff(0.05, 9, 36, 0)]
        try:
            stats = await stream(
                SendSettings(("127.0.0.1", port), SendOptions(), start_in_s=0.2, max_passes=1),
                events=events,
                tempo=TempoMap([(0.0, 0.05)]),
                beats=[Beat(0.0, 0, 1, 4, 2, 50_000)],
                duration_s=0.1,
                route_factory=lambda: route,
                clock=clock,
            )
            assert stats.datagrams == 3
            for _ in range(100):  # bounded wait for the datagrams to arrive
                if len(got) >= 3:
                    break
                await asyncio.sleep(0.01)
        finally:
            listener.close()
        return got

    got = asyncio.run(main())
    kinds = sorted(type(r.event).__name__ for r in got)
    assert kinds == ["Beat", "NoteOff", "NoteOn"]
    assert {r.event.sender for r in got if isinstance(r.event, NoteOn)} == {2}


def test_clock_client_sets_offset_from_a_reply() -> None:
    """Sans-IO round trip: request -> a receiver that answers -> reply -> offset."""
    from virja.rmcp.receiver import ReceiverConfig
    from virja.rmcp.transport import ClockClient

    local = SessionClock(wall_ns=lambda: START * 1000, monotonic_ns=lambda: 0)
    client = ClockClient(("127.0.0.1", 1), local)
    server = Receiver(ReceiverConfig(sender_id=3))
    req = client.request()
    server.receive_datagram(req, ("127.0.0.1", 2), now_us=START + 40_000)
    [(reply, _)] = server.datagrams_to_send(now_us=START + 40_100)
    assert client.reply_received(reply, t3_us=START + 200)
    assert local.offset_us == round(((40_000) + (40_100 - 200)) / 2)
    assert not client.reply_received(reply, t3_us=START + 300)  # not pending any more


def test_cli_send_missing_file_is_a_one_line_error(capsys: object) -> None:
    from virja.cli.main import main

    assert main(["send", "/nonexistent/x.mid", "--to", "127.0.0.1:9"]) == 1


def test_loopback_clock_client_gets_reply_from_a_listener() -> None:
    """ClockClient -> real socket -> RmcpProtocol answers -> the estimator has a sample."""
    from virja.rmcp.transport import ClockClient

    async def main() -> int:
        clock = SessionClock()
        proto = RmcpProtocol(Receiver(), clock, lambda evs, now_s: None)
        listener = await open_listener("127.0.0.1", 0, proto)
        port = listener.get_extra_info("sockname")[1]
        client = ClockClient(("127.0.0.1", port), SessionClock(), interval_s=0.05)
        task = asyncio.create_task(client.run())
        try:
            for _ in range(200):  # bounded wait
                if len(client.estimator):
                    break
                await asyncio.sleep(0.01)
        finally:
            task.cancel()
            listener.close()
        return len(client.estimator)

    assert asyncio.run(main()) >= 1


def test_programs_are_repeated_at_each_bar_head() -> None:
    """A receiver that missed the first datagram still learns the bass channel's program."""
    tempo = TempoMap([(0.0, 0.5)])
    beats = beats_of(tempo, 4.0, 4)  # two bars
    items, _ = schedule_pass(EVENTS, tempo, beats, SendOptions(), START, route=route)
    programs = [
        s.datagram.time_us
        for s in items
        if s.datagram.sender == 1
        and isinstance(s.datagram.body, MidiBody)
        and bytes([0xC1, 33]) in s.datagram.body.messages
    ]
    assert programs == [START, START + 2_000_000]  # the file's own, then bar 2's head


def test_a_restarted_sender_is_not_taken_for_repeats_or_replays() -> None:
    """Each run numbers from the clock (ms), so a running receiver, keyed or not,
    accepts a second run of the same file from the same sender ids."""
    from virja.rmcp.signing import sign

    for key in (None, b"k" * 16):
        rx = Receiver(ReceiverConfig(key=key))
        runs = []
        for run, start_us in enumerate((START, START + 5_000_000)):
            items, _ = schedule_pass(
                EVENTS,
                TempoMap(),
                [],
                SendOptions(),
                start_us,
                route=route,
                seq_start=start_us // 1000,
            )
            runs.append(items)
            for s in items:
                d = sign(s.datagram, key) if key else s.datagram
                rx.receive_datagram(bytes(d), ("127.0.0.1", 9), now_us=s.send_us)
            assert rx.stats.dropped.get("duplicate", 0) == 0, (run, key)
            assert not rx.stats.dropped, (run, key, rx.stats.dropped)
        assert rx.stats.accepted == sum(len(r) for r in runs)


def test_chords_go_out_as_chord_messages_from_the_conductor() -> None:
    """A file's chord symbols reach a receiver's heads-up display, a beat ahead like notes."""
    from virja.events import Chord
    from virja.rmcp.bodies import ChordBody

    options = SendOptions()
    items, _ = schedule_pass(
        [Chord(2.0, 10, None, "7")], TempoMap(), [], options, 1_000_000, route=lambda ev: None
    )
    (item,) = items
    assert isinstance(item.datagram.body, ChordBody)
    assert (item.datagram.body.root, item.datagram.body.quality) == (10, "7")
    assert item.datagram.sender == options.conductor
    assert item.datagram.time_us == 3_000_000 and item.send_us < item.datagram.time_us


def test_clock_client_refuses_hostile_replies_and_the_recorder_keeps_going(
    tmp_path: object,
) -> None:
    """D2: t1 = t2 = 2^63-1, a negative delay, a +1 h shift: the clock stays, the
    receiver and the recorder go on (docs/reliability.md)."""
    from pathlib import Path

    from virja.rmcp.bodies import ClockReplyBody, ClockRequestBody
    from virja.rmcp.pcap import PcapWriter, read_capture
    from virja.rmcp.transport import ClockClient
    from virja.rmcp.wire import Datagram, Flags

    local = SessionClock(wall_ns=lambda: START * 1000, monotonic_ns=lambda: 0)
    client = ClockClient(("127.0.0.1", 1), local)

    def reply(t1: int, t2: int) -> bytes:
        req = Datagram.parse(client.request())
        body = req.body
        assert isinstance(body, ClockRequestBody)
        out = ClockReplyBody(body.nonce, body.t0_us, t1, t2)
        return bytes(Datagram(5, 1, START, out, Flags.IMMEDIATE))

    big = (1 << 63) - 1
    assert client.reply_received(reply(big, big), t3_us=START + 100)
    assert local.offset_us == 0 and client.refused == {"panic": 1}
    assert not client.reply_received(reply(START, START + 10**12), t3_us=START + 100)
    hour = 3_600_000_000
    for _ in range(2):  # a plausible +1 h shift, not (yet) confirmed by three samples
        client.reply_received(reply(START + hour, START + hour), t3_us=START)
    assert local.offset_us == 0
    path = Path(str(tmp_path)) / "r.pcap"
    with PcapWriter.open(path, local=("127.0.0.1", 50500)) as w:
        w.write(b"x", ("127.0.0.1", 9), time_us=local.now_us())
        w.write(b"y", ("127.0.0.1", 9), time_us=1 << 62)  # a time pcap cannot hold: skipped
    assert len(read_capture(path).datagrams) == 1
