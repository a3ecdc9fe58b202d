"""The sans-IO session host, stepped with a hand-set clock: invitations, clock
sync, feedback, BY, timeouts, and every bad peer a counted drop."""

from __future__ import annotations

from tests.rtpmidi.conftest import node_datagrams
from virja.rtpmidi.control import Command, FeedbackPacket, SessionPacket, SyncPacket, parse_control
from virja.rtpmidi.host import Channel, HostConfig, SessionHost
from virja.rtpmidi.payload import midi_packet

C, D = Channel.CONTROL, Channel.DATA
PEER_C, PEER_D = ("10.0.0.2", 5004), ("10.0.0.2", 5005)
SSRC, TOKEN = 0xABCD0001, 77
T0 = 1_800_000_000_000_000


def invite(cmd: Command = Command.IN, ssrc: int = SSRC, token: int = TOKEN) -> bytes:
    return bytes(SessionPacket(cmd, token, ssrc, "peer"))


def open_host(**kw: object) -> SessionHost:
    host = SessionHost(HostConfig(ssrc=0x11, **kw))  # type: ignore[arg-type]
    host.receive_datagram(invite(), PEER_C, channel=C, now_us=T0)
    host.receive_datagram(invite(), PEER_D, channel=D, now_us=T0 + 1000)
    host.datagrams_to_send(now_us=T0 + 1000)
    return host


def test_invitation_on_both_ports_is_accepted_from_the_right_port() -> None:
    host = SessionHost(HostConfig(ssrc=0x11, name="virja"))
    host.receive_datagram(invite(), PEER_C, channel=C, now_us=T0)
    host.receive_datagram(invite(), PEER_D, channel=D, now_us=T0 + 1)
    out = host.datagrams_to_send(now_us=T0 + 2)
    assert [(parse_control(d), a, ch) for d, a, ch in out] == [
        (SessionPacket(Command.OK, TOKEN, 0x11, "virja"), PEER_C, C),
        (SessionPacket(Command.OK, TOKEN, 0x11, "virja"), PEER_D, D),
    ]
    assert host.open_sessions == 1 and host.stats.sessions_opened == 1


def test_a_repeated_invitation_is_answered_again() -> None:
    host = SessionHost(HostConfig(ssrc=0x11))
    for _ in range(3):
        host.receive_datagram(invite(), PEER_C, channel=C, now_us=T0)
    assert len(host.datagrams_to_send(now_us=T0)) == 3 and len(host.sessions) == 1


def test_clock_sync_is_answered_with_our_time_and_closed_by_ck2() -> None:
    host = open_host()
    ck0 = SyncPacket(SSRC, 0, (1234, 0, 0))
    host.receive_datagram(bytes(ck0), PEER_D, channel=D, now_us=T0 + 50_000)
    [(data, addr, ch)] = host.datagrams_to_send(now_us=T0 + 50_000)
    ck1 = parse_control(data)
    assert isinstance(ck1, SyncPacket) and (addr, ch) == (PEER_D, D)
    assert ck1.count == 1 and ck1.ssrc == 0x11 and ck1.timestamps[0] == 1234
    assert ck1.timestamps[1] == 500  # 100 us ticks since the host's first datagram
    ck2 = SyncPacket(SSRC, 2, (1234, 500, 1254))
    host.receive_datagram(bytes(ck2), PEER_D, channel=D, now_us=T0 + 60_000)
    assert host.datagrams_to_send(now_us=T0 + 60_000) == []
    assert host.stats.last_latency_ms == 1.0


def test_midi_becomes_messages_at_arrival_plus_delta_and_feedback_follows() -> None:
    host = open_host()
    pkt = midi_packet(SSRC, 9, 0, (0, [0x99, 36, 100]), (20, [0x90, 40, 90]))
    host.receive_datagram(pkt, PEER_D, channel=D, now_us=T0 + 2_000_000)
    msgs = host.drain_messages()
    assert [(m.data, m.time_s, m.arrival_s, m.ssrc) for m in msgs] == [
        (b"\x99\x24\x64", 1_800_000_002.0, 1_800_000_002.0, SSRC),
        (b"\x90\x28\x5a", 1_800_000_002.002, 1_800_000_002.0, SSRC),
    ]
    [(data, addr, ch)] = host.datagrams_to_send(now_us=T0 + 2_000_000)
    assert parse_control(data) == FeedbackPacket(0x11, 9) and (addr, ch) == (PEER_C, C)
    # no new data: no new feedback
    assert host.datagrams_to_send(now_us=T0 + 4_000_000) == []


def test_bye_ends_the_session_and_its_midi_is_then_refused() -> None:
    host = open_host()
    host.receive_datagram(invite(Command.BY), PEER_C, channel=C, now_us=T0 + 1)
    assert host.sessions == {} and host.stats.sessions_ended == 1
    host.receive_datagram(
        midi_packet(SSRC, 1, 0, (0, [0x99, 36, 1])), PEER_D, channel=D, now_us=T0 + 2
    )
    assert host.drain_messages() == [] and host.stats.dropped["unknown_ssrc"] == 1


def test_quiet_sessions_time_out_and_pending_ones_sooner() -> None:
    host = open_host(session_timeout_s=60.0, pending_timeout_s=10.0)
    host.receive_datagram(invite(ssrc=5), ("10.0.0.3", 5004), channel=C, now_us=T0)
    host.tick(T0 + 11_000_000)
    assert set(host.sessions) == {SSRC}
    host.tick(T0 + 61_000_000)
    assert host.sessions == {} and host.stats.sessions_timed_out == 2


def test_every_bad_peer_is_a_counted_drop() -> None:
    host = open_host(max_sessions=2)
    stranger = ("10.9.9.9", 5005)
    note = (0, [0x99, 36, 100])
    cases = [
        (midi_packet(999, 1, 0, note), PEER_D, D, "unknown_ssrc"),  # never invited
        (midi_packet(SSRC, 1, 0, note), stranger, D, "wrong_peer"),  # right SSRC, wrong host
        (midi_packet(SSRC, 1, 0, note), PEER_C, C, "midi_on_control_port"),
        (invite(ssrc=42), ("10.0.0.4", 5005), D, "not_invited"),  # data IN without control IN
        (invite(token=5), ("10.9.9.9", 5004), C, "ssrc_in_use"),
        (invite(Command.OK), PEER_C, C, "unexpected_ok"),
        (invite(Command.BY, ssrc=4), PEER_C, C, "unknown_session"),
        (bytes(SyncPacket(SSRC, 1, (0, 0, 0))), PEER_D, D, "unexpected_ck1"),
        (bytes(SyncPacket(31337, 0, (0, 0, 0))), PEER_D, D, "unknown_session"),
        (b"\x80\x61", PEER_D, D, "truncated"),
        (b"\x00" * 20, PEER_D, D, "bad_version"),
        (b"\xff\xff" + b"ZZ" + bytes(20), PEER_C, C, "unknown_command"),
        (bytes(5000), PEER_D, D, "too_long"),
        (midi_packet(SSRC, 1, 0, (20_000, [0x99, 36, 100])), PEER_D, D, "delta_too_far"),
    ]
    for data, addr, ch, reason in cases:
        before = host.stats.dropped[reason]
        host.receive_datagram(data, addr, channel=ch, now_us=T0 + 5)
        assert host.stats.dropped[reason] == before + 1, reason
    assert host.drain_messages() == []
    # the session survived it all
    host.receive_datagram(midi_packet(SSRC, 2, 0, note), PEER_D, channel=D, now_us=T0 + 6)
    assert len(host.drain_messages()) == 1


def test_stale_and_duplicate_sequence_numbers_are_dropped_and_gaps_counted() -> None:
    host = open_host()
    note = (0, [0x99, 36, 100])
    for seq in (0xFFFE, 0xFFFE, 0xFFF0, 0x0001, 0x0005):
        host.receive_datagram(midi_packet(SSRC, seq, 0, note), PEER_D, channel=D, now_us=T0 + 9)
    assert len(host.drain_messages()) == 3  # 0xFFFE, 0x0001 (across the wrap), 0x0005
    assert host.stats.dropped["stale_seq"] == 2 and host.stats.lost_packets == 2 + 3


def test_a_flood_is_capped_per_session_per_second() -> None:
    host = open_host(max_commands_per_s=100.0)
    cmds = [(0, [0x99, 36, 100])] * 50
    for i in range(10):  # 500 commands within a millisecond
        host.receive_datagram(midi_packet(SSRC, i, 0, *cmds), PEER_D, channel=D, now_us=T0 + 10 + i)
    assert len(host.drain_messages()) == 100 and host.stats.dropped["flood"] == 400
    host.receive_datagram(midi_packet(SSRC, 99, 0, *cmds), PEER_D, channel=D, now_us=T0 + 1_000_100)
    assert len(host.drain_messages()) == 50  # refilled a second later


def test_sessions_are_capped_and_the_extra_peer_told_no() -> None:
    host = SessionHost(HostConfig(ssrc=0x11, max_sessions=2))
    for i in range(3):
        host.receive_datagram(invite(ssrc=i), (f"10.0.0.{i}", 5004), channel=C, now_us=T0)
    replies = [parse_control(d) for d, _a, _c in host.datagrams_to_send(now_us=T0)]
    assert [r.command for r in replies if isinstance(r, SessionPacket)] == [
        Command.OK,
        Command.OK,
        Command.NO,
    ]
    assert len(host.sessions) == 2 and host.stats.dropped["sessions_full"] == 1


def test_two_peers_at_once_each_keep_their_running_order() -> None:
    host = open_host()
    other_c, other_d = ("10.0.0.7", 6000), ("10.0.0.7", 6001)
    host.receive_datagram(invite(ssrc=7), other_c, channel=C, now_us=T0)
    host.receive_datagram(invite(ssrc=7), other_d, channel=D, now_us=T0)
    host.receive_datagram(
        midi_packet(7, 1, 0, (0, [0x99, 38, 1])), other_d, channel=D, now_us=T0 + 1
    )
    host.receive_datagram(
        midi_packet(SSRC, 1, 0, (0, [0x99, 36, 1])), PEER_D, channel=D, now_us=T0 + 2
    )
    assert [(m.ssrc, m.data[1]) for m in host.drain_messages()] == [(7, 38), (SSRC, 36)]


def test_close_says_bye_to_every_peer() -> None:
    host = open_host()
    host.close()
    [(data, addr, ch)] = host.datagrams_to_send(now_us=T0 + 1)
    bye = parse_control(data)
    assert isinstance(bye, SessionPacket) and bye.command is Command.BY and addr == PEER_C


def test_the_node_session_replays_to_its_seven_messages() -> None:
    host = SessionHost()
    dgrams = node_datagrams()
    port = dgrams[0].dst[1]
    for d in dgrams:
        ch = C if d.dst[1] == port else D
        host.receive_datagram(d.payload, d.src, channel=ch, now_us=d.time_us)
    msgs = host.drain_messages()
    assert [m.data[0] for m in msgs] == [0x99, 0x99, 0x99, 0x90, 0xC0, 0x90, 0x80]
    assert host.stats.sysex_skipped == 1 and not host.stats.dropped
    assert host.stats.sessions_opened == 1 and host.stats.sessions_ended == 1
