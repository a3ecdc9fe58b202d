"""Recordings: classic pcap written, classic pcap and pcapng read.

:class:`PcapWriter` writes one record per datagram received (LINKTYPE_RAW,
IPv4 or IPv6 + UDP keeping the sender's address and port, stamped with the
receive time) and flushes at least every ``flush_interval_s`` of the times it
is given, so a killed process leaves a readable file.

:func:`read_capture` reads classic pcap (µs and ns, either byte order) and
pcapng (SHB/IDB/EPB/SPB/obsolete PB, per-interface link type and timestamp
resolution, either byte order) and keeps the UDP payloads sent to the RMCP
port.  A truncated last record is read up to the last complete one with a
warning; a malformed file raises InputFileError naming it.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

from virja.errors import InputFileError
from virja.rmcp import DEFAULT_PORT
from virja.rmcp.packets import LINKTYPE_RAW, SUPPORTED_LINKTYPES, udp_from_frame, udp_packet

log = logging.getLogger(__name__)

PCAP_MAGIC_US = 0xA1B2C3D4
PCAP_MAGIC_NS = 0xA1B23C4D
PCAP_HEADER = struct.Struct("<IHHiIII")  # magic, major, minor, thiszone, sigfigs, snaplen, network
PCAP_RECORD = struct.Struct("<IIII")  # ts_sec, ts_frac, incl_len, orig_len
SNAPLEN = 65535
MAX_RECORD = 1 << 24  # a record claiming more than 16 MiB means a corrupt file

PCAPNG_SHB = 0x0A0D0D0A
PCAPNG_BOM = 0x1A2B3C4D
PCAPNG_IDB = 1
PCAPNG_PB = 2  # obsolete Packet Block
PCAPNG_SPB = 3
PCAPNG_EPB = 6
OPT_IF_TSRESOL = 9
OPT_IF_TSOFFSET = 14


@dataclass(frozen=True, slots=True)
class CapturedDatagram:
    """One UDP payload of a capture with its capture time (µs) and addresses."""

    time_us: int
    src: tuple[str, int]
    dst: tuple[str, int]
    payload: bytes


@dataclass
class Capture:
    """What a capture file held: the RMCP-port datagrams, and counts of the rest."""

    path: str
    datagrams: list[CapturedDatagram] = field(default_factory=list)
    packets: int = 0
    other_packets: int = 0
    warnings: list[str] = field(default_factory=list)


# -- writing ------------------------------------------------------------------


class PcapWriter:
    """Classic pcap (µs, little-endian, LINKTYPE_RAW) of received datagrams.

    ``local`` is the (host, port) the datagrams were received on, written as
    the destination.  Call :meth:`tick` with the current time when idle so the
    buffer is flushed within ``flush_interval_s`` even without traffic.

    A write that fails (a full disk, an I/O error) never reaches the caller: the
    recording stops there, ``failed`` says why (logged once as a warning), and
    the file is cut back to the last record that was flushed whole, so it stays
    readable.  A time that does not fit a pcap record (before 1970 or after
    2106) skips that datagram.
    """

    def __init__(
        self, stream: BinaryIO, *, local: tuple[str, int], flush_interval_s: float = 0.1
    ) -> None:
        self._stream = stream
        self._local = local
        self._flush_us = round(flush_interval_s * 1_000_000)
        self._last_flush_us: int | None = None
        self._dirty = False
        self._ident = 0
        self._written = 0  # bytes handed to the stream
        self._flushed = 0  # of those, the bytes known to be in the file (whole records)
        self.failed: str | None = None
        self.skipped = 0
        stream.write(PCAP_HEADER.pack(PCAP_MAGIC_US, 2, 4, 0, 0, SNAPLEN, LINKTYPE_RAW))
        stream.flush()
        self._written = self._flushed = PCAP_HEADER.size

    @classmethod
    def open(cls, path: str | Path, *, local: tuple[str, int]) -> PcapWriter:
        try:
            stream = open(path, "wb")  # noqa: SIM115 - closed by close()
        except OSError as exc:
            raise InputFileError(path, f"cannot write recording: {exc.strerror or exc}") from None
        try:
            return cls(stream, local=local)
        except OSError as exc:
            stream.close()
            raise InputFileError(path, f"cannot write recording: {exc.strerror or exc}") from None

    @classmethod
    def for_listener(cls, path: str | Path, bound: tuple[Any, ...]) -> PcapWriter:
        """A recording of what a socket bound to ``bound`` (its ``getsockname()``)
        receives: the packets name the address and port actually bound (port 0 picks
        one; a wildcard address is written as the loopback of its family)."""
        host, port = str(bound[0]), int(bound[1])
        if host in ("0.0.0.0", "::"):
            host = "::1" if ":" in host else "127.0.0.1"
        return cls.open(path, local=(host, port))

    def write(
        self,
        payload: bytes,
        src: tuple[str, int] | tuple[str, int, int, int],
        *,
        time_us: int,
        dst: tuple[str, int] | None = None,
    ) -> None:
        """Append one received datagram from ``src`` stamped ``time_us``
        (received on ``dst``, by default the writer's ``local`` address)."""
        if self.failed is not None:
            return
        self._ident = (self._ident + 1) & 0xFFFF
        to = self._local if dst is None else dst
        try:
            pkt = udp_packet(src[0], src[1], to[0], to[1], payload, self._ident)
        except ValueError:  # a source that is not an IP address (never from UDP)
            log.warning("not recording a datagram from non-IP source %r", src)
            return
        sec, usec = divmod(time_us, 1_000_000)
        try:
            record = PCAP_RECORD.pack(sec, usec, len(pkt), len(pkt)) + pkt
        except struct.error:
            self.skipped += 1
            return
        try:
            self._stream.write(record)
        except (OSError, ValueError) as exc:
            self._fail(exc)
            return
        self._written += len(record)
        self._dirty = True
        self.tick(time_us)

    def tick(self, now_us: int) -> None:
        """Flush if the last flush is ``flush_interval_s`` old."""
        if self._last_flush_us is None:
            self._last_flush_us = now_us
        if self._dirty and now_us - self._last_flush_us >= self._flush_us:
            self.flush()
            self._last_flush_us = now_us

    def flush(self) -> None:
        if self.failed is not None:
            return
        try:
            self._stream.flush()
        except (OSError, ValueError) as exc:
            self._fail(exc)
            return
        self._flushed = self._written
        self._dirty = False

    def _fail(self, exc: Exception) -> None:
        """Stop recording: report once, cut the file back to whole records, close it."""
        reason = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
        self.failed = reason
        log.warning(
            "recording stopped: %s (kept %d bytes of whole records; receiving goes on)",
            reason,
            self._flushed,
        )
        fd = None
        with contextlib.suppress(OSError, ValueError, AttributeError, io.UnsupportedOperation):
            fd = os.dup(self._stream.fileno())
        with contextlib.suppress(OSError, ValueError):
            self._stream.close()  # its flush may fail again; the file is closed anyway
        if fd is not None:
            with contextlib.suppress(OSError):
                os.ftruncate(fd, self._flushed)
            os.close(fd)

    def close(self) -> None:
        if self.failed is not None:
            return
        self.flush()
        if self.failed is None:
            with contextlib.suppress(OSError, ValueError):
                self._stream.close()

    def __enter__(self) -> PcapWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# -- reading ------------------------------------------------------------------

Frame = tuple[int, int, bytes]  # time_us, linktype, frame bytes


def _classic(path: str, data: bytes, cap: Capture) -> Iterator[Frame]:
    if len(data) < PCAP_HEADER.size:
        raise InputFileError(path, "pcap file header truncated")
    magic_le = struct.unpack_from("<I", data)[0]
    magic_be = struct.unpack_from(">I", data)[0]
    if magic_le in (PCAP_MAGIC_US, PCAP_MAGIC_NS):
        order, magic = "<", magic_le
    else:
        order, magic = ">", magic_be
    network = struct.unpack_from(order + "I", data, 20)[0]
    linktype = network & 0xFFFF  # upper bits: FCS length information
    frac_per_us = 1000 if magic == PCAP_MAGIC_NS else 1
    rec = struct.Struct(order + "IIII")
    off = PCAP_HEADER.size
    while off < len(data):
        if off + rec.size > len(data):
            cap.warnings.append(f"truncated record header at byte {off}; read up to it")
            return
        sec, frac, incl, _ = rec.unpack_from(data, off)
        if incl > MAX_RECORD:
            raise InputFileError(path, f"corrupt pcap: record at byte {off} claims {incl} bytes")
        start = off + rec.size
        if start + incl > len(data):
            cap.warnings.append(
                f"truncated last record at byte {off}: {len(data) - start} of {incl} bytes; "
                "read up to it"
            )
            return
        yield sec * 1_000_000 + frac // frac_per_us, linktype, data[start : start + incl]
        off = start + incl


@dataclass
class _Iface:
    linktype: int
    units_per_s: int = 1_000_000
    offset_s: int = 0


def _tsresol(value: int) -> int:
    return 2 ** (value & 0x7F) if value & 0x80 else 10 ** (value & 0x7F)


def _idb(path: str, order: str, body: bytes, at: int) -> _Iface:
    """The interface an IDB body describes; ``at`` is the block's byte offset (for errors).

    Every option's value must lie inside the block: an option that claims more
    bytes than are left, or an if_tsresol/if_tsoffset of the wrong length, is a
    corrupt file.
    """
    linktype = struct.unpack_from(order + "H", body)[0]
    iface = _Iface(linktype)
    off = 8
    while off + 4 <= len(body):
        code, length = struct.unpack_from(order + "HH", body, off)
        if code == 0:
            break
        start = off + 4
        if start + length > len(body):
            raise InputFileError(
                path,
                f"corrupt pcapng: interface block at byte {at}: option {code} claims "
                f"{length} bytes, {len(body) - start} left in the block",
            )
        val = body[start : start + length]
        if code == OPT_IF_TSRESOL:
            if length != 1:
                raise InputFileError(
                    path,
                    f"corrupt pcapng: interface block at byte {at}: if_tsresol has "
                    f"{length} bytes, not 1",
                )
            iface.units_per_s = _tsresol(val[0])
        elif code == OPT_IF_TSOFFSET:
            if length != 8:
                raise InputFileError(
                    path,
                    f"corrupt pcapng: interface block at byte {at}: if_tsoffset has "
                    f"{length} bytes, not 8",
                )
            iface.offset_s = struct.unpack(order + "q", val)[0]
        off = start + (length + 3) // 4 * 4
    return iface


def _ts_us(iface: _Iface, high: int, low: int) -> int:
    ts = (high << 32) | low
    return iface.offset_s * 1_000_000 + ts * 1_000_000 // iface.units_per_s


def _pcapng(path: str, data: bytes, cap: Capture) -> Iterator[Frame]:
    order = "<"
    ifaces: list[_Iface] = []
    last_us = 0
    off = 0
    while off < len(data):
        if off + 12 > len(data):
            cap.warnings.append(f"truncated block at byte {off}; read up to it")
            return
        btype = struct.unpack_from(order + "I", data, off)[0]
        if btype == PCAPNG_SHB:
            bom = data[off + 8 : off + 12]
            if bom == b"\x1a\x2b\x3c\x4d":
                order = ">"
            elif bom == b"\x4d\x3c\x2b\x1a":
                order = "<"
            else:
                raise InputFileError(path, f"corrupt pcapng: bad byte-order magic at byte {off}")
            ifaces = []
        blen = struct.unpack_from(order + "I", data, off + 4)[0]
        if blen < 12 or blen % 4 or blen > MAX_RECORD:
            raise InputFileError(path, f"corrupt pcapng: block at byte {off} has length {blen}")
        if off + blen > len(data):
            cap.warnings.append(
                f"truncated last block at byte {off}: {len(data) - off} of {blen} bytes; "
                "read up to it"
            )
            return
        body = data[off + 8 : off + blen - 4]
        btype = struct.unpack_from(order + "I", data, off)[0]
        if btype == PCAPNG_IDB and len(body) >= 8:
            ifaces.append(_idb(path, order, body, off))
        elif btype == PCAPNG_EPB and len(body) >= 20:
            if_id, high, low, caplen, _ = struct.unpack_from(order + "IIIII", body)
            if if_id >= len(ifaces):
                raise InputFileError(path, f"corrupt pcapng: packet of unknown interface {if_id}")
            last_us = _ts_us(ifaces[if_id], high, low)
            yield last_us, ifaces[if_id].linktype, body[20 : 20 + caplen]
        elif btype == PCAPNG_PB and len(body) >= 20:
            if_id, _, high, low, caplen, _ = struct.unpack_from(order + "HHIIII", body)
            if if_id >= len(ifaces):
                raise InputFileError(path, f"corrupt pcapng: packet of unknown interface {if_id}")
            last_us = _ts_us(ifaces[if_id], high, low)
            yield last_us, ifaces[if_id].linktype, body[20 : 20 + caplen]
        elif btype == PCAPNG_SPB and len(body) >= 4:
            if not ifaces:
                raise InputFileError(path, "corrupt pcapng: simple packet before any interface")
            orig = struct.unpack_from(order + "I", body)[0]
            # no time stamp in an SPB: it takes the previous packet's time
            yield last_us, ifaces[0].linktype, body[4 : 4 + orig]
        off += blen


def read_capture(
    path: str | Path, *, port: int | None = DEFAULT_PORT, allow_empty: bool = False
) -> Capture:
    """The UDP datagrams to ``port`` (None: to any port) in a pcap or pcapng file, in file order.

    Raises InputFileError for unreadable, unknown or corrupt files, and, unless
    ``allow_empty``, when no datagram was sent to ``port``.
    """
    name = str(path)
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        raise InputFileError(name, "file not found") from None
    except OSError as exc:
        raise InputFileError(name, f"cannot read: {exc.strerror or exc}") from None
    if len(data) < 4:
        raise InputFileError(name, "not a pcap or pcapng file (too short)")
    cap = Capture(name)
    head_le = struct.unpack_from("<I", data)[0]
    head_be = struct.unpack_from(">I", data)[0]
    if head_le == PCAPNG_SHB:
        frames = _pcapng(name, data, cap)
    elif PCAP_MAGIC_US in (head_le, head_be) or PCAP_MAGIC_NS in (head_le, head_be):
        frames = _classic(name, data, cap)
    else:
        raise InputFileError(name, "not a pcap or pcapng file (unknown magic number)")
    unsupported: set[int] = set()
    for time_us, linktype, frame in frames:
        cap.packets += 1
        if linktype not in SUPPORTED_LINKTYPES:
            unsupported.add(linktype)
            cap.other_packets += 1
            continue
        udp = udp_from_frame(linktype, frame)
        if udp is None or (port is not None and udp.dport != port):
            cap.other_packets += 1
            continue
        cap.datagrams.append(
            CapturedDatagram(time_us, (udp.src, udp.sport), (udp.dst, udp.dport), udp.payload)
        )
    for lt in sorted(unsupported):
        cap.warnings.append(f"skipped packets of unsupported link type {lt}")
    for w in cap.warnings:
        log.warning("%s: %s", name, w)
    if not cap.datagrams and not allow_empty:
        raise InputFileError(
            name, f"no UDP datagrams to port {port} among {cap.packets} packets (wrong --port?)"
        )
    return cap
