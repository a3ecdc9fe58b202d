"""Offline inputs as a reveal schedule: MIDI files and pcap recordings of RMCP.

Both become a :class:`PerformanceInput`: the events with the session time at
which each becomes known (a file's notes a beat ahead; a recording's at their
recorded receive times, through the same receiver as the live daemon), the
tempo, the events to sound in the audio track, and a report for the CLI.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from virja.errors import InputFileError
from virja.events import Event, NoteOff, NoteOn
from virja.midifile import MidiSession, read_midi
from virja.routing import Router, RoutingConfig
from virja.routing_hints import routing_hints
from virja.session import Reveal, reveal_schedule
from virja.tempo import Tempo
from virja.vocab import Performer

MIDI_SUFFIXES = frozenset({".mid", ".midi", ".smf", ".kar"})
PCAP_SUFFIXES = frozenset({".pcap", ".pcapng", ".cap"})
TAIL_S = 1.5  # frames after the last note, so the last strokes finish and ring


@dataclass
class PerformanceInput:
    kind: str  # "midi" or "pcap"
    path: Path
    schedule: list[Reveal]
    tempo: Tempo | None
    sound_events: list[Event]
    sound_origin_s: float  # session time of the audio track's t = 0
    note_count: int
    report: list[str] = field(default_factory=list)
    midi: MidiSession | None = None
    receiver_stats: dict[str, Any] = field(default_factory=dict)
    immediate: bool = False  # live notes played at once (RTP-MIDI): strokes as short as a jam's
    # the session time a user calls 0 (options like --at, printed times): a MIDI file's
    # start, a recording's first packet (its times are Unix time inside)
    start_s: float = 0.0

    def default_span(self) -> tuple[float, float]:
        """From the first reveal (early enough for the first motion) to the end plus a tail."""
        if not self.schedule:
            return (0.0, 0.0)
        first = min(r.at_s for r in self.schedule)
        last_event = max(r.event.time_s for r in self.schedule)
        start = min(first, min(r.event.time_s for r in self.schedule))
        return (start, last_event + TAIL_S)


def _routed_notes(events: Iterable[Event], router: Router) -> list[tuple[NoteOn, Performer | None]]:
    """Each note-on with the performer it goes to.  Every event goes through the
    router, so program changes take effect for the notes after them."""
    out: list[tuple[NoteOn, Performer | None]] = []
    for ev in events:
        who = router.route(ev)
        if isinstance(ev, NoteOn):
            out.append((ev, who))
    return out


def nothing_for_the_band(path: Path, report: list[str]) -> InputFileError:
    """The error for an input the band plays nothing of, with the routing hints."""
    hints = [line.removeprefix("hint: ") for line in report if line.startswith("hint: ")]
    advice = (
        f"; {hints[0]}"
        if hints
        else (
            "; if a part is the bass or the drums, route it with --bass-channel N, "
            "--drums-channel N or --bass-track NAME (docs/routing.md)"
        )
    )
    return InputFileError(path, "no notes for the band (bass or drums) in this input" + advice)


def input_kind(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in MIDI_SUFFIXES:
        return "midi"
    if suffix in PCAP_SUFFIXES:
        return "pcap"
    try:
        head = path.read_bytes()[:4]
    except OSError as exc:
        raise InputFileError(path, f"cannot read: {exc.strerror or exc}") from exc
    if head == b"MThd":
        return "midi"
    if head in (
        b"\xd4\xc3\xb2\xa1",
        b"\xa1\xb2\xc3\xd4",
        b"\x4d\x3c\xb2\xa1",
        b"\xa1\xb2\x3c\x4d",
        b"\x0a\x0d\x0d\x0a",
    ):
        return "pcap"
    raise InputFileError(path, "neither a MIDI file nor a pcap recording (by name or content)")


def load_performance_input(
    path: Path,
    routing: RoutingConfig,
    *,
    lookahead_beats: float = 1.0,
    port: int | None = None,
    key_file: str | None = None,
) -> PerformanceInput:
    """A MIDI file or a pcap recording (by name, else by content) as a reveal schedule."""
    if input_kind(path) == "midi":
        return midi_input(path, routing, lookahead_beats)
    return pcap_input(path, routing, port=port, key_file=key_file)


def midi_input(path: Path, routing: RoutingConfig, lookahead_beats: float) -> PerformanceInput:
    session = read_midi(path)
    dry = Router.for_session(session, routing)
    routed = _routed_notes(session.events, dry)
    notes = sum(1 for _note, who in routed if who is not None)
    events: list[Event] = [*session.events, *session.beats, *session.chords]
    events.sort(key=lambda e: e.time_s)
    n = len(session.tracks)
    report = [
        f"{path}: {n} track{'' if n == 1 else 's'}, {session.duration_s:.1f} s",
        *dry.report(),
        *routing_hints(routed, dry.track_names),
    ]
    return PerformanceInput(
        kind="midi",
        path=path,
        schedule=reveal_schedule(events, session.tempo_map, lookahead_beats),
        tempo=session.tempo_map,
        sound_events=list(session.events),
        sound_origin_s=0.0,
        note_count=notes,
        report=report,
        midi=session,
    )


def rtp_midi_report(rtp: Any) -> list[str]:
    if rtp.control_port is None:
        return []
    st = rtp.stats
    return [
        f"RTP-MIDI on ports {rtp.control_port}/{rtp.control_port + 1}: "
        f"{st.sessions_opened} session{'' if st.sessions_opened == 1 else 's'}, "
        f"{st.messages} MIDI message{'' if st.messages == 1 else 's'}, "
        f"drops {dict(st.dropped) or 'none'}"
    ]


def pcap_input(
    path: Path, routing: RoutingConfig, *, port: int | None = None, key_file: str | None = None
) -> PerformanceInput:
    from virja.rmcp import DEFAULT_PORT
    from virja.rmcp.pcap import read_capture
    from virja.rmcp.receiver import Receiver, ReceiverConfig
    from virja.rmcp.signing import load_key
    from virja.rtpmidi.recording import replay as rtp_midi_replay

    rmcp_port = DEFAULT_PORT if port is None else port
    cap = read_capture(path, port=None, allow_empty=True)
    start_s = min((d.time_us for d in cap.datagrams), default=0) / 1e6
    rtp = rtp_midi_replay(cap.datagrams, skip_port=rmcp_port)
    cap.datagrams = [d for d in cap.datagrams if d.dst[1] == rmcp_port]
    if not cap.datagrams and rtp.control_port is None:
        raise InputFileError(
            path,
            f"no UDP datagrams to port {rmcp_port} among {cap.packets} packets "
            "and no RTP-MIDI session (wrong --port?)",
        )
    key = load_key(key_file) if key_file else None
    receiver = Receiver(ReceiverConfig(key=key, answer_clock=False))
    schedule: list[Reveal] = []
    for dg in cap.datagrams:
        receiver.receive_datagram(dg.payload, dg.src, now_us=dg.time_us)
        for rec in receiver.drain_events():
            schedule.append(Reveal(rec.arrival_s, rec.event))
    schedule += [Reveal(rec.arrival_s, rec.event) for rec in rtp.received]
    schedule.sort(key=lambda r: r.at_s)  # stable: each source keeps its order
    dry = Router(routing)
    routed = _routed_notes((r.event for r in schedule), dry)
    notes = sum(1 for _note, who in routed if who is not None)
    sound = sorted(
        (r.event for r in schedule if isinstance(r.event, NoteOn | NoteOff)), key=lambda e: e.time_s
    )
    origin = sound[0].time_s if sound else 0.0
    # no tempo up front: as live, the scheduler learns the tempo from BEAT messages
    tempo: Tempo | None = None
    stats = receiver.stats.as_dict()
    report = [
        f"{path}: {cap.packets} packets, {len(cap.datagrams)} RMCP datagrams, "
        f"{stats['events']} events accepted, drops {stats['dropped'] or 'none'}",
        *rtp_midi_report(rtp),
        *dry.report(),
        *routing_hints(routed, {}),
    ]
    return PerformanceInput(
        kind="pcap",
        path=path,
        schedule=schedule,
        tempo=tempo,
        sound_events=list(sound),
        sound_origin_s=origin,
        note_count=notes,
        report=report,
        receiver_stats=stats,
        immediate=rtp.control_port is not None,
        start_s=start_s,
    )
