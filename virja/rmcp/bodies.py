"""RMCP/1 message bodies, one frozen dataclass per kind (docs/rmcp.md).

Each body has ``parse(data)`` (raises :class:`~virja.rmcp.errors.BadBodyError`
naming what is wrong) and ``__bytes__``; ``parse(bytes(b)) == b``.  The MIDI
body is validated exactly as the spec says: complete channel voice messages
and terminated system exclusive, no running status, nothing else.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum
from typing import ClassVar

from virja.midispec import data_len
from virja.rmcp.errors import BadBodyError


class Kind(IntEnum):
    """The ``kind`` header byte."""

    MIDI = 1
    BEAT = 2
    CHORD = 3
    CLOCK_REQUEST = 16
    CLOCK_REPLY = 17


BEAT_BODY = struct.Struct("!IBBBBI")  # bar, beat, beats_per_bar, level, reserved, tempo_us
CHORD_HEAD = struct.Struct("!BBB")  # root, bass, n
CLOCK_REQUEST_BODY = struct.Struct("!Iq")  # nonce, t0
CLOCK_REPLY_BODY = struct.Struct("!Iqqq")  # nonce, t0, t1, t2

SYSEX_START = 0xF0
SYSEX_END = 0xF7
BASS_SAME_AS_ROOT = 255


def _exact(name: str, data: bytes, size: int) -> None:
    if len(data) != size:
        raise BadBodyError(f"{name} body must be {size} bytes, got {len(data)}")


def split_midi(data: bytes) -> tuple[bytes, ...]:
    """Split a MIDI body into its messages, or raise BadBodyError saying why."""
    if not data:
        raise BadBodyError("MIDI body is empty")
    out: list[bytes] = []
    i = 0
    n = len(data)
    while i < n:
        status = data[i]
        if status < 0x80:
            raise BadBodyError(
                f"data byte 0x{status:02X} at offset {i} without a status byte "
                "(running status is not allowed)"
            )
        if status < 0xF0:
            need = data_len(status)  # the one table (virja.midispec)
            end = i + 1 + need
            if end > n:
                raise BadBodyError(
                    f"MIDI message 0x{status:02X} at offset {i} truncated: "
                    f"{n - i - 1} of {need} data bytes"
                )
            for j in range(i + 1, end):
                if data[j] > 0x7F:
                    raise BadBodyError(
                        f"MIDI message 0x{status:02X} at offset {i}: data byte "
                        f"0x{data[j]:02X} at offset {j} above 127"
                    )
            out.append(data[i:end])
            i = end
        elif status == SYSEX_START:
            j = i + 1
            while j < n and data[j] < 0x80:
                j += 1
            if j >= n:
                raise BadBodyError(f"system exclusive at offset {i} has no F7")
            if data[j] != SYSEX_END:
                raise BadBodyError(
                    f"system exclusive at offset {i} has no F7 "
                    f"(status 0x{data[j]:02X} at offset {j})"
                )
            out.append(data[i : j + 1])
            i = j + 1
        else:
            raise BadBodyError(f"status byte 0x{status:02X} at offset {i} is not allowed")
    return tuple(out)


@dataclass(frozen=True, slots=True)
class MidiBody:
    """One or more complete MIDI messages sharing the datagram's time."""

    KIND: ClassVar[int] = Kind.MIDI
    messages: tuple[bytes, ...]

    @classmethod
    def parse(cls, data: bytes) -> MidiBody:
        return cls(split_midi(bytes(data)))

    @classmethod
    def of(cls, *messages: bytes | tuple[int, ...] | list[int]) -> MidiBody:
        """Build from messages, validating them like a received body."""
        return cls.parse(b"".join(bytes(m) for m in messages))

    def __bytes__(self) -> bytes:
        return b"".join(self.messages)


@dataclass(frozen=True, slots=True)
class BeatBody:
    """A beat: ``time`` of the datagram is the time of this beat."""

    KIND: ClassVar[int] = Kind.BEAT
    bar: int
    beat: int
    beats_per_bar: int
    level: int
    tempo_us: int
    reserved: int = 0  # senders write 0; a receiver ignores it (kept for the round trip)

    @classmethod
    def parse(cls, data: bytes) -> BeatBody:
        _exact("BEAT", data, BEAT_BODY.size)
        bar, beat, bpb, level, reserved, tempo_us = BEAT_BODY.unpack(data)
        if level > 2:
            raise BadBodyError(f"BEAT level must be 0, 1 or 2, got {level}")
        if not 1 <= beat <= bpb:
            raise BadBodyError(f"BEAT beat must be 1-{bpb} (beats_per_bar), got {beat}")
        if tempo_us == 0:
            raise BadBodyError("BEAT tempo must be > 0 microseconds per beat")
        return cls(bar, beat, bpb, level, tempo_us, reserved)

    def __bytes__(self) -> bytes:
        return BEAT_BODY.pack(
            self.bar, self.beat, self.beats_per_bar, self.level, self.reserved, self.tempo_us
        )


@dataclass(frozen=True, slots=True)
class ChordBody:
    """A chord: root and bass pitch classes (bass None = same as root), quality."""

    KIND: ClassVar[int] = Kind.CHORD
    root: int
    bass: int | None
    quality: str

    @classmethod
    def parse(cls, data: bytes) -> ChordBody:
        if len(data) < CHORD_HEAD.size:
            raise BadBodyError(f"CHORD body truncated: {len(data)} of 3 bytes")
        root, bass, n = CHORD_HEAD.unpack_from(data)
        if len(data) != CHORD_HEAD.size + n:
            raise BadBodyError(f"CHORD body must be 3 + n = {3 + n} bytes, got {len(data)}")
        if root > 11:
            raise BadBodyError(f"CHORD root pitch class must be 0-11, got {root}")
        if bass > 11 and bass != BASS_SAME_AS_ROOT:
            raise BadBodyError(f"CHORD bass pitch class must be 0-11 or 255, got {bass}")
        raw = data[CHORD_HEAD.size :]
        if not raw.isascii():
            raise BadBodyError("CHORD quality is not ASCII")
        return cls(root, None if bass == BASS_SAME_AS_ROOT else bass, raw.decode("ascii"))

    def __bytes__(self) -> bytes:
        q = self.quality.encode("ascii")
        bass = BASS_SAME_AS_ROOT if self.bass is None else self.bass
        return CHORD_HEAD.pack(self.root, bass, len(q)) + q


@dataclass(frozen=True, slots=True)
class ClockRequestBody:
    """NTP-style request: ``t0`` is the requester's clock at sending (µs)."""

    KIND: ClassVar[int] = Kind.CLOCK_REQUEST
    nonce: int
    t0_us: int

    @classmethod
    def parse(cls, data: bytes) -> ClockRequestBody:
        _exact("CLOCK_REQUEST", data, CLOCK_REQUEST_BODY.size)
        return cls(*CLOCK_REQUEST_BODY.unpack(data))

    def __bytes__(self) -> bytes:
        return CLOCK_REQUEST_BODY.pack(self.nonce, self.t0_us)


@dataclass(frozen=True, slots=True)
class ClockReplyBody:
    """The reply: t0 echoed, t1 on receipt and t2 on sending by the replier (µs)."""

    KIND: ClassVar[int] = Kind.CLOCK_REPLY
    nonce: int
    t0_us: int
    t1_us: int
    t2_us: int

    @classmethod
    def parse(cls, data: bytes) -> ClockReplyBody:
        _exact("CLOCK_REPLY", data, CLOCK_REPLY_BODY.size)
        return cls(*CLOCK_REPLY_BODY.unpack(data))

    def __bytes__(self) -> bytes:
        return CLOCK_REPLY_BODY.pack(self.nonce, self.t0_us, self.t1_us, self.t2_us)


@dataclass(frozen=True, slots=True)
class UnknownBody:
    """The body of a kind this version does not know (kept, never interpreted)."""

    kind: int
    data: bytes

    @property
    def KIND(self) -> int:  # noqa: N802 - mirrors the class constant of known bodies
        return self.kind

    def __bytes__(self) -> bytes:
        return self.data


Body = MidiBody | BeatBody | ChordBody | ClockRequestBody | ClockReplyBody | UnknownBody

BODY_TYPES: dict[int, type[MidiBody | BeatBody | ChordBody | ClockRequestBody | ClockReplyBody]] = {
    Kind.MIDI: MidiBody,
    Kind.BEAT: BeatBody,
    Kind.CHORD: ChordBody,
    Kind.CLOCK_REQUEST: ClockRequestBody,
    Kind.CLOCK_REPLY: ClockReplyBody,
}


def parse_body(kind: int, data: bytes) -> Body:
    """The body of ``kind`` from its bytes; unknown kinds give :class:`UnknownBody`."""
    cls = BODY_TYPES.get(kind)
    if cls is None:
        return UnknownBody(kind, bytes(data))
    return cls.parse(data)
