"""The event model: what flows from every input (RMCP, MIDI file, MIDI port) inward.

All times are seconds on the *session clock*, as ``float``:
- network input and live ports: Unix time in seconds (RMCP carries microseconds;
  ``virja.rmcp`` converts with ``time_us / 1e6`` at the boundary);
- MIDI files: seconds from the start of the file.

Events are immutable value objects; ordering is by ``time_s`` (ties keep arrival
order, which callers preserve with a stable sort).
"""

from __future__ import annotations

from dataclasses import dataclass


def _check_7bit(name: str, value: int) -> None:
    if not 0 <= value <= 127:
        raise ValueError(f"{name} must be 0-127, got {value}")


def _check_channel(channel: int) -> None:
    if not 0 <= channel <= 15:
        raise ValueError(f"channel must be 0-15, got {channel}")


@dataclass(frozen=True, slots=True)
class NoteOn:
    """A note starts sounding at ``time_s``.  ``velocity`` is 1-127 (0 is a NoteOff)."""

    time_s: float
    channel: int
    note: int
    velocity: int
    sender: int = 0
    track: int | None = None

    def __post_init__(self) -> None:
        _check_channel(self.channel)
        _check_7bit("note", self.note)
        if not 1 <= self.velocity <= 127:
            raise ValueError(f"note-on velocity must be 1-127, got {self.velocity}")


@dataclass(frozen=True, slots=True)
class NoteOff:
    """A note stops sounding at ``time_s`` (also made from note_on with velocity 0)."""

    time_s: float
    channel: int
    note: int
    velocity: int = 0
    sender: int = 0
    track: int | None = None

    def __post_init__(self) -> None:
        _check_channel(self.channel)
        _check_7bit("note", self.note)
        _check_7bit("velocity", self.velocity)


@dataclass(frozen=True, slots=True)
class ControlChange:
    """A controller change; always applied, never dropped as late."""

    time_s: float
    channel: int
    control: int
    value: int
    sender: int = 0
    track: int | None = None

    def __post_init__(self) -> None:
        _check_channel(self.channel)
        _check_7bit("control", self.control)
        _check_7bit("value", self.value)


@dataclass(frozen=True, slots=True)
class ProgramChange:
    """A GM program change (0-based program number: 32-39 are basses)."""

    time_s: float
    channel: int
    program: int
    sender: int = 0
    track: int | None = None

    def __post_init__(self) -> None:
        _check_channel(self.channel)
        _check_7bit("program", self.program)


@dataclass(frozen=True, slots=True)
class Beat:
    """A beat of the session (RMCP BEAT, or derived from a file's tempo map).

    ``bar`` is 0-based, ``beat`` 1-based within the bar; ``level`` 0 quarter-note
    beat, 1 half-note beat, 2 bar head; ``tempo_us`` microseconds per beat.
    """

    time_s: float
    bar: int
    beat: int
    beats_per_bar: int
    level: int
    tempo_us: int
    sender: int = 0

    @property
    def seconds_per_beat(self) -> float:
        return self.tempo_us / 1e6


@dataclass(frozen=True, slots=True)
class Chord:
    """A chord starting at ``time_s``; ``bass`` is None when it equals the root."""

    time_s: float
    root: int
    bass: int | None
    quality: str
    sender: int = 0


Event = NoteOn | NoteOff | ControlChange | ProgramChange | Beat | Chord


def sort_events(events: list[Event]) -> list[Event]:
    """Events ordered by time; simultaneous events keep their given order."""
    return sorted(events, key=lambda e: e.time_s)
