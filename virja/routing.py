"""Which performer plays an event: the drummer, the bassist, or nobody.

Rules, in order (the first that decides wins), all data in
:class:`RoutingConfig` so a user can override them from TOML or flags:

1. a track named in ``tracks`` (case-insensitive, exact name) -> that performer
   ("bass", "drums" or "none");
2. a channel listed in ``channels`` -> that performer;
3. a drum channel (default MIDI channel 10, index 9) -> drums;
4. the track's name reads as a bass part (``bass_track_words``) -> bass, whatever
   its program ("Bass" with GM program 26 is still the bass part; :meth:`Router.report`
   says so), unless another track of the file plays a GM bass program: then that
   track is the bass part and a bass-named track on another instrument is not (an
   MMA session's "Bass-Hits" horn stabs on program 66 beside its "Bass" on 32; the
   report says so and names the flag that adds it); ``names_over_programs = false``
   turns this rule off;
5. the GM program in force on the channel is a bass (32-39) -> bass; any other
   program -> nobody (a piano part never makes the bassist play chords);
6. otherwise nobody.

Channels in the config are 1-based, as musicians count them; events carry
0-based channels.
"""

from __future__ import annotations

import re
from collections import Counter, OrderedDict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from virja import tomlconf
from virja.errors import ConfigError
from virja.events import Event, NoteOff, NoteOn, ProgramChange
from virja.tomlconf import Schema
from virja.vocab import Performer

GM_BASS_PROGRAMS = frozenset(range(32, 40))  # Acoustic Bass .. Synth Bass 2 (0-based)
DEFAULT_BASS_WORDS = ("bass", "contrabass", "kontrabass", "basse", "bajo", "baixo", "upright")
# words that mean the track is not a bass part even though it contains "bass"
DEFAULT_NOT_BASS_WORDS = ("drum", "bassdrum", "bass drum", "kick")
# (source, channel) programs remembered: 1,024 senders (the receiver's cap) x 16 channels
MAX_PROGRAMS = 16_384

Route = Performer | None
_TARGETS: dict[str, Route] = {"bass": "bass", "drums": "drums", "none": None}


class RoutingTable(Schema):
    """The ``[routing]`` table of the config file (docs/virja.example.toml documents
    each key); a key left out keeps :class:`RoutingConfig`'s default."""

    drum_channels: list[int] | None = None
    bass_programs: list[int] | None = None
    bass_track_words: list[str] | None = None
    channels: dict[str, str] = {}
    tracks: dict[str, str] = {}
    names_over_programs: bool | None = None


ROUTING_KEYS = tuple(RoutingTable.__struct_fields__)


@dataclass(frozen=True)
class RoutingConfig:
    drum_channels: frozenset[int] = frozenset({10})  # 1-based
    bass_programs: frozenset[int] = GM_BASS_PROGRAMS  # 0-based GM program numbers
    bass_track_words: tuple[str, ...] = DEFAULT_BASS_WORDS
    channels: Mapping[int, Route] = field(default_factory=dict)  # 1-based channel -> route
    tracks: Mapping[str, Route] = field(default_factory=dict)  # lower-case name -> route
    names_over_programs: bool = True  # a bass-named track is the bassist's, whatever its program

    @classmethod
    def from_dict(cls, table: Mapping[str, Any], where: str = "[routing]") -> RoutingConfig:
        """From the ``[routing]`` table of the config file; ``where`` names it in errors."""
        t = tomlconf.convert(table, RoutingTable, where)
        base = cls()
        drum = base.drum_channels
        if t.drum_channels is not None:
            drum = frozenset(_channel_list(t.drum_channels))
        progs = base.bass_programs
        if t.bass_programs is not None:
            if not all(0 <= p <= 127 for p in t.bass_programs):
                raise ConfigError(f"{where} bass_programs: integers 0-127 (GM programs, 0-based)")
            progs = frozenset(t.bass_programs)
        words = base.bass_track_words
        if t.bass_track_words is not None:
            words = tuple(w.lower() for w in t.bass_track_words)
        chans: dict[int, Route] = {}
        for k, v in t.channels.items():
            if not k.isascii() or not k.isdigit():
                raise ConfigError(f"{where}.channels: key {k!r} must be a channel number 1-16")
            (ch,) = _channel_list([int(k)])
            chans[ch] = _target(v, f"{where}.channels {k}")
        tracks = {k.lower(): _target(v, f"{where}.tracks {k!r}") for k, v in t.tracks.items()}
        names_first = base.names_over_programs
        if t.names_over_programs is not None:
            names_first = t.names_over_programs
        return cls(drum, progs, words, chans, tracks, names_first)

    def with_overrides(
        self,
        *,
        bass_channels: Iterable[int] = (),
        drum_channels: Iterable[int] = (),
        bass_tracks: Iterable[str] = (),
        ignore_tracks: Iterable[str] = (),
    ) -> RoutingConfig:
        """A copy with CLI flags applied on top (flags win over the file)."""
        chans = dict(self.channels)
        for ch in _channel_list(bass_channels):
            chans[ch] = "bass"
        for ch in _channel_list(drum_channels):
            chans[ch] = "drums"
        tracks = dict(self.tracks)
        tracks.update({n.lower(): "bass" for n in bass_tracks})
        tracks.update({n.lower(): None for n in ignore_tracks})
        return RoutingConfig(
            self.drum_channels,
            self.bass_programs,
            self.bass_track_words,
            chans,
            tracks,
            self.names_over_programs,
        )


def _channel_list(values: Iterable[Any]) -> list[int]:
    out = []
    for v in values:
        if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 16:
            raise ConfigError(f"MIDI channel must be 1-16, got {v!r}")
        out.append(v)
    return out


def _target(value: Any, where: str) -> Route:
    if not isinstance(value, str) or value.lower() not in _TARGETS:
        raise ConfigError(f"{where}: must be one of 'bass', 'drums', 'none', got {value!r}")
    return _TARGETS[value.lower()]


def looks_like_bass(name: str, words: Iterable[str] = DEFAULT_BASS_WORDS) -> bool:
    """True if a track name reads as a bass part ("Bass", "Walking bass", "Contrabass")."""
    low = name.lower()
    if any(w in low for w in DEFAULT_NOT_BASS_WORDS):
        return False
    tokens = re.split(r"[^a-z]+", low)
    return any(w in tokens or (len(w) > 4 and w in low) for w in words)


class Router:
    """Stateful router: remembers the program in force per (source, channel).

    The source is the track index for files and the sender id for network
    input.  Events must be fed in time order (program changes take effect for
    the notes after them).  At most ``max_programs`` (source, channel) programs
    are remembered, the least recently changed forgotten first: 65,536 network
    senders cannot grow it without bound (docs/reliability.md).
    """

    max_programs = MAX_PROGRAMS

    def __init__(
        self,
        config: RoutingConfig | None = None,
        track_names: Mapping[int, str] | None = None,
        bass_program_tracks: Iterable[int] = (),
    ) -> None:
        self.config = config or RoutingConfig()
        self.track_names = dict(track_names or {})
        # tracks of the file that play a GM bass program somewhere: the bass part, so
        # a bass-named track on another instrument is not (rule 4)
        self.bass_program_tracks = frozenset(bass_program_tracks)
        self._programs: OrderedDict[tuple[int | None, int], int] = OrderedDict()
        self.programs_evicted = 0
        self.counts: Counter[tuple[int | None, int, str]] = Counter()
        # (track, channel) -> the non-bass program a bass-named track was played over
        self.named_over_program: dict[tuple[int | None, int], int] = {}
        # (track, channel) -> (its non-bass program, the track with a bass program) for a
        # bass-named track left to nobody because the file has a real bass part
        self.named_but_left: dict[tuple[int | None, int], tuple[int, int]] = {}

    @classmethod
    def for_session(cls, session: Any, config: RoutingConfig | None = None) -> Router:
        """A router for a :class:`virja.midifile.MidiSession` (knows its track names,
        and which tracks play a bass program)."""
        cfg = config or RoutingConfig()
        bass_tracks = {
            ev.track
            for ev in session.events
            if isinstance(ev, ProgramChange)
            and ev.track is not None
            and ev.program in cfg.bass_programs
            and (cfg.channels.get(ev.channel + 1, "bass") == "bass")
            and ev.channel + 1 not in cfg.drum_channels
        }
        return cls(config, {t.index: t.name for t in session.tracks}, bass_tracks)

    def _source(self, event: Event) -> int | None:
        track = getattr(event, "track", None)
        return track if track is not None else getattr(event, "sender", None)

    def route(self, event: Event) -> Route:
        """The performer of a note event; None for anything not the band's."""
        if isinstance(event, ProgramChange):
            key = (self._source(event), event.channel)
            self._programs[key] = event.program
            self._programs.move_to_end(key)
            if len(self._programs) > self.max_programs:
                self._programs.popitem(last=False)
                self.programs_evicted += 1
            return None
        if not isinstance(event, NoteOn | NoteOff):
            return None
        route = self._decide(event)
        if isinstance(event, NoteOn):
            track = getattr(event, "track", None)
            self.counts[(track, event.channel, route or "none")] += 1
        return route

    def _decide(self, event: NoteOn | NoteOff) -> Route:
        cfg = self.config
        track = event.track
        if track is not None and track in self.track_names:
            name = self.track_names[track].lower()
            if name in cfg.tracks:
                return cfg.tracks[name]
        channel_1 = event.channel + 1
        if channel_1 in cfg.channels:
            return cfg.channels[channel_1]
        if channel_1 in cfg.drum_channels:
            return "drums"
        program = self._programs.get((self._source(event), event.channel))
        named_bass = track is not None and looks_like_bass(
            self.track_names.get(track, ""), cfg.bass_track_words
        )
        if named_bass and (cfg.names_over_programs or program is None):
            if program is not None and program not in cfg.bass_programs:
                others = sorted(self.bass_program_tracks - {track})
                if others:  # the file has its bass part: this is another instrument
                    self.named_but_left[(track, event.channel)] = (program, others[0])
                    return None
                self.named_over_program[(track, event.channel)] = program
            return "bass"
        if program is not None:
            return "bass" if program in cfg.bass_programs else None
        return None

    def report(self) -> list[str]:
        """One line per (track, channel): how many notes went to whom."""
        lines = []
        for (track, channel, route), n in sorted(
            self.counts.items(), key=lambda kv: (kv[0][0] if kv[0][0] is not None else -1, kv[0][1])
        ):
            where = f"channel {channel + 1}"
            if track is not None:
                name = self.track_names.get(track, "")
                where = f"track {track}" + (f" {name!r}" if name else "") + f", {where}"
            who = {"bass": "bassist", "drums": "drummer"}.get(route, "not the band's (ignored)")
            program = self.named_over_program.get((track, channel))
            if route == "bass" and program is not None:
                who += (
                    f" (named as a bass part; its GM program {program + 1} is not a bass;"
                    " [routing] names_over_programs = false to leave it)"
                )
            left = self.named_but_left.get((track, channel))
            if route == "none" and left is not None and track is not None:
                other = self.track_names.get(left[1], "")
                who += (
                    f" (named like a bass part, but its GM program {left[0] + 1} is not a bass"
                    f" and track {left[1]}" + (f" {other!r}" if other else "") + " plays one;"
                    f" --bass-track {self.track_names.get(track, '')!r} adds it)"
                )
            lines.append(f"{where}: {n} note{'' if n == 1 else 's'} -> {who}")
        return lines


def route_all(events: Iterable[Event], router: Router) -> list[tuple[Performer, NoteOn | NoteOff]]:
    """The band's note events with their performer, in the given (time) order."""
    out: list[tuple[Performer, NoteOn | NoteOff]] = []
    for ev in events:
        who = router.route(ev)
        if who is not None and isinstance(ev, NoteOn | NoteOff):
            out.append((who, ev))
    return out
