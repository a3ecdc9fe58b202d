"""MIDI 1.0 channel messages <-> virja events: the one table (mido messages/specs.py style).

:data:`SPECS` lists the channel voice messages once: status nibble, mido's type
name, the data byte count, the field names (which are also the event's field
names), and the :mod:`virja.events` class it becomes (None: valid MIDI that is
not an event of the band, e.g. pitch bend).  Every place that turns bytes into
events or events into bytes reads it: the RMCP codec (:mod:`virja.rmcp.bodies`
validates with :func:`data_len`, :mod:`virja.rmcp.wire` converts with
:func:`decode`), the keyboard (:mod:`virja.jam.keyboard`), the audio renderer
(:mod:`virja.render.video`, through :func:`to_mido`) and the file reader
(:mod:`virja.midifile`, through :func:`from_mido`).

The one rule of meaning, written once here: a note-on with velocity 0 is a
:class:`~virja.events.NoteOff` (velocity 0).  What a transport refuses
(running status, system messages, ...) stays with that transport.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from operator import attrgetter
from typing import TYPE_CHECKING, Any

from virja.events import ControlChange, Event, NoteOff, NoteOn, ProgramChange

if TYPE_CHECKING:
    import mido

ChannelEvent = NoteOn | NoteOff | ControlChange | ProgramChange


@dataclass(frozen=True, slots=True)
class Spec:
    """One channel voice message: ``status`` is the high nibble (0x80-0xE0)."""

    status: int
    name: str  # mido's message type
    fields: tuple[str, ...]  # the data bytes' names, in wire order
    event: type[ChannelEvent] | None  # the event it becomes (None: not an event)

    @property
    def data_len(self) -> int:
        return len(self.fields)


SPECS: tuple[Spec, ...] = (
    Spec(0x80, "note_off", ("note", "velocity"), NoteOff),
    Spec(0x90, "note_on", ("note", "velocity"), NoteOn),
    Spec(0xA0, "polytouch", ("note", "value"), None),
    Spec(0xB0, "control_change", ("control", "value"), ControlChange),
    Spec(0xC0, "program_change", ("program",), ProgramChange),
    Spec(0xD0, "aftertouch", ("value",), None),
    Spec(0xE0, "pitchwheel", ("lsb", "msb"), None),
)

BY_STATUS: dict[int, Spec] = {s.status: s for s in SPECS}
BY_NAME: dict[str, Spec] = {s.name: s for s in SPECS}
BY_EVENT: dict[type[ChannelEvent], Spec] = {s.event: s for s in SPECS if s.event is not None}
# data bytes after each channel status nibble (the RMCP and RTP-MIDI validators use it)
CHANNEL_DATA_LEN: dict[int, int] = {s.status: s.data_len for s in SPECS}
NOTE_ON = BY_NAME["note_on"].status
PROGRAM_CHANGE = BY_NAME["program_change"].status


def data_len(status: int) -> int:
    """Data bytes after channel status byte ``status`` (0x80-0xEF)."""
    return BY_STATUS[status & 0xF0].data_len


def _event(
    spec: Spec,
    channel: int,
    values: Sequence[int],
    time_s: float,
    sender: int,
    track: int | None,
) -> ChannelEvent | None:
    cls = spec.event
    if cls is None:
        return None
    if cls is NoteOn and values[1] == 0:
        cls = NoteOff
    # the fields of every event class are (time_s, channel, *spec.fields, sender, track)
    return cls(time_s, channel, *values, sender=sender, track=track)  # type: ignore[misc]


def decode(
    message: Sequence[int], *, time_s: float, sender: int = 0, track: int | None = None
) -> ChannelEvent | None:
    """The event of one complete channel message (status byte first); None when the
    message is no event of the band (aftertouch, pitch bend, system messages) or is
    short or malformed (a data byte above 127 anywhere after the status byte).  Bytes
    past the message's own length are otherwise ignored."""
    if not message:
        return None
    status = message[0]
    spec = BY_STATUS.get(status & 0xF0) if 0x80 <= status <= 0xEF else None
    if spec is None or len(message) <= spec.data_len:
        return None
    if any(not 0 <= b <= 0x7F for b in message[1:]):
        return None
    return _event(spec, status & 0x0F, message[1 : 1 + spec.data_len], time_s, sender, track)


def encode(event: Event) -> bytes | None:
    """The MIDI bytes of a channel event (status byte included); None for Beat and Chord."""
    spec = BY_EVENT.get(type(event))  # type: ignore[arg-type]
    if spec is None:
        return None
    values = [getattr(event, f) for f in spec.fields]
    return bytes((spec.status | event.channel, *values))  # type: ignore[union-attr]


# mido type name -> (event class, getter of (channel, *fields)): read per message of a
# file, so built once from SPECS
_FROM_MIDO: dict[str, tuple[type[ChannelEvent], attrgetter[Any]]] = {
    s.name: (s.event, attrgetter("channel", *s.fields)) for s in SPECS if s.event is not None
}


def from_mido(
    msg: mido.Message, *, time_s: float, sender: int = 0, track: int | None = None
) -> ChannelEvent | None:
    """The event of a mido channel message (None for any other type)."""
    entry = _FROM_MIDO.get(msg.type)
    if entry is None:
        return None
    cls, get = entry
    values = get(msg)
    if cls is NoteOn and values[2] == 0:
        cls = NoteOff
    return cls(time_s, *values, sender=sender, track=track)  # type: ignore[misc]


def to_mido(event: Event) -> mido.Message | None:
    """The mido message of a channel event (None for Beat and Chord)."""
    import mido

    spec = BY_EVENT.get(type(event))  # type: ignore[arg-type]
    if spec is None:
        return None
    fields: dict[str, Any] = {f: getattr(event, f) for f in spec.fields}
    return mido.Message(spec.name, channel=event.channel, **fields)  # type: ignore[union-attr]
