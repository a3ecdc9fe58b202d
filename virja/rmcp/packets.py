"""IPv4 / IPv6 + UDP packets, built for recordings and decoded from captures.

Building: :func:`udp_packet` makes an IP packet (IPv4 with a correct header
checksum, or IPv6) carrying one UDP datagram, UDP checksum included.
Decoding: :func:`udp_from_frame` takes one captured frame of a link type
(Ethernet with 802.1Q/802.1ad tags, raw IP, Linux cooked v1/v2, BSD loopback)
and returns the UDP datagram inside, or None for anything else.
"""

from __future__ import annotations

import ipaddress
import struct
from dataclasses import dataclass

IPV4 = struct.Struct("!BBHHHBBH4s4s")
IPV6 = struct.Struct("!IHBB16s16s")
UDP = struct.Struct("!HHHH")
PROTO_UDP = 17

ETH_IPV4 = 0x0800
ETH_IPV6 = 0x86DD
ETH_VLAN = (0x8100, 0x88A8, 0x9100)

# link types (tcpdump.org/linktypes.html): name -> value, the one table
LINKTYPE_NULL = 0
LINKTYPE_ETHERNET = 1
LINKTYPE_RAW = 101
LINKTYPE_DLT_RAW_12 = 12  # DLT_RAW as written by most BSDs
LINKTYPE_DLT_RAW_14 = 14  # DLT_RAW as written by OpenBSD
LINKTYPE_LOOP = 108
LINKTYPE_LINUX_SLL = 113
LINKTYPE_IPV4 = 228
LINKTYPE_IPV6 = 229
LINKTYPE_LINUX_SLL2 = 276

# BSD loopback address families: AF_INET is 2 everywhere, AF_INET6 differs
AF_INET = 2
AF_INET6_VALUES = frozenset({10, 24, 28, 30})  # Linux, NetBSD/OpenBSD, FreeBSD, macOS


@dataclass(frozen=True, slots=True)
class UdpDatagram:
    """A UDP datagram found in a frame: addresses as strings, ports, payload."""

    src: str
    sport: int
    dst: str
    dport: int
    payload: bytes


def ipv4_checksum(header: bytes) -> int:
    """The one's-complement sum used by IPv4 and UDP checksums."""
    if len(header) % 2:
        header += b"\0"
    total = sum(struct.unpack(f"!{len(header) // 2}H", header))
    while total >> 16:
        total = (total & 0xFFFF) + (total >> 16)
    return ~total & 0xFFFF


def _udp(
    src: bytes, dst: bytes, sport: int, dport: int, payload: bytes, pseudo_tail: bytes
) -> bytes:
    length = UDP.size + len(payload)
    head = UDP.pack(sport, dport, length, 0)
    csum = ipv4_checksum(src + dst + pseudo_tail + head + payload) or 0xFFFF
    return UDP.pack(sport, dport, length, csum) + payload


def udp_packet(src: str, sport: int, dst: str, dport: int, payload: bytes, ident: int = 0) -> bytes:
    """An IPv4 or IPv6 packet (by the source address family) carrying ``payload``.

    An IPv4-mapped IPv6 source is written as IPv4; a destination of the other
    family is replaced by the unspecified address of the source's family.
    """
    s = ipaddress.ip_address(src.split("%", 1)[0])
    if isinstance(s, ipaddress.IPv6Address) and s.ipv4_mapped is not None:
        s = s.ipv4_mapped
    try:
        d: ipaddress.IPv4Address | ipaddress.IPv6Address = ipaddress.ip_address(
            dst.split("%", 1)[0]
        )
    except ValueError:
        d = ipaddress.ip_address("0.0.0.0" if s.version == 4 else "::")
    if isinstance(d, ipaddress.IPv6Address) and d.ipv4_mapped is not None:
        d = d.ipv4_mapped
    if d.version != s.version:
        d = ipaddress.ip_address("0.0.0.0" if s.version == 4 else "::")
    if s.version == 4:
        udp_len = UDP.size + len(payload)
        udp = _udp(
            s.packed, d.packed, sport, dport, payload, struct.pack("!BBH", 0, PROTO_UDP, udp_len)
        )
        total = IPV4.size + len(udp)
        head = IPV4.pack(
            0x45, 0, total, ident & 0xFFFF, 0x4000, 64, PROTO_UDP, 0, s.packed, d.packed
        )
        csum = ipv4_checksum(head)
        return head[:10] + struct.pack("!H", csum) + head[12:] + udp
    udp_len = UDP.size + len(payload)
    udp = _udp(s.packed, d.packed, sport, dport, payload, struct.pack("!IxxxB", udp_len, PROTO_UDP))
    head = IPV6.pack(6 << 28, len(udp), PROTO_UDP, 64, s.packed, d.packed)
    return head + udp


def _udp_in(src: str, dst: str, seg: bytes) -> UdpDatagram | None:
    if len(seg) < UDP.size:
        return None
    sport, dport, length, _ = UDP.unpack_from(seg)
    end = min(len(seg), length) if length >= UDP.size else len(seg)
    return UdpDatagram(src, sport, dst, dport, bytes(seg[UDP.size : end]))


def udp_from_ipv4(pkt: bytes) -> UdpDatagram | None:
    """The UDP datagram of an IPv4 packet; None for other protocols and non-first fragments.

    A first fragment yields what it holds (a truncated datagram the receiver
    will count as bad_length); fragments are not reassembled.
    """
    if len(pkt) < IPV4.size or pkt[0] >> 4 != 4:
        return None
    vihl, _, total, _, frag, _, proto, _, src, dst = IPV4.unpack_from(pkt)
    ihl = (vihl & 0x0F) * 4
    if proto != PROTO_UDP or ihl < IPV4.size or frag & 0x1FFF:
        return None
    end = min(len(pkt), total) if total >= ihl else len(pkt)
    return _udp_in(str(ipaddress.IPv4Address(src)), str(ipaddress.IPv4Address(dst)), pkt[ihl:end])


_IPV6_EXT = frozenset({0, 43, 60})  # hop-by-hop, routing, destination options


def udp_from_ipv6(pkt: bytes) -> UdpDatagram | None:
    """The UDP datagram of an IPv6 packet, past hop-by-hop/routing/dest-opts/fragment headers."""
    if len(pkt) < IPV6.size or pkt[0] >> 4 != 6:
        return None
    _, plen, nxt, _, src, dst = IPV6.unpack_from(pkt)
    end = min(len(pkt), IPV6.size + plen) if plen else len(pkt)
    off = IPV6.size
    for _ in range(8):  # bounded walk of extension headers
        if nxt == PROTO_UDP:
            return _udp_in(
                str(ipaddress.IPv6Address(src)), str(ipaddress.IPv6Address(dst)), pkt[off:end]
            )
        if off + 8 > end:
            return None
        if nxt in _IPV6_EXT:
            nxt, hlen = pkt[off], (pkt[off + 1] + 1) * 8
        elif nxt == 44:  # fragment
            if struct.unpack_from("!H", pkt, off + 2)[0] & 0xFFF8:
                return None
            nxt, hlen = pkt[off], 8
        else:
            return None
        off += hlen
    return None


def udp_from_ip(pkt: bytes) -> UdpDatagram | None:
    """IPv4 or IPv6 by the version nibble."""
    if not pkt:
        return None
    version = pkt[0] >> 4
    if version == 4:
        return udp_from_ipv4(pkt)
    if version == 6:
        return udp_from_ipv6(pkt)
    return None


def _by_ethertype(ethertype: int, pkt: bytes) -> UdpDatagram | None:
    if ethertype == ETH_IPV4:
        return udp_from_ipv4(pkt)
    if ethertype == ETH_IPV6:
        return udp_from_ipv6(pkt)
    return None


def _ethernet(frame: bytes) -> UdpDatagram | None:
    off = 12
    for _ in range(4):  # up to three stacked VLAN tags
        if len(frame) < off + 2:
            return None
        ethertype = struct.unpack_from("!H", frame, off)[0]
        if ethertype in ETH_VLAN:
            off += 4
            continue
        return _by_ethertype(ethertype, frame[off + 2 :])
    return None


def _loopback(frame: bytes, big_endian_only: bool) -> UdpDatagram | None:
    if len(frame) < 4:
        return None
    families = {int.from_bytes(frame[:4], "big")}
    if not big_endian_only:  # DLT_NULL: host byte order of the capturing machine
        families.add(int.from_bytes(frame[:4], "little"))
    if AF_INET in families:
        return udp_from_ipv4(frame[4:])
    if families & AF_INET6_VALUES:
        return udp_from_ipv6(frame[4:])
    return None


def _sll(frame: bytes) -> UdpDatagram | None:
    if len(frame) < 16:
        return None
    return _by_ethertype(struct.unpack_from("!H", frame, 14)[0], frame[16:])


def _sll2(frame: bytes) -> UdpDatagram | None:
    if len(frame) < 20:
        return None
    return _by_ethertype(struct.unpack_from("!H", frame, 0)[0], frame[20:])


SUPPORTED_LINKTYPES: frozenset[int] = frozenset(
    {
        LINKTYPE_NULL,
        LINKTYPE_ETHERNET,
        LINKTYPE_RAW,
        LINKTYPE_DLT_RAW_12,
        LINKTYPE_DLT_RAW_14,
        LINKTYPE_LOOP,
        LINKTYPE_LINUX_SLL,
        LINKTYPE_IPV4,
        LINKTYPE_IPV6,
        LINKTYPE_LINUX_SLL2,
    }
)


def udp_from_frame(linktype: int, frame: bytes) -> UdpDatagram | None:
    """The UDP datagram in one captured frame of ``linktype``, or None."""
    if linktype == LINKTYPE_ETHERNET:
        return _ethernet(frame)
    if linktype in (LINKTYPE_RAW, LINKTYPE_DLT_RAW_12, LINKTYPE_DLT_RAW_14):
        return udp_from_ip(frame)
    if linktype == LINKTYPE_IPV4:
        return udp_from_ipv4(frame)
    if linktype == LINKTYPE_IPV6:
        return udp_from_ipv6(frame)
    if linktype == LINKTYPE_LINUX_SLL:
        return _sll(frame)
    if linktype == LINKTYPE_LINUX_SLL2:
        return _sll2(frame)
    if linktype == LINKTYPE_NULL:
        return _loopback(frame, big_endian_only=False)
    if linktype == LINKTYPE_LOOP:
        return _loopback(frame, big_endian_only=True)
    return None
