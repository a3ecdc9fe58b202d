"""Per-peer budgets: a flooding peer is shed by reason; other peers and state stay bounded."""

from __future__ import annotations

from virja.events import NoteOn, ProgramChange
from virja.rmcp import wire
from virja.rmcp.budget import Bucket, Budget, PeerBudgets
from virja.rmcp.receiver import Receiver, ReceiverConfig
from virja.routing import Router

NOW = 1_700_000_000_000_000
FLOOD, HONEST = ("127.0.0.1", 40002), ("127.0.0.1", 40001)


def _big_immediate(seq: int) -> bytes:
    notes = b"".join(bytes([0x99, 36 + i % 10, 100]) for i in range(392))  # 1,200 bytes
    return bytes(wire.midi(9, seq, NOW, notes, flags=wire.Flags.IMMEDIATE))


def test_bucket_refills_at_its_rate_up_to_its_depth() -> None:
    b = Bucket(10.0, 5.0, 0)
    assert b.take_up_to(100, 0) == 5
    assert not b.take(1, 50_000)  # 0.05 s: half a token
    assert b.take(1, 100_000)
    assert b.take_up_to(100, 10_000_000) == 5  # never more than the depth


def test_act_now_flood_is_shed_and_the_honest_peer_is_untouched() -> None:
    r = Receiver()
    honest = 0
    for i in range(1000):  # one second of 1,200-byte floods at 1,000/s
        now = NOW + i * 1000
        r.receive_datagram(_big_immediate(i), FLOOD, now_us=now)
        if i % 100 == 0:
            r.receive_datagram(
                bytes(wire.midi(7, i, now + 500_000, bytes([0x90, 40, 90]))), HONEST, now_us=now
            )
            honest += 1
    events = r.drain_events()
    from_honest = [e for e in events if e.event.sender == 7]
    assert len(from_honest) == honest
    notes_from_flood = sum(isinstance(e.event, NoteOn) and e.event.sender == 9 for e in events)
    budget = Budget()
    assert notes_from_flood <= budget.notes_burst + budget.notes_per_s * 1.0 + 1
    assert r.stats.dropped["note_flood"] > 0 and r.stats.dropped["rate_limited"] > 0


def test_peer_out_of_note_budget_has_midi_shed_unparsed() -> None:
    r = Receiver()
    r.receive_datagram(_big_immediate(0), FLOOD, now_us=NOW)  # spends the burst
    before = r.stats.dropped["note_flood"]
    r.receive_datagram(
        b"RMCP\x01" + bytes([wire.Kind.MIDI]) + b"garbage that would not parse", FLOOD, now_us=NOW
    )
    assert r.stats.dropped["note_flood"] == before + 1  # shed before the parse


def test_clock_replies_at_a_bounded_rate() -> None:
    cfg = ReceiverConfig(budget=Budget(clock_replies_per_s=10.0))
    r = Receiver(cfg)
    for i in range(100):
        req = wire.clock_request(1, i, nonce=i, t0_us=NOW, time_us=NOW)
        r.receive_datagram(bytes(req), ("127.0.0.1", 30000 + i), now_us=NOW)
    assert len(r.datagrams_to_send(now_us=NOW)) == 10
    assert r.stats.dropped["clock_rate_limited"] == 90


def test_peer_table_is_capped() -> None:
    b = PeerBudgets(Budget(max_peers=8))
    for port in range(100):
        b.admit(("127.0.0.1", port), 30, NOW)
    assert len(b) == 8 and b.evicted == 92


def test_programs_of_65536_senders_stay_under_the_cap() -> None:
    router = Router()
    for sender in range(0, 65536, 7):
        for ch in range(16):
            router.route(ProgramChange(0.0, ch, 33, sender))
    assert len(router._programs) <= router.max_programs
    assert router.programs_evicted > 0
    # the latest senders' programs are still in force
    assert router.route(NoteOn(0.0, 3, 40, 90, 65534)) == "bass"
