"""``virja send``'s schedule: which datagram leaves when, as a pure function.

:func:`schedule_pass` turns one pass over a performance (events with
``time_s`` from its start, a tempo map, beats) into :class:`Scheduled` items:
send time and datagram (unsigned).  A note at file time ``t`` takes effect at
``start_us + t`` and is sent ``lead_beats`` beats earlier at the tempo in force
at ``t``.  Events of one sender at one time share a MIDI datagram.  A BEAT
goes out for every beat (level 2 on bar heads, 1 on the half-bar of even
metres), from the ``conductor`` sender id.  Sequence numbers run per sender
and carry over between passes (``--loop``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from virja.events import Beat, Chord, ControlChange, Event, NoteOff, NoteOn, ProgramChange
from virja.midispec import PROGRAM_CHANGE
from virja.rmcp.bodies import BeatBody, ChordBody, MidiBody
from virja.rmcp.seqnum import seq_add
from virja.rmcp.wire import MAX_BODY, Datagram, event_message, s_to_us
from virja.tempo import Tempo, TempoMap

Route = Callable[[Event], str | None]  # virja.routing.Router.route

DEFAULT_SENDER_IDS: dict[str, int] = {"bass": 1, "drums": 2, "other": 3}


@dataclass(frozen=True)
class SendOptions:
    """lead_beats: how far ahead notes are sent; sender: force one id for all;
    sender_ids: id per performer ("bass", "drums", "other")."""

    lead_beats: float = 1.0
    sender: int | None = None
    sender_ids: dict[str, int] = field(default_factory=lambda: dict(DEFAULT_SENDER_IDS))
    beats_per_bar: int = 4

    def sender_for(self, performer: str | None) -> int:
        if self.sender is not None:
            return self.sender
        return self.sender_ids.get(performer or "other", self.sender_ids["other"])

    @property
    def conductor(self) -> int:
        return self.sender if self.sender is not None else self.sender_ids["other"]


@dataclass(frozen=True, slots=True)
class Scheduled:
    """Send ``datagram`` at ``send_us`` (session clock)."""

    send_us: int
    datagram: Datagram


def beats_of(tempo_map: TempoMap, duration_s: float, beats_per_bar: int) -> list[Beat]:
    """One Beat per beat of ``tempo_map`` in [0, duration_s)."""
    out: list[Beat] = []
    for i, t in enumerate(tempo_map.beat_times(0.0, duration_s)):
        if t >= duration_s and i:
            break
        bar, pos = divmod(i, beats_per_bar)
        level = 2 if pos == 0 else 1 if beats_per_bar % 2 == 0 and pos == beats_per_bar // 2 else 0
        tempo_us = round(tempo_map.seconds_per_beat_at(t) * 1_000_000)
        out.append(Beat(t, bar, pos + 1, beats_per_bar, level, tempo_us))
    return out


def schedule_pass(
    events: Sequence[Event],
    tempo: Tempo,
    beats: Sequence[Beat],
    options: SendOptions,
    start_us: int,
    *,
    route: Route,
    seqs: dict[int, int] | None = None,
    seq_start: int = 0,
) -> tuple[list[Scheduled], dict[int, int]]:
    """The datagrams of one pass starting at session time ``start_us``, by send time.

    ``seqs`` is the next sequence number per sender id (updated copy returned);
    a sender not in it starts at ``seq_start``.  Each bar head also repeats the
    program in force on every channel that had a program change, so a receiver
    that joins late, or lost the first datagram, still knows the bass channel.
    """
    next_seq = dict(seqs or {})
    # (time_us, sender) -> messages, in event order
    groups: dict[tuple[int, int], list[bytes]] = {}
    order: list[tuple[float, tuple[int, int]]] = []
    routes = [route(ev) for ev in events]
    # program changes and controllers go with the performer of their channel's
    # notes, so a receiver that routes by (sender, channel) sees them together
    channel_route: dict[tuple[int | None, int], str] = {}
    for ev, r in zip(events, routes, strict=True):
        if r is not None and isinstance(ev, NoteOn | NoteOff):
            channel_route.setdefault((ev.track, ev.channel), r)
    programs: list[tuple[float, int, int, int]] = []  # (time, sender, channel, program)
    chords: list[Chord] = []  # sent by the conductor, like beats (for heads-up displays)
    for ev, r in zip(events, routes, strict=True):
        if isinstance(ev, Chord):
            chords.append(ev)
            continue
        msg = event_message(ev)
        if msg is None:
            continue
        if r is None and isinstance(ev, ControlChange | ProgramChange):
            r = channel_route.get((ev.track, ev.channel))
        if isinstance(ev, ProgramChange):
            programs.append((ev.time_s, options.sender_for(r), ev.channel, ev.program))
        key = (start_us + s_to_us(ev.time_s), options.sender_for(r))
        if key not in groups:
            groups[key] = []
            order.append((ev.time_s, key))
        groups[key].append(msg)
    items: list[
        tuple[int, int, int, int, MidiBody | BeatBody | ChordBody]
    ] = []  # send, time, n, sender
    n = 0
    for time_s, key in order:
        lead_us = s_to_us(options.lead_beats * tempo.seconds_per_beat_at(time_s))
        for midi in _pack(groups[key]):
            items.append((key[0] - lead_us, key[0], n, key[1], midi))
            n += 1
    for b in beats:
        time_us = start_us + s_to_us(b.time_s)
        lead_us = s_to_us(options.lead_beats * b.tempo_us / 1_000_000)
        beat = BeatBody(b.bar, b.beat, b.beats_per_bar, b.level, b.tempo_us)
        items.append((time_us - lead_us, time_us, n, options.conductor, beat))
        n += 1
        if b.level == 2 and b.time_s > 0:  # bar head: repeat the programs in force
            in_force: dict[tuple[int, int], int] = {}
            for t, sender, channel, program in programs:
                if t <= b.time_s:
                    in_force[(sender, channel)] = program
            for (sender, channel), program in sorted(in_force.items()):
                repeat = MidiBody((bytes((PROGRAM_CHANGE | channel, program)),))
                items.append((time_us - lead_us, time_us, n, sender, repeat))
                n += 1
    for c in chords:
        time_us = start_us + s_to_us(c.time_s)
        lead_us = s_to_us(options.lead_beats * tempo.seconds_per_beat_at(c.time_s))
        items.append(
            (time_us - lead_us, time_us, n, options.conductor, ChordBody(c.root, c.bass, c.quality))
        )
        n += 1
    items.sort(key=lambda it: (it[0], it[1], it[2]))
    out: list[Scheduled] = []
    for send_us, time_us, _, sender, body in items:
        seq = next_seq.get(sender, seq_start & 0xFFFF_FFFF)
        next_seq[sender] = seq_add(seq, 1)
        out.append(Scheduled(send_us, Datagram(sender, seq, time_us, body)))
    return out, next_seq


def _pack(messages: list[bytes]) -> list[MidiBody]:
    """Messages into MIDI bodies of at most MAX_BODY bytes."""
    bodies: list[MidiBody] = []
    cur: list[bytes] = []
    size = 0
    for m in messages:
        if cur and size + len(m) > MAX_BODY:
            bodies.append(MidiBody(tuple(cur)))
            cur, size = [], 0
        cur.append(m)
        size += len(m)
    if cur:
        bodies.append(MidiBody(tuple(cur)))
    return bodies
