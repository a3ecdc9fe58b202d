"""Fan committed motions out to several sinks (window, and any later consumer).

``Performance(animator=Fanout([...]))``: each committed ``PlannedNote``, beat and
note-off goes to every sink in order, on the planning thread.  A sink must
return at once (the window's process takes items through a queue); anything
slow belongs behind a queue of its own.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from virja.events import Beat, Chord, NoteOff, NoteOn
from virja.motion.pose import BandPose
from virja.plan.types import HandPin, PlannedNote
from virja.session import PlanSink
from virja.vocab import Performer


class Fanout:
    """A :class:`~virja.session.PlanSink` that forwards to several."""

    def __init__(self, sinks: Iterable[PlanSink] = ()) -> None:
        self.sinks: list[PlanSink] = []
        self._strings: tuple[str, ...] | None = None
        self._articulations: dict[int, str | None] | None = None
        for s in sinks:
            self.add(s)

    def add(self, sink: PlanSink) -> None:
        """A sink more; it learns the tuning and kit map already told (a sink added late)."""
        self.sinks.append(sink)
        if self._strings is not None:
            _tell(sink, "use_bass_strings", self._strings)
        if self._articulations is not None:
            _tell(sink, "set_articulations", self._articulations)

    def use_bass_strings(self, strings: tuple[str, ...]) -> None:
        """The tuning's strings, to every sink that plays them (and to sinks added later)."""
        self._strings = tuple(strings)
        for s in self.sinks:
            _tell(s, "use_bass_strings", self._strings)

    def set_articulations(self, articulations: Mapping[int, str | None]) -> None:
        """The kit map's articulations, to every sink that takes them (and later ones)."""
        self._articulations = dict(articulations)
        for s in self.sinks:
            _tell(s, "set_articulations", self._articulations)

    def add_planned(self, p: PlannedNote) -> None:
        for s in self.sinks:
            s.add_planned(p)

    def note_known(self, performer: Performer, note: NoteOn, at_s: float) -> None:
        """When a note became known, to every sink that animates a drummer's hands."""
        for s in self.sinks:
            call = getattr(s, "note_known", None)
            if call is not None:
                call(performer, note, at_s)

    def note_provisional(self, notes: list[PlannedNote]) -> None:
        """The plan's current hands for notes not yet started, to every sink that
        animates a drummer's hands."""
        for s in self.sinks:
            call = getattr(s, "note_provisional", None)
            if call is not None:
                call(notes)

    def shown_moving(self) -> list[HandPin]:
        """The provisional strokes drawn moving (the whole current set) by the sinks that
        draw a drummer on this side (the web feed's animator; the window's process draws
        its own, out of reach): what the performance pins for the planner."""
        out: list[HandPin] = []
        for s in self.sinks:
            call = getattr(s, "shown_moving", None)
            if call is not None:
                out.extend(call())
        return out

    def add_beat(self, beat: Beat) -> None:
        for s in self.sinks:
            s.add_beat(beat)

    def add_chord(self, chord: Chord) -> None:
        """Chords for the heads-up display of the sinks that show one."""
        for s in self.sinks:
            add = getattr(s, "add_chord", None)
            if add is not None:
                add(chord)

    def pose(self, time_s: float) -> BandPose:
        """The pose of the first sink that animates here (a BandAnimator beside the
        window's process, for the web feed); ``Performance.pose`` comes through."""
        for s in self.sinks:
            pose = getattr(s, "pose", None)
            if pose is not None:
                result: BandPose = pose(time_s)
                return result
        raise RuntimeError("no sink animates in this process")

    def forget_before(self, time_s: float) -> None:
        for s in self.sinks:
            forget = getattr(s, "forget_before", None)
            if forget is not None:
                forget(time_s)

    def note_off(self, performer: Performer, event: NoteOff) -> None:
        for s in self.sinks:
            off = getattr(s, "note_off", None)
            if off is not None:
                off(performer, event)


def _tell(sink: PlanSink, method: str, value: Any) -> None:
    call = getattr(sink, method, None)
    if call is not None:
        call(value)
