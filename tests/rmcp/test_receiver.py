"""The sans-IO receiver, stepped with a hand-set ``now``."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from tests.rmcp.conftest import DATA, golden
from virja.events import Beat, ControlChange, NoteOff, NoteOn
from virja.rmcp import wire
from virja.rmcp.bodies import ClockReplyBody, UnknownBody
from virja.rmcp.receiver import Received, Receiver, ReceiverConfig
from virja.rmcp.seqnum import seq_add, seq_after, seq_diff
from virja.rmcp.signing import sign
from virja.rmcp.wire import Datagram, Flags

NOW = 1_700_000_000_000_000
ADDR = ("127.0.0.1", 40000)
KEY = b"secret"
ON = bytes([0x90, 60, 100])
OFF = bytes([0x80, 60, 0])
CC = bytes([0xB0, 7, 90])


def note(
    seq: int, time_us: int, msg: bytes = ON, sender: int = 1, flags: Flags = Flags.NONE
) -> bytes:
    return bytes(wire.midi(sender, seq, time_us, msg, flags=flags))


def signed(seq: int, time_us: int, msg: bytes = ON, sender: int = 1, key: bytes = KEY) -> bytes:
    return bytes(sign(wire.midi(sender, seq, time_us, msg), key))


def test_valid_note_delivered_at_its_time_on_arrival() -> None:
    r = Receiver()
    r.receive_datagram(note(0, NOW + 500_000), ADDR, now_us=NOW)
    assert r.drain_events() == [
        Received(NoteOn((NOW + 500_000) / 1e6, 0, 60, 100, 1), NOW / 1e6, False)
    ]
    assert r.stats.accepted == 1 and r.stats.by_kind["MIDI"] == 1


def test_invalid_datagrams_counted_by_reason_and_receiver_goes_on() -> None:
    r = Receiver()
    for p in sorted(DATA.glob("bad_*.bin")):
        r.receive_datagram(p.read_bytes(), ADDR, now_us=NOW)
    r.receive_datagram(note(0, NOW), ADDR, now_us=NOW)
    assert r.stats.dropped["bad_body"] == 11
    assert r.stats.dropped["bad_length"] == 2
    for reason in (
        "too_short",
        "too_long",
        "bad_magic",
        "bad_version",
        "bad_flags",
        "bad_reserved",
    ):
        assert r.stats.dropped[reason] == 1
    assert len(r.drain_events()) == 1


def test_duplicate_seq_dropped_and_counted() -> None:
    r = Receiver()
    for _ in range(3):
        r.receive_datagram(note(5, NOW + 1000), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1
    assert r.stats.dropped["duplicate"] == 2


def test_same_seq_from_another_sender_is_not_a_duplicate() -> None:
    r = Receiver()
    r.receive_datagram(note(5, NOW + 1000, sender=1), ADDR, now_us=NOW)
    r.receive_datagram(note(5, NOW + 1000, sender=2), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 2


def test_reordered_datagrams_all_delivered_without_key() -> None:
    r = Receiver()
    for seq in (3, 1, 2, 0):
        r.receive_datagram(note(seq, NOW + 100_000 * (seq + 1)), ADDR, now_us=NOW)
    events = r.drain_events()
    assert len(events) == 4
    assert sorted(e.event.time_s for e in events)[0] == (NOW + 100_000) / 1e6


def test_duplicate_window_covers_4096_numbers() -> None:
    r = Receiver(ReceiverConfig(budget=None))  # 4,100 datagrams in one instant: no rate limit
    for seq in range(4100):
        r.receive_datagram(note(seq, NOW), ADDR, now_us=NOW)
    r.drain_events()
    r.receive_datagram(note(4099 - 4095, NOW), ADDR, now_us=NOW)  # inside the window
    assert r.stats.dropped["duplicate"] == 1


def test_duplicates_detected_across_sequence_wrap() -> None:
    r = Receiver()
    seqs = [0xFFFFFFFE, 0xFFFFFFFF, 0, 1]
    for s in seqs:
        r.receive_datagram(note(s, NOW), ADDR, now_us=NOW)
    for s in seqs:
        r.receive_datagram(note(s, NOW), ADDR, now_us=NOW)
    assert r.stats.accepted == 4 and r.stats.dropped["duplicate"] == 4


def test_seq_helpers_wrap() -> None:
    assert seq_add(0xFFFFFFFF, 1) == 0
    assert seq_diff(0, 0xFFFFFFFF) == 1
    assert seq_diff(0xFFFFFFFF, 0) == -1
    assert seq_after(5, 0xFFFFFFF0)
    assert not seq_after(0xFFFFFFF0, 5)


def test_beyond_horizon_dropped_and_counted() -> None:
    r = Receiver(ReceiverConfig(horizon_s=10.0))
    r.receive_datagram(note(0, NOW + 10_000_001), ADDR, now_us=NOW)
    r.receive_datagram(note(1, NOW + 10_000_000), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1
    assert r.stats.dropped["beyond_horizon"] == 1


def test_note_on_within_lateness_delivered_marked_late() -> None:
    r = Receiver(ReceiverConfig(lateness_s=0.060))
    r.receive_datagram(note(0, NOW - 60_000), ADDR, now_us=NOW)
    [got] = r.drain_events()
    assert got.late and isinstance(got.event, NoteOn)
    assert r.stats.late == 1


def test_note_on_later_than_lateness_dropped_and_counted() -> None:
    r = Receiver(ReceiverConfig(lateness_s=0.060))
    r.receive_datagram(note(0, NOW - 60_001), ADDR, now_us=NOW)
    assert r.drain_events() == []
    assert r.stats.dropped["too_late"] == 1


def test_note_off_and_controller_always_apply_however_late() -> None:
    r = Receiver()
    r.receive_datagram(note(0, NOW - 5_000_000, OFF), ADDR, now_us=NOW)
    r.receive_datagram(note(1, NOW - 5_000_000, CC), ADDR, now_us=NOW)
    got = r.drain_events()
    assert [type(g.event) for g in got] == [NoteOff, ControlChange]
    assert all(g.late for g in got)


def test_immediate_takes_arrival_time() -> None:
    r = Receiver()
    r.receive_datagram(note(0, NOW - 99_000_000, flags=Flags.IMMEDIATE), ADDR, now_us=NOW)
    [got] = r.drain_events()
    assert got.event.time_s == NOW / 1e6 and not got.late


def test_unknown_kind_ignored_counted_and_advances_seq() -> None:
    r = Receiver()
    r.receive_datagram(bytes(Datagram(1, 3, NOW, UnknownBody(99, b"x"))), ADDR, now_us=NOW)
    r.receive_datagram(note(3, NOW), ADDR, now_us=NOW)
    assert r.stats.dropped["unknown_kind"] == 1
    assert r.stats.dropped["duplicate"] == 1
    assert r.drain_events() == []


def test_beat_delivered_as_event() -> None:
    r = Receiver()
    r.receive_datagram(golden("beat.bin"), ADDR, now_us=1_700_000_000_000_000)
    [got] = r.drain_events()
    assert isinstance(got.event, Beat) and got.event.bar == 12


def test_next_event_returns_in_arrival_order_then_none() -> None:
    r = Receiver()
    r.receive_datagram(note(0, NOW + 2000), ADDR, now_us=NOW)
    r.receive_datagram(note(1, NOW + 1000), ADDR, now_us=NOW)
    a, b = r.next_event(), r.next_event()
    assert a is not None and b is not None
    assert a.event.time_s > b.event.time_s
    assert r.next_event() is None


# -- signing ------------------------------------------------------------------


def keyed() -> Receiver:
    return Receiver(ReceiverConfig(key=KEY))


def test_signed_accepted_with_key() -> None:
    r = keyed()
    r.receive_datagram(signed(0, NOW + 1000), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1


def test_unsigned_dropped_with_key() -> None:
    r = keyed()
    r.receive_datagram(note(0, NOW + 1000), ADDR, now_us=NOW)
    assert r.drain_events() == [] and r.stats.dropped["unsigned"] == 1


def test_forged_tag_dropped_with_key() -> None:
    r = keyed()
    r.receive_datagram(signed(0, NOW + 1000, key=b"wrong"), ADDR, now_us=NOW)
    data = bytearray(signed(1, NOW + 1000))
    data[26] ^= 1  # flip a body bit; the tag no longer matches
    r.receive_datagram(bytes(data), ADDR, now_us=NOW)
    assert r.drain_events() == [] and r.stats.dropped["bad_tag"] == 2


def test_replayed_older_seq_dropped_with_key() -> None:
    r = keyed()
    r.receive_datagram(signed(10, NOW + 1000), ADDR, now_us=NOW)
    r.receive_datagram(signed(9, NOW + 1000), ADDR, now_us=NOW)
    r.receive_datagram(signed(10, NOW + 1000), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1
    assert r.stats.dropped["replay"] == 1 and r.stats.dropped["duplicate"] == 1


def test_replay_rule_wraps() -> None:
    r = keyed()
    r.receive_datagram(signed(0xFFFFFFFF, NOW + 1000), ADDR, now_us=NOW)
    r.receive_datagram(signed(0, NOW + 1000), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 2


def test_too_old_time_dropped_with_key() -> None:
    r = keyed()
    r.receive_datagram(signed(0, NOW - 30_000_001, OFF), ADDR, now_us=NOW)
    r.receive_datagram(signed(1, NOW - 30_000_000, OFF), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1 and r.stats.dropped["stale"] == 1


def test_without_key_signed_accepted_unchecked() -> None:
    r = Receiver()
    r.receive_datagram(signed(0, NOW + 1000, key=b"anything"), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 1


# -- clock requests -----------------------------------------------------------


def test_clock_request_answered_with_t1_t2() -> None:
    r = Receiver(ReceiverConfig(sender_id=77))
    req = bytes(wire.clock_request(5, 0, nonce=42, t0_us=NOW - 300))
    r.receive_datagram(req, ADDR, now_us=NOW)
    [(data, addr)] = r.datagrams_to_send(now_us=NOW + 20)
    reply = Datagram.parse(data)
    assert addr == ADDR and reply.sender == 77 and reply.immediate
    assert reply.body == ClockReplyBody(42, NOW - 300, NOW, NOW + 20)
    assert r.datagrams_to_send(now_us=NOW) == []


def test_clock_reply_signed_when_keyed() -> None:
    r = keyed()
    r.receive_datagram(
        bytes(sign(wire.clock_request(5, 0, nonce=1, t0_us=NOW), KEY)), ADDR, now_us=NOW
    )
    [(data, _)] = r.datagrams_to_send(now_us=NOW)
    assert Datagram.parse(data).signed


# -- bounded state ------------------------------------------------------------


def test_sender_state_is_bounded() -> None:
    r = Receiver(ReceiverConfig(max_senders=16, budget=None))  # one address: no budget here
    for s in range(100):
        r.receive_datagram(note(0, NOW, sender=s), ADDR, now_us=NOW)
    assert r.tracked_senders == 16 and r.stats.senders_evicted == 84


def test_event_queue_is_bounded() -> None:
    r = Receiver(ReceiverConfig(max_queue=10))
    for s in range(20):
        r.receive_datagram(note(s, NOW), ADDR, now_us=NOW)
    assert len(r.drain_events()) == 10 and r.stats.dropped["queue_full"] == 10


# -- fuzzing ------------------------------------------------------------------


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=1300))
def test_fuzz_random_bytes_never_raise(data: bytes) -> None:
    r = Receiver(ReceiverConfig(key=KEY))
    r.receive_datagram(data, ADDR, now_us=NOW)
    r.receive_datagram(b"RMCP\x01" + data, ADDR, now_us=NOW)
    assert r.stats.dropped["internal_error"] == 0


@settings(max_examples=300, deadline=None)
@given(
    st.sampled_from(sorted(p.name for p in DATA.glob("*.bin"))),
    st.lists(st.tuples(st.integers(0, 1300), st.integers(0, 255)), max_size=4),
)
def test_fuzz_mutated_golden_never_raise(name: str, edits: list[tuple[int, int]]) -> None:
    data = bytearray(golden(name))
    for pos, val in edits:
        if pos < len(data):
            data[pos] = val
    r = Receiver()
    r.receive_datagram(bytes(data), ADDR, now_us=NOW)
    assert r.stats.dropped["internal_error"] == 0
    try:
        d = Datagram.parse(bytes(data))
    except ValueError:
        return
    assert bytes(d) == bytes(data)
