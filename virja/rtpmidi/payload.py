"""RTP packets carrying MIDI (RFC 6295): the RTP header and the MIDI command section.

An RTP-MIDI data packet is a 12-byte RTP header (version 2; CSRCs, a header
extension and padding are allowed and skipped), then the MIDI command
section: a header byte ``B J Z P LEN`` (with B set, LEN has 12 bits and takes
a second byte), then LEN bytes of MIDI list: ``[delta] command [delta command]
...``.  Delta times are 1-4 byte variable-length numbers in clock ticks
(10 kHz for AppleMIDI), each relative to the command before (the first to the
packet's RTP timestamp; Z says whether the first has one).  Commands may use
running status (not the first: RFC 6295 section 3.2 requires its status
byte; P only says whether the source stream had it).  System exclusive comes
whole (F0 .. F7) or in segments (F0 .. F0, F7 .. F0, F7 .. F7, cancelled by
F4); realtime bytes (F8-FF) may sit inside it.  System messages cancel running
status, realtime ones do not.

After the command section, when J is set, comes the recovery journal.  It is
not read: virja plays notes as they arrive, and the journal's use is to
repair the *state* of a receiver after a lost packet (a held note or a
controller value); a note-on it recovers is already past its time, and a
drawn stroke has no state to repair.  Its presence is counted.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from virja.midispec import data_len
from virja.rtpmidi.errors import BadCommandSectionError, BadVersionError, TruncatedError

RTP_HEADER = struct.Struct("!BBHII")  # V P X CC, M PT, seq, timestamp, ssrc
PAYLOAD_TYPE = 0x61  # 97, the dynamic type Apple and node-rtpmidi use

FLAG_B, FLAG_J, FLAG_Z, FLAG_P = 0x80, 0x40, 0x20, 0x10

# data bytes after each channel status (high nibble) and system common status
SYSTEM_DATA_LEN = {0xF1: 1, 0xF2: 2, 0xF3: 1, 0xF4: 0, 0xF5: 0, 0xF6: 0}
SYSEX_START, SYSEX_END, SYSEX_CANCEL = 0xF0, 0xF7, 0xF4
SYSEX_ENDINGS = frozenset({SYSEX_START, SYSEX_END, SYSEX_CANCEL})


@dataclass(frozen=True, slots=True)
class RtpHeader:
    seq: int
    timestamp: int
    ssrc: int
    payload_type: int = PAYLOAD_TYPE
    marker: bool = False

    @staticmethod
    def split(data: bytes) -> tuple[RtpHeader, bytes]:
        """The header and the payload (CSRCs, extension and padding removed)."""
        if len(data) < RTP_HEADER.size:
            raise TruncatedError(f"RTP header truncated: {len(data)} of 12 bytes")
        b0, b1, seq, ts, ssrc = RTP_HEADER.unpack_from(data)
        if b0 >> 6 != 2:
            raise BadVersionError(f"RTP version {b0 >> 6}, expected 2")
        end = len(data)
        if b0 & 0x20:  # padding: the last byte counts the padding bytes
            pad = data[-1]
            if pad == 0 or pad > end - RTP_HEADER.size:
                raise TruncatedError(f"RTP padding of {pad} bytes does not fit")
            end -= pad
        off = RTP_HEADER.size + 4 * (b0 & 0x0F)
        if b0 & 0x10:
            if off + 4 > end:
                raise TruncatedError("RTP header extension truncated")
            (words,) = struct.unpack_from("!H", data, off + 2)
            off += 4 + 4 * words
        if off > end:
            raise TruncatedError(f"RTP header of {off} bytes in a packet of {end}")
        header = RtpHeader(seq, ts, ssrc, b1 & 0x7F, bool(b1 & 0x80))
        return header, data[off:end]

    def __bytes__(self) -> bytes:
        b1 = self.payload_type | (0x80 if self.marker else 0)
        return RTP_HEADER.pack(0x80, b1, self.seq & 0xFFFF, self.timestamp & 0xFFFF_FFFF, self.ssrc)


@dataclass(frozen=True, slots=True)
class MidiCommand:
    """One command of the list: ``delta`` ticks after the one before, its bytes
    (the status byte always included, also where the wire used running status)."""

    delta: int
    data: bytes

    @property
    def is_sysex(self) -> bool:
        return self.data[0] in (SYSEX_START, SYSEX_END)


@dataclass(frozen=True, slots=True)
class MidiPacket:
    header: RtpHeader
    commands: tuple[MidiCommand, ...]
    journal: bool = False

    @classmethod
    def parse(cls, data: bytes) -> MidiPacket:
        header, payload = RtpHeader.split(data)
        commands, journal = parse_command_section(payload)
        return cls(header, commands, journal)

    def __bytes__(self) -> bytes:
        return bytes(self.header) + encode_command_section(self.commands)

    def offsets(self) -> list[tuple[int, MidiCommand]]:
        """Each command with its time after the packet's timestamp, in ticks."""
        out = []
        t = 0
        for c in self.commands:
            t += c.delta
            out.append((t, c))
        return out


def _delta(section: bytes, pos: int) -> tuple[int, int]:
    value = 0
    for k in range(4):
        if pos + k >= len(section):
            raise TruncatedError(f"delta time at offset {pos} runs past the MIDI list")
        b = section[pos + k]
        value = (value << 7) | (b & 0x7F)
        if not b & 0x80:
            return value, pos + k + 1
    raise BadCommandSectionError(f"delta time at offset {pos} longer than 4 bytes")


def _data_bytes(section: bytes, pos: int, need: int, status: int) -> int:
    end = pos + need
    if end > len(section):
        raise TruncatedError(
            f"MIDI command 0x{status:02X} truncated: {len(section) - pos} of {need} data bytes"
        )
    for j in range(pos, end):
        if section[j] > 0x7F:
            raise BadCommandSectionError(
                f"MIDI command 0x{status:02X}: status byte 0x{section[j]:02X} where data belongs"
            )
    return end


def _sysex_end(section: bytes, pos: int) -> int:
    """The index after the byte that ends a SysEx segment starting at ``pos``."""
    for j in range(pos + 1, len(section)):
        b = section[j]
        if b in SYSEX_ENDINGS:
            return j + 1
        if 0x80 <= b < 0xF8:  # realtime bytes (F8-FF) may be embedded; nothing else
            raise BadCommandSectionError(
                f"system exclusive at offset {pos}: status 0x{b:02X} inside it"
            )
    raise TruncatedError(f"system exclusive at offset {pos} has no end (F0, F7 or F4)")


def parse_command_section(payload: bytes) -> tuple[tuple[MidiCommand, ...], bool]:
    """The commands of an RTP-MIDI payload and whether a journal follows them."""
    if not payload:
        raise TruncatedError("RTP-MIDI payload is empty")
    flags = payload[0]
    if flags & FLAG_B:
        if len(payload) < 2:
            raise TruncatedError("MIDI command section header truncated: 1 of 2 bytes")
        length, start = ((flags & 0x0F) << 8) | payload[1], 2
    else:
        length, start = flags & 0x0F, 1
    if start + length > len(payload):
        raise TruncatedError(f"MIDI list truncated: {len(payload) - start} of {length} bytes")
    section = payload[start : start + length]
    commands: list[MidiCommand] = []
    running: int | None = None
    pos = 0
    while pos < len(section):
        delta = 0
        if commands or flags & FLAG_Z:
            delta, pos = _delta(section, pos)
            if pos >= len(section):
                raise TruncatedError("MIDI list ends with a delta time and no command")
        b = section[pos]
        if b >= 0x80:
            status, pos = b, pos + 1
        elif running is None:
            where = "the first command" if not commands else f"offset {pos}"
            raise BadCommandSectionError(
                f"data byte 0x{b:02X} at {where} with no status byte (no running status)"
            )
        else:
            status = running
        if status < 0xF0:
            running = status
            begin = pos
            pos = _data_bytes(section, pos, data_len(status), status)
            commands.append(MidiCommand(delta, bytes([status]) + section[begin:pos]))
        elif status in (SYSEX_START, SYSEX_END):
            running = None
            end = _sysex_end(section, pos - 1)
            commands.append(MidiCommand(delta, section[pos - 1 : end]))
            pos = end
        elif status < 0xF8:
            running = None
            begin = pos
            pos = _data_bytes(section, pos, SYSTEM_DATA_LEN[status], status)
            commands.append(MidiCommand(delta, bytes([status]) + section[begin:pos]))
        else:
            commands.append(MidiCommand(delta, bytes([status])))
    return tuple(commands), bool(flags & FLAG_J)


def _vlq(value: int) -> bytes:
    if not 0 <= value < 1 << 28:
        raise ValueError(f"delta time {value} outside 0 .. 2^28 - 1")
    out = [value & 0x7F]
    value >>= 7
    while value:
        out.append(0x80 | (value & 0x7F))
        value >>= 7
    return bytes(reversed(out))


def encode_command_section(commands: tuple[MidiCommand, ...] | list[MidiCommand]) -> bytes:
    """The command section for ``commands`` (running status where it applies; no journal)."""
    body = bytearray()
    running: int | None = None
    z = bool(commands) and commands[0].delta != 0
    for i, c in enumerate(commands):
        if i or z:
            body += _vlq(c.delta)
        status = c.data[0]
        if status < 0xF0 and status == running and i:
            body += c.data[1:]
        else:
            body += c.data
        if status < 0xF0:
            running = status
        elif status < 0xF8:
            running = None
    if len(body) > 0xFFF:
        raise ValueError(f"MIDI list of {len(body)} bytes (at most 4095)")
    flags = FLAG_Z if z else 0
    if len(body) > 0x0F:
        return bytes([FLAG_B | flags | (len(body) >> 8), len(body) & 0xFF]) + body
    return bytes([flags | len(body)]) + body


def midi_packet(
    ssrc: int, seq: int, timestamp: int, *commands: tuple[int, bytes | list[int]]
) -> bytes:
    """An RTP-MIDI packet of ``(delta_ticks, message)`` pairs (tests, tools)."""
    cmds = [MidiCommand(d, bytes(m)) for d, m in commands]
    return bytes(MidiPacket(RtpHeader(seq, timestamp, ssrc), tuple(cmds)))
