"""AppleMIDI session packets: the control protocol around RTP-MIDI.

Every control packet starts with the signature 0xFFFF and a two-letter
command.  Layouts (big-endian):

- ``IN`` invitation, ``OK`` accepted, ``NO`` rejected, ``BY`` end:
  signature, command, protocol version (u32, 2), initiator token (u32),
  SSRC (u32), then a UTF-8 name ended by NUL (optional; node-rtpmidi ends BY
  without the NUL, so the name runs to the end of the packet when none is there).
- ``CK`` clock synchronisation: signature, command, SSRC (u32), count (u8:
  0, 1, 2), 3 padding bytes, three u64 timestamps in 100 us ticks.
- ``RS`` receiver feedback: signature, command, SSRC (u32), the highest RTP
  sequence number received (u16), 2 padding bytes.
- ``RL`` bitrate receive limit: signature, command, SSRC (u32), limit (u32).

The initiator sends IN on the peer's control port, then on its data port
(control + 1); then CK0, answered CK1, closed by CK2 on the data port.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum

from virja.rtpmidi.errors import (
    BadSignatureError,
    BadVersionError,
    RtpMidiError,
    TruncatedError,
    UnknownCommandError,
)

SIGNATURE = 0xFFFF
PROTOCOL_VERSION = 2
MAX_NAME_BYTES = 256  # longer names are cut (Apple's are short; this bounds the state)

HEAD = struct.Struct("!HH")
SESSION = struct.Struct("!HHIII")  # signature, command, version, token, ssrc
SYNC = struct.Struct("!HHIB3xQQQ")  # signature, command, ssrc, count, pad, ts1..ts3
FEEDBACK = struct.Struct("!HHIH2x")  # signature, command, ssrc, seq, pad
LIMIT = struct.Struct("!HHII")  # signature, command, ssrc, limit
U64 = 1 << 64


class Command(IntEnum):
    IN = 0x494E  # invitation
    OK = 0x4F4B  # invitation accepted
    NO = 0x4E4F  # invitation rejected
    BY = 0x4259  # end of session
    CK = 0x434B  # clock synchronisation
    RS = 0x5253  # receiver feedback
    RL = 0x524C  # bitrate receive limit


SESSION_COMMANDS = frozenset({Command.IN, Command.OK, Command.NO, Command.BY})


def command_name(cmd: int) -> str:
    return Command(cmd).name if cmd in Command._value2member_map_ else f"0x{cmd:04X}"


def _need(data: bytes, size: int, what: str) -> None:
    if len(data) < size:
        raise TruncatedError(f"{what} truncated: {len(data)} of {size} bytes")


@dataclass(frozen=True, slots=True)
class SessionPacket:
    """IN, OK, NO or BY."""

    command: Command
    token: int
    ssrc: int
    name: str = ""
    version: int = PROTOCOL_VERSION

    @classmethod
    def parse(cls, data: bytes) -> SessionPacket:
        _need(data, SESSION.size, "session packet")
        _sig, cmd, version, token, ssrc = SESSION.unpack_from(data)
        if version != PROTOCOL_VERSION:
            raise BadVersionError(f"AppleMIDI protocol version {version}, expected 2")
        raw = data[SESSION.size :]
        end = raw.find(b"\x00")
        raw = raw if end < 0 else raw[:end]
        name = raw[:MAX_NAME_BYTES].decode("utf-8", errors="replace")
        return cls(Command(cmd), token, ssrc, name, version)

    def __bytes__(self) -> bytes:
        name = self.name.encode("utf-8")[:MAX_NAME_BYTES]
        head = SESSION.pack(SIGNATURE, self.command, self.version, self.token, self.ssrc)
        return head + name + b"\x00"


@dataclass(frozen=True, slots=True)
class SyncPacket:
    """CK: count 0 from the initiator, 1 the answer, 2 the initiator's close."""

    ssrc: int
    count: int
    timestamps: tuple[int, int, int]

    @classmethod
    def parse(cls, data: bytes) -> SyncPacket:
        _need(data, SYNC.size, "clock sync")
        _sig, _cmd, ssrc, count, t1, t2, t3 = SYNC.unpack_from(data)
        if count > 2:
            raise RtpMidiError(f"clock sync count {count}, expected 0-2")
        return cls(ssrc, count, (t1, t2, t3))

    def __bytes__(self) -> bytes:
        t1, t2, t3 = (t % U64 for t in self.timestamps)
        return SYNC.pack(SIGNATURE, Command.CK, self.ssrc, self.count, t1, t2, t3)


@dataclass(frozen=True, slots=True)
class FeedbackPacket:
    """RS: the receiver has everything up to ``seq``."""

    ssrc: int
    seq: int

    @classmethod
    def parse(cls, data: bytes) -> FeedbackPacket:
        # node-rtpmidi and Apple send 12 bytes; the last two are padding
        _need(data, FEEDBACK.size - 2, "receiver feedback")
        _sig, _cmd, ssrc, seq = struct.unpack_from("!HHIH", data)
        return cls(ssrc, seq)

    def __bytes__(self) -> bytes:
        return FEEDBACK.pack(SIGNATURE, Command.RS, self.ssrc, self.seq & 0xFFFF)


@dataclass(frozen=True, slots=True)
class LimitPacket:
    """RL: the peer asks for at most ``limit`` bits per second (noted, not needed)."""

    ssrc: int
    limit: int

    @classmethod
    def parse(cls, data: bytes) -> LimitPacket:
        _need(data, LIMIT.size, "bitrate limit")
        _sig, _cmd, ssrc, limit = LIMIT.unpack_from(data)
        return cls(ssrc, limit)

    def __bytes__(self) -> bytes:
        return LIMIT.pack(SIGNATURE, Command.RL, self.ssrc, self.limit)


ControlPacket = SessionPacket | SyncPacket | FeedbackPacket | LimitPacket


def is_control(data: bytes) -> bool:
    """Whether a datagram is an AppleMIDI control packet (signature 0xFFFF).

    An RTP packet starts with version bits 10, so its first byte is 0x80-0xBF:
    the two never collide."""
    return len(data) >= 2 and data[0] == 0xFF and data[1] == 0xFF


def parse_control(data: bytes) -> ControlPacket:
    """One control packet, or a typed error saying what is wrong."""
    _need(data, HEAD.size, "control packet")
    sig, cmd = HEAD.unpack_from(data)
    if sig != SIGNATURE:
        raise BadSignatureError(f"control signature 0x{sig:04X}, expected 0xFFFF")
    if cmd in SESSION_COMMANDS:
        return SessionPacket.parse(data)
    if cmd == Command.CK:
        return SyncPacket.parse(data)
    if cmd == Command.RS:
        return FeedbackPacket.parse(data)
    if cmd == Command.RL:
        return LimitPacket.parse(data)
    raise UnknownCommandError(f"unknown control command {command_name(cmd)}")


def packet_kind(pkt: ControlPacket) -> str:
    """The two-letter name counted in the host's statistics."""
    if isinstance(pkt, SessionPacket):
        return pkt.command.name
    if isinstance(pkt, SyncPacket):
        return f"CK{pkt.count}"
    return "RS" if isinstance(pkt, FeedbackPacket) else "RL"
