"""RTP-MIDI as events: live (:func:`to_received`) and from a recording (:func:`replay`).

A recording made by ``virja serve --record`` holds every datagram that came
in on the control and data ports (as RMCP's are held).  :func:`replay` finds
the control port (where the first invitation went; data is the next port)
and feeds the datagrams, at their recorded times, through the same
:class:`~virja.rtpmidi.host.SessionHost` as the live listener, so replaying
gives the events the live daemon got.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from virja.rmcp.bodies import MidiBody
from virja.rmcp.pcap import CapturedDatagram
from virja.rmcp.receiver import Received
from virja.rmcp.wire import midi_events
from virja.rtpmidi.control import SIGNATURE, Command
from virja.rtpmidi.host import Channel, HostStats, Incoming, SessionHost

INVITATION_HEAD = SIGNATURE.to_bytes(2, "big") + Command.IN.to_bytes(2, "big")


def to_received(messages: Iterable[Incoming]) -> list[Received]:
    """The band's events in the messages (note on/off, controllers, programs),
    each at its message's time and arrival; everything else is left out."""
    out: list[Received] = []
    for m in messages:
        for ev in midi_events(MidiBody((m.data,)), m.time_s, m.ssrc):
            out.append(Received(ev, m.arrival_s))
    return out


@dataclass
class Replayed:
    control_port: int | None = None
    received: list[Received] = field(default_factory=list)
    stats: HostStats = field(default_factory=HostStats)


def control_port(
    datagrams: Iterable[CapturedDatagram], *, skip_port: int | None = None
) -> int | None:
    """The port the first AppleMIDI invitation in a capture was sent to."""
    for d in datagrams:
        if d.payload[:4] == INVITATION_HEAD and d.dst[1] != skip_port:
            return d.dst[1]
    return None


def replay(datagrams: list[CapturedDatagram], *, skip_port: int | None = None) -> Replayed:
    """The RTP-MIDI events of a capture, received as the live listener received them."""
    port = control_port(datagrams, skip_port=skip_port)
    out = Replayed(port)
    if port is None:
        return out
    host = SessionHost()
    for d in datagrams:
        if d.dst[1] not in (port, port + 1):
            continue
        channel = Channel.CONTROL if d.dst[1] == port else Channel.DATA
        host.receive_datagram(d.payload, d.src, channel=channel, now_us=d.time_us)
        host.tick(d.time_us)
        out.received.extend(to_received(host.drain_messages()))
    out.stats = host.stats
    return out
