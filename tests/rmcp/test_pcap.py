"""Recordings: pcap written and read back; other formats and link types built here."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import pytest

from virja.errors import InputFileError
from virja.rmcp import wire
from virja.rmcp.packets import ipv4_checksum, udp_packet
from virja.rmcp.pcap import PcapWriter, read_capture

T = 1_700_000_000_000_000
PAYLOAD = bytes(wire.midi(1, 0, T, bytes([0x90, 60, 100])))


def write_pcap(
    path: Path, linktype: int, frames: list[bytes], *, order: str = "<", ns: bool = False
) -> None:
    magic = 0xA1B23C4D if ns else 0xA1B2C3D4
    out = struct.pack(order + "IHHiIII", magic, 2, 4, 0, 0, 65535, linktype)
    for i, f in enumerate(frames):
        frac = (i * 1000 + 5) * (1000 if ns else 1)
        out += struct.pack(order + "IIII", T // 1_000_000 + i, frac, len(f), len(f)) + f
    path.write_bytes(out)


def block(order: str, btype: int, body: bytes) -> bytes:
    body += b"\0" * (-len(body) % 4)
    n = len(body) + 12
    return struct.pack(order + "II", btype, n) + body + struct.pack(order + "I", n)


def write_pcapng(
    path: Path, linktype: int, frames: list[bytes], *, order: str = "<", tsresol: int | None = None
) -> None:
    shb = block(order, 0x0A0D0D0A, struct.pack(order + "IHHq", 0x1A2B3C4D, 1, 0, -1))
    opts = b""
    if tsresol is not None:
        opts = (
            struct.pack(order + "HH", 9, 1)
            + bytes([tsresol, 0, 0, 0])
            + struct.pack(order + "HH", 0, 0)
        )
    idb = block(order, 1, struct.pack(order + "HHI", linktype, 0, 0) + opts)
    out = shb + idb
    units = 10**9 if tsresol == 9 else 10**6
    for i, f in enumerate(frames):
        ts = (T + i * 1000) * units // 10**6
        out += block(
            order, 6, struct.pack(order + "IIIII", 0, ts >> 32, ts & 0xFFFFFFFF, len(f), len(f)) + f
        )
    out += block(order, 3, struct.pack(order + "I", len(frames[0])) + frames[0])  # SPB
    path.write_bytes(out)


def v4(payload: bytes = PAYLOAD, dport: int = 50500) -> bytes:
    return udp_packet("192.168.1.7", 40000, "192.168.1.2", dport, payload)


def v6(payload: bytes = PAYLOAD) -> bytes:
    return udp_packet("fe80::1", 40001, "fe80::2", 50500, payload)


def test_written_ipv4_header_checksum_is_correct() -> None:
    pkt = v4()
    assert ipv4_checksum(pkt[:20]) == 0
    assert struct.unpack("!H", pkt[2:4])[0] == len(pkt)


def test_write_then_read_back_keeps_sender_time_and_payload(tmp_path: Path) -> None:
    p = tmp_path / "rec.pcap"
    with PcapWriter.open(p, local=("127.0.0.1", 50500)) as w:
        w.write(PAYLOAD, ("10.0.0.5", 4321), time_us=T + 17)
        w.write(PAYLOAD + b"", ("::1", 5555, 0, 0), time_us=T + 40)
    cap = read_capture(p)
    assert [(d.time_us, d.src, d.payload) for d in cap.datagrams] == [
        (T + 17, ("10.0.0.5", 4321), PAYLOAD),
        (T + 40, ("::1", 5555), PAYLOAD),
    ]
    assert cap.datagrams[0].dst == ("127.0.0.1", 50500)
    assert cap.warnings == []


@pytest.mark.parametrize(
    ("bound", "dst"),
    [
        (("0.0.0.0", 50600), ("127.0.0.1", 50600)),
        (("::", 50601, 0, 0), ("::1", 50601)),
        (("192.0.2.7", 50602), ("192.0.2.7", 50602)),
    ],
)
def test_a_listeners_recording_names_the_bound_port_and_a_real_address(
    tmp_path: Path, bound: tuple[object, ...], dst: tuple[str, int]
) -> None:
    """serve --record: the packets are addressed to the port bound (port 0 picks one),
    a wildcard address written as its family's loopback."""
    p = tmp_path / "rec.pcap"
    with PcapWriter.for_listener(p, bound) as w:
        w.write(PAYLOAD, ("::1", 4321, 0, 0) if ":" in dst[0] else ("127.0.0.1", 4321), time_us=T)
    assert read_capture(p, port=dst[1]).datagrams[0].dst == dst


def test_writer_flushes_every_100_ms_of_given_time() -> None:
    buf = io.BytesIO()

    class Spy(io.BytesIO):
        flushes = 0

        def flush(self) -> None:
            Spy.flushes += 1

    s = Spy()
    w = PcapWriter(s, local=("127.0.0.1", 50500))
    base = Spy.flushes
    w.write(PAYLOAD, ("10.0.0.5", 1), time_us=T)
    w.write(PAYLOAD, ("10.0.0.5", 1), time_us=T + 50_000)
    assert Spy.flushes == base
    w.tick(T + 100_000)
    assert Spy.flushes == base + 1
    del buf


def test_truncated_last_record_read_up_to_it_with_warning(tmp_path: Path) -> None:
    p = tmp_path / "killed.pcap"
    with PcapWriter.open(p, local=("127.0.0.1", 50500)) as w:
        for i in range(3):
            w.write(PAYLOAD, ("10.0.0.5", 4321), time_us=T + i)
    data = p.read_bytes()
    p.write_bytes(data[:-10])
    cap = read_capture(p)
    assert len(cap.datagrams) == 2
    assert any("truncated last record" in w for w in cap.warnings)


@pytest.mark.parametrize(("order", "ns"), [("<", False), (">", False), ("<", True), (">", True)])
def test_classic_pcap_byte_orders_and_ns(tmp_path: Path, order: str, ns: bool) -> None:
    p = tmp_path / "x.pcap"
    write_pcap(p, 101, [v4(), v6()], order=order, ns=ns)
    cap = read_capture(p)
    assert [d.time_us for d in cap.datagrams] == [T + 5, T + 1_000_000 + 1005]
    assert [d.src for d in cap.datagrams] == [("192.168.1.7", 40000), ("fe80::1", 40001)]


def _eth(ip: bytes, vlan: bool = False) -> bytes:
    et = 0x0800 if ip[0] >> 4 == 4 else 0x86DD
    tag = struct.pack("!HH", 0x8100, 42) if vlan else b""
    return b"\x00" * 12 + tag + struct.pack("!H", et) + ip


def _sll(ip: bytes) -> bytes:
    et = 0x0800 if ip[0] >> 4 == 4 else 0x86DD
    return struct.pack("!HHH8sH", 0, 1, 6, b"\0" * 8, et) + ip


def _sll2(ip: bytes) -> bytes:
    et = 0x0800 if ip[0] >> 4 == 4 else 0x86DD
    return struct.pack("!HHIHBB8s", et, 0, 1, 1, 0, 6, b"\0" * 8) + ip


@pytest.mark.parametrize(
    ("linktype", "wrap"),
    [
        (1, _eth),
        (1, lambda ip: _eth(ip, vlan=True)),
        (101, lambda ip: ip),
        (12, lambda ip: ip),
        (113, _sll),
        (276, _sll2),
        (0, lambda ip: struct.pack("<I", 2 if ip[0] >> 4 == 4 else 30) + ip),
        (0, lambda ip: struct.pack(">I", 2 if ip[0] >> 4 == 4 else 24) + ip),
        (108, lambda ip: struct.pack(">I", 2 if ip[0] >> 4 == 4 else 28) + ip),
    ],
)
def test_link_types_in_pcap_and_pcapng(tmp_path: Path, linktype: int, wrap: object) -> None:
    frames = [wrap(v4()), wrap(v6())]  # type: ignore[operator]
    write_pcap(tmp_path / "a.pcap", linktype, frames)
    write_pcapng(tmp_path / "a.pcapng", linktype, frames)
    assert [d.payload for d in read_capture(tmp_path / "a.pcap").datagrams] == [PAYLOAD] * 2
    ng = read_capture(tmp_path / "a.pcapng").datagrams
    assert [d.payload for d in ng] == [PAYLOAD] * 3  # EPB, EPB, SPB


def test_ipv4_and_ipv6_only_link_types(tmp_path: Path) -> None:
    write_pcap(tmp_path / "4.pcap", 228, [v4()])
    write_pcap(tmp_path / "6.pcap", 229, [v6()])
    assert len(read_capture(tmp_path / "4.pcap").datagrams) == 1
    assert len(read_capture(tmp_path / "6.pcap").datagrams) == 1


@pytest.mark.parametrize("order", ["<", ">"])
def test_pcapng_ns_resolution_either_order(tmp_path: Path, order: str) -> None:
    p = tmp_path / "n.pcapng"
    write_pcapng(p, 101, [v4(), v4()], order=order, tsresol=9)
    cap = read_capture(p)
    assert [d.time_us for d in cap.datagrams[:2]] == [T, T + 1000]


def test_other_ports_and_protocols_skipped(tmp_path: Path) -> None:
    p = tmp_path / "o.pcap"
    tcpish = bytearray(v4())
    tcpish[9] = 6
    write_pcap(p, 101, [v4(dport=53), bytes(tcpish), v4()])
    cap = read_capture(p)
    assert len(cap.datagrams) == 1 and cap.packets == 3 and cap.other_packets == 2


def test_given_port_is_used(tmp_path: Path) -> None:
    p = tmp_path / "o.pcap"
    write_pcap(p, 101, [v4(dport=6000)])
    assert len(read_capture(p, port=6000).datagrams) == 1


def test_non_first_ipv4_fragment_skipped(tmp_path: Path) -> None:
    frag = bytearray(v4())
    frag[6:8] = struct.pack("!H", 0x0010)  # offset 16*8
    p = tmp_path / "f.pcap"
    write_pcap(p, 101, [bytes(frag), v4()])
    assert len(read_capture(p).datagrams) == 1


def test_no_rmcp_traffic_is_a_clear_error(tmp_path: Path) -> None:
    p = tmp_path / "none.pcap"
    write_pcap(p, 101, [v4(dport=53)])
    with pytest.raises(
        InputFileError, match=r"none.pcap: no UDP datagrams to port 50500 among 1 packets"
    ):
        read_capture(p)
    assert read_capture(p, allow_empty=True).datagrams == []


def test_bad_files_name_the_file(tmp_path: Path) -> None:
    p = tmp_path / "junk.pcap"
    p.write_bytes(b"hello world, not a capture")
    with pytest.raises(InputFileError, match="junk.pcap: not a pcap or pcapng file"):
        read_capture(p)
    with pytest.raises(InputFileError, match="missing.pcap: file not found"):
        read_capture(tmp_path / "missing.pcap")
    p.write_bytes(
        struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 101)
        + struct.pack("<IIII", 0, 0, 1 << 30, 0)
    )
    with pytest.raises(InputFileError, match="corrupt pcap"):
        read_capture(p)
