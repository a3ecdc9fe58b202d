"""RMCP/1 datagrams: the 24-byte header, the body, the optional tag (sans-IO).

``Datagram.parse(data)`` checks, in this order, the rules of the spec
(/work/shared/specs/rmcp.md, "What a receiver does"): too short, too long, bad
magic, bad version, bad flags, bad reserved, bad length, bad body; it raises
the matching :mod:`virja.rmcp.errors` subclass.  ``bytes(Datagram.parse(d)) ==
d`` for every valid ``d``.

This module is also the one place where wire time (``int`` µs) becomes virja
time (``float`` s): :func:`us_to_s`, used by :func:`to_events`.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntFlag

from virja import midispec
from virja.events import Beat, Chord, Event
from virja.rmcp.bodies import (
    BeatBody,
    Body,
    ChordBody,
    ClockReplyBody,
    ClockRequestBody,
    Kind,
    MidiBody,
    UnknownBody,
    parse_body,
)
from virja.rmcp.errors import (
    BadFlagsError,
    BadLengthError,
    BadMagicError,
    BadReservedError,
    BadVersionError,
    TooLongError,
    TooShortError,
)

__all__ = [
    "HEADER",
    "HEADER_LEN",
    "MAGIC",
    "MAX_DATAGRAM",
    "TAG_LEN",
    "VERSION",
    "Datagram",
    "Flags",
    "Kind",
    "UnknownBody",
    "kind_name",
    "to_events",
    "us_to_s",
    "s_to_us",
]

HEADER = struct.Struct("!4sBBBBHHIq")  # magic version kind flags reserved sender body_len seq time
HEADER_LEN = HEADER.size  # 24
MAGIC = b"RMCP"
VERSION = 1
TAG_LEN = 16
MAX_DATAGRAM = 1200
MAX_BODY = MAX_DATAGRAM - HEADER_LEN - TAG_LEN  # a body that fits even when signed

U16_MAX = 0xFFFF
U32_MAX = 0xFFFF_FFFF
I64_MIN = -(1 << 63)
I64_MAX = (1 << 63) - 1


class Flags(IntFlag):
    """The ``flags`` header byte; bits 2-7 must be 0."""

    NONE = 0
    IMMEDIATE = 1
    SIGNED = 2


KNOWN_FLAGS = Flags.IMMEDIATE | Flags.SIGNED


def us_to_s(time_us: int) -> float:
    """Wire time (µs since the Unix epoch) to virja time (s): the one conversion."""
    return time_us / 1_000_000


def s_to_us(time_s: float) -> int:
    """virja time (s) to wire time (µs), rounded to the nearest microsecond."""
    return round(time_s * 1_000_000)


def kind_name(kind: int) -> str:
    """``"MIDI"`` ... for known kinds, ``"kind_42"`` otherwise (a counter key)."""
    try:
        return Kind(kind).name
    except ValueError:
        return f"kind_{kind}"


@dataclass(frozen=True, slots=True)
class Datagram:
    """One RMCP/1 message: header fields, body, and the tag when SIGNED.

    ``tag`` is empty unless ``flags`` has SIGNED; :func:`virja.rmcp.signing.sign`
    sets both.  ``kind`` comes from the body.
    """

    sender: int
    seq: int
    time_us: int
    body: Body
    flags: Flags = Flags.NONE
    tag: bytes = b""

    def __post_init__(self) -> None:
        if not 0 <= self.sender <= U16_MAX:
            raise ValueError(f"sender must be 0-65535, got {self.sender}")
        if not 0 <= self.seq <= U32_MAX:
            raise ValueError(f"seq must be 0-4294967295, got {self.seq}")
        if not I64_MIN <= self.time_us <= I64_MAX:
            raise ValueError(f"time_us out of the i64 range: {self.time_us}")
        if int(self.flags) & ~int(KNOWN_FLAGS):
            raise ValueError(f"unknown flag bits 0x{int(self.flags):02X}")
        want = TAG_LEN if self.flags & Flags.SIGNED else 0
        if len(self.tag) != want:
            raise ValueError(
                f"tag must be {want} bytes with flags {self.flags!r}, got {len(self.tag)}"
            )

    @property
    def kind(self) -> int:
        return int(self.body.KIND)

    @property
    def immediate(self) -> bool:
        return bool(self.flags & Flags.IMMEDIATE)

    @property
    def signed(self) -> bool:
        return bool(self.flags & Flags.SIGNED)

    def header_and_body(self) -> bytes:
        """The bytes the tag covers: header then body."""
        body = bytes(self.body)
        head = HEADER.pack(
            MAGIC,
            VERSION,
            self.kind,
            int(self.flags),
            0,
            self.sender,
            len(body),
            self.seq,
            self.time_us,
        )
        return head + body

    def __bytes__(self) -> bytes:
        data = self.header_and_body() + self.tag
        if len(data) > MAX_DATAGRAM:
            raise ValueError(f"datagram of {len(data)} bytes exceeds {MAX_DATAGRAM}")
        return data

    @classmethod
    def parse(cls, data: bytes) -> Datagram:
        """Decode and validate one datagram; raises an RmcpError subclass."""
        n = len(data)
        if n < HEADER_LEN:
            raise TooShortError(f"datagram too short: {n} of {HEADER_LEN} header bytes")
        if n > MAX_DATAGRAM:
            raise TooLongError(f"datagram too long: {n} bytes, at most {MAX_DATAGRAM}")
        magic, version, kind, flags, reserved, sender, body_len, seq, time_us = HEADER.unpack_from(
            data
        )
        if magic != MAGIC:
            raise BadMagicError(f"bad magic {magic!r}, expected {MAGIC!r}")
        if version != VERSION:
            raise BadVersionError(f"unsupported version {version}, expected {VERSION}")
        if flags & ~int(KNOWN_FLAGS):
            raise BadFlagsError(f"reserved flag bits set: 0x{flags:02X}")
        if reserved != 0:
            raise BadReservedError(f"reserved byte is {reserved}, must be 0")
        signed = bool(flags & Flags.SIGNED)
        body_end = HEADER_LEN + body_len
        want = body_end + (TAG_LEN if signed else 0)
        if n < body_end:
            raise BadLengthError(f"body truncated: {n - HEADER_LEN} of {body_len} bytes")
        if n < want:
            raise BadLengthError(f"tag truncated: {n - body_end} of {TAG_LEN} bytes")
        if n > want:
            raise BadLengthError(
                f"{n - want} bytes after the end of the message (body_len {body_len}"
                f"{', signed' if signed else ''})"
            )
        body = parse_body(kind, data[HEADER_LEN:body_end])
        return cls(sender, seq, time_us, body, Flags(flags), bytes(data[body_end:want]))


# -- builders -----------------------------------------------------------------


def midi(
    sender: int, seq: int, time_us: int, *messages: bytes, flags: Flags = Flags.NONE
) -> Datagram:
    """A MIDI datagram of complete messages (validated)."""
    return Datagram(sender, seq, time_us, MidiBody.of(*messages), flags)


def beat(
    sender: int,
    seq: int,
    time_us: int,
    *,
    bar: int,
    beat: int,
    beats_per_bar: int,
    level: int,
    tempo_us: int,
) -> Datagram:
    return Datagram(sender, seq, time_us, BeatBody(bar, beat, beats_per_bar, level, tempo_us))


def chord(
    sender: int, seq: int, time_us: int, *, root: int, bass: int | None, quality: str
) -> Datagram:
    return Datagram(sender, seq, time_us, ChordBody(root, bass, quality))


def clock_request(
    sender: int, seq: int, *, nonce: int, t0_us: int, time_us: int | None = None
) -> Datagram:
    """A CLOCK_REQUEST, IMMEDIATE.  ``t0_us`` (the body) is the requester's own clock;
    the header's ``time`` is its current *session* time (``time_us``, default t0), as
    the spec asks of IMMEDIATE datagrams, so a keyed receiver's 30 s rule holds."""
    header_us = t0_us if time_us is None else time_us
    return Datagram(sender, seq, header_us, ClockRequestBody(nonce, t0_us), Flags.IMMEDIATE)


def clock_reply(
    sender: int, seq: int, request: ClockRequestBody, *, t1_us: int, t2_us: int
) -> Datagram:
    """The CLOCK_REPLY to ``request``, IMMEDIATE, with ``time`` = t2."""
    body = ClockReplyBody(request.nonce, request.t0_us, t1_us, t2_us)
    return Datagram(sender, seq, t2_us, body, Flags.IMMEDIATE)


# -- conversion to virja events -----------------------------------------------


def midi_events(body: MidiBody, time_s: float, sender: int) -> list[Event]:
    """NoteOn / NoteOff (incl. velocity-0 note-on) / ControlChange / ProgramChange,
    by the one table (:mod:`virja.midispec`).

    Other messages (aftertouch, pitch bend, sysex) are valid on the wire and
    ignored here.
    """
    out: list[Event] = []
    for m in body.messages:
        ev = midispec.decode(m, time_s=time_s, sender=sender)
        if ev is not None:
            out.append(ev)
    return out


def to_events(dgram: Datagram, *, time_s: float | None = None) -> list[Event]:
    """The virja events a datagram carries, at ``time_s`` (default its own ``time``).

    CLOCK and unknown kinds carry no events.
    """
    t = us_to_s(dgram.time_us) if time_s is None else time_s
    body = dgram.body
    if isinstance(body, MidiBody):
        return midi_events(body, t, dgram.sender)
    if isinstance(body, BeatBody):
        return [
            Beat(
                t, body.bar, body.beat, body.beats_per_bar, body.level, body.tempo_us, dgram.sender
            )
        ]
    if isinstance(body, ChordBody):
        return [Chord(t, body.root, body.bass, body.quality, dgram.sender)]
    return []


def event_message(event: Event) -> bytes | None:
    """The MIDI bytes of a channel event (None for Beat and Chord)."""
    return midispec.encode(event)
