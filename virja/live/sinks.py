"""Fan committed motions out to several sinks (window, and any later consumer).

``Performance(animator=Fanout([...]))``: each committed ``PlannedNote``, beat and
note-off goes to every sink in order, on the planning thread.  A sink must
return at once (the window's process takes items through a queue); anything
slow belongs behind a queue of its own.
"""

from __future__ import annotations

from collections.abc import Iterable

from virja.events import Beat, Chord, NoteOff
from virja.motion.pose import BandPose
from virja.plan.types import PlannedNote
from virja.session import PlanSink
from virja.vocab import Performer


class Fanout:
    """A :class:`~virja.session.PlanSink` that forwards to several."""

    def __init__(self, sinks: Iterable[PlanSink] = ()) -> None:
        self.sinks: list[PlanSink] = list(sinks)

    def add(self, sink: PlanSink) -> None:
        self.sinks.append(sink)

    def add_planned(self, p: PlannedNote) -> None:
        for s in self.sinks:
            s.add_planned(p)

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
