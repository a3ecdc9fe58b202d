"""Routing live keyboard messages to the band: pure functions, no ports, no clock.

A message arrives as raw MIDI bytes; :func:`decode` turns it into a
:mod:`virja.events` event stamped with the time the caller passes (the key's
arrival on the session clock, plus ``--delay-ms`` when the picture is delayed);
:func:`route` says who plays it:

- channel 10 (index 9): the drummer, note numbers as they are (the GM drum map
  is the planner's business);
- any other channel, keys below the split (default 48, C3): the bassist;
- keys from the split up: the pianist's own part, drawn by nobody, unless
  ``upper="drums"``, which turns them into drum strokes through
  :data:`UPPER_DRUM_NOTES` (sent on channel 10 so a synth plays them as drums).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from virja import midispec
from virja.errors import ConfigError
from virja.events import ControlChange, NoteOff, NoteOn, ProgramChange
from virja.vocab import Performer

LiveEvent = NoteOn | NoteOff | ControlChange | ProgramChange
UpperMode = Literal["ignore", "drums"]
UPPER_MODES: tuple[UpperMode, ...] = ("ignore", "drums")

DRUM_CHANNEL = 9
"""GM percussion channel, 0-based (channel 10 to a musician)."""

DEFAULT_SPLIT = 48
"""C3 (MIDI 48): the lowest key of the pianist's part; the bassist gets the keys below."""

# Keys from the split up, with ``upper="drums"``: pitch class -> GM drum note.
# Every octave above the split repeats the table, so a drummer's hand stays on
# one octave.  White keys carry the kit of the paper (bass drum, snare, hi-hat,
# three toms, ride); four black keys the pedal hi-hat, open hi-hat and the two
# crashes (crash 2, the kit's right-hand crash beside the ride, on G# between the
# toms).  D# is left unmapped on purpose: it lies between the snare and the
# closed hi-hat, the two keys played most, so a slip of the finger there makes no
# stroke rather than a wrong one.
UPPER_DRUM_NOTES: dict[int, int] = {
    0: 36,  # C  -> Bass Drum 1 (right foot)
    1: 44,  # C# -> Pedal Hi-Hat (left foot)
    2: 38,  # D  -> Acoustic Snare
    4: 42,  # E  -> Closed Hi-Hat
    5: 43,  # F  -> High Floor Tom
    6: 46,  # F# -> Open Hi-Hat
    7: 47,  # G  -> Low-Mid Tom (the low tom)
    8: 57,  # G# -> Crash Cymbal 2 (the right-hand crash)
    9: 50,  # A  -> High Tom
    10: 49,  # A# -> Crash Cymbal 1
    11: 51,  # B  -> Ride Cymbal 1
}

# GM names of the notes above, for documentation and the CLI's routing table.
GM_DRUM_NAMES: dict[int, str] = {
    36: "Bass Drum 1",
    38: "Acoustic Snare",
    42: "Closed Hi-Hat",
    43: "High Floor Tom",
    44: "Pedal Hi-Hat",
    46: "Open Hi-Hat",
    47: "Low-Mid Tom",
    49: "Crash Cymbal 1",
    50: "High Tom",
    51: "Ride Cymbal 1",
    57: "Crash Cymbal 2",
}

PITCH_NAMES = ("C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B")


@dataclass(frozen=True, slots=True)
class KeyboardLayout:
    """How the keys are split between the performers.

    ``split`` is the lowest key of the upper part (0-127); ``upper`` says what the
    upper part does: ``"ignore"`` (the pianist plays it, nobody is drawn) or
    ``"drums"`` (mapped through :data:`UPPER_DRUM_NOTES` to the drummer).
    """

    split: int = DEFAULT_SPLIT
    upper: UpperMode = "ignore"

    def __post_init__(self) -> None:
        if not 0 <= self.split <= 128:
            raise ConfigError(f"split must be a MIDI key 0-128, got {self.split}")
        if self.upper not in UPPER_MODES:
            raise ConfigError(f"upper must be one of {', '.join(UPPER_MODES)}, got {self.upper!r}")


@dataclass(frozen=True, slots=True)
class Routed:
    """An event after routing: who plays it (None: nobody drawn) and the event itself.

    For upper keys mapped to drums ``event`` is the drum note on channel 10, the
    form both the planner and a thru synth want.
    """

    performer: Performer | None
    event: LiveEvent


def pitch_name(note: int) -> str:
    """Scientific pitch name with MIDI 60 = C4 (so 48 = C3)."""
    return f"{PITCH_NAMES[note % 12]}{note // 12 - 1}"


def decode(data: Sequence[int], *, time_s: float) -> LiveEvent | None:
    """One raw MIDI message -> an event at ``time_s``; None for anything else.

    Note-on with velocity 0 is a NoteOff.  System messages, pitch bend and
    aftertouch are not events of the band (the thru output forwards them raw).
    A short or malformed message gives None, never an exception.
    """
    return midispec.decode(data, time_s=time_s)


def encode(event: LiveEvent) -> bytes:
    """The MIDI bytes of an event (the inverse of :func:`decode`)."""
    data = midispec.encode(event)
    assert data is not None  # every LiveEvent is a channel event
    return data


def upper_drum_note(note: int) -> int | None:
    """The GM drum note an upper key plays with ``upper="drums"``; None if unmapped."""
    return UPPER_DRUM_NOTES.get(note % 12)


def route(event: LiveEvent, layout: KeyboardLayout) -> Routed:
    """Who plays ``event`` under ``layout``.

    Controllers and program changes on channel 10 go to the drummer (a hi-hat
    pedal controller matters to it); on other channels to nobody.
    """
    if event.channel == DRUM_CHANNEL:
        return Routed("drums", event)
    if not isinstance(event, NoteOn | NoteOff):
        return Routed(None, event)
    if event.note < layout.split:
        return Routed("bass", event)
    if layout.upper == "drums":
        drum = upper_drum_note(event.note)
        if drum is None:
            return Routed(None, event)
        if isinstance(event, NoteOn):
            mapped: LiveEvent = NoteOn(
                time_s=event.time_s, channel=DRUM_CHANNEL, note=drum, velocity=event.velocity
            )
        else:
            mapped = NoteOff(
                time_s=event.time_s, channel=DRUM_CHANNEL, note=drum, velocity=event.velocity
            )
        return Routed("drums", mapped)
    return Routed(None, event)


def routing_table(layout: KeyboardLayout) -> list[tuple[str, str]]:
    """Human-readable rows (keys, what they do) for ``virja jam --list-routing`` and docs."""
    rows = [("channel 10, any key", "drums (GM drum map)")]
    if layout.split > 0:
        rows.append((f"keys below {pitch_name(layout.split)} ({layout.split})", "bass"))
    upper = f"keys from {pitch_name(layout.split)} ({layout.split}) up"
    if layout.upper == "ignore":
        rows.append((upper, "the pianist (not drawn)"))
        return rows
    for pc in range(12):
        drum = UPPER_DRUM_NOTES.get(pc)
        what = "nothing" if drum is None else f"drums: {drum} {GM_DRUM_NAMES[drum]}"
        rows.append((f"{upper}, every {PITCH_NAMES[pc]}", what))
    return rows
