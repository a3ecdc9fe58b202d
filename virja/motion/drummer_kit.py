"""The hi-hat's openness from the notes (issue 15, deliverable 4).

A closed (42, its edge), pedal (44) or open (46, its edge) hi-hat note says
where the two cymbals are at its impact; the kit map's ``articulation`` field
names which (``closed``, ``closed_edge``, ``pedal``, ``open``, ``open_edge``).
Between notes the cymbals hold the last note's state; a change moves
linearly over ``lead_s`` before the impact (the foot lifts or presses just
ahead of the stroke), starting no earlier than the note before (which lands
on its own state: a chick 50 ms before an open stroke is shut at its
impact, then the foot lifts), and an open hi-hat left alone closes again after
``hold_open_s`` (the foot comes back down to rest); before the first note
they are closed.  Just before a pedal note (a foot chick) the cymbals follow
the left foot's lift, weighted up to its impact, when the foot presses them
shut.  With no articulated hi-hat note at all (no kit map given)
the caller falls back to the left toe on the pedal.
"""

from __future__ import annotations

import bisect

from virja import tomlconf
from virja.errors import ConfigError
from virja.kit_file import KitFile

OPEN = frozenset({"open", "open_edge"})
CLOSED = frozenset({"closed", "closed_edge", "pedal"})


def default_articulations() -> dict[int, str | None]:
    """Articulation per note number from the shipped kit map (motions/drum_kit.toml,
    ``[notes]``, schema :class:`virja.kit_file.KitFile`), so every animator, in any
    process, opens the hi-hat by the notes; a user's kit map replaces it through
    ``BandAnimator.set_articulations``.  The planner reports a kit map that does not
    fit its schema; here such a file, or a note key that is not a number, gives no
    articulations."""
    from virja.resources import motions_dir

    try:
        kit = tomlconf.load(motions_dir() / "drum_kit.toml", KitFile)
    except ConfigError:
        return {}
    return {int(key): entry.articulation for key, entry in kit.notes.items() if key.isdigit()}


class HihatState:
    """Hi-hat notes in time order, and the openness (0 closed .. 1 open) they imply."""

    def __init__(self, lead_s: float = 0.06, hold_open_s: float = 1.0) -> None:
        self.lead_s = lead_s
        self.hold_open_s = hold_open_s
        self._times: list[float] = []
        self._open: list[float] = []
        self._pedal: list[float] = []

    def add(self, time_s: float, articulation: str | None) -> None:
        """Record a hi-hat note; articulations other than open/closed/pedal are ignored."""
        if articulation in OPEN:
            value = 1.0
        elif articulation in CLOSED:
            value = 0.0
        else:
            return
        i = bisect.bisect_right(self._times, time_s)
        self._times.insert(i, time_s)
        self._open.insert(i, value)
        if articulation == "pedal":
            bisect.insort(self._pedal, time_s)

    def chick_weight(self, t: float, window_s: float = 0.25) -> float:
        """0..1, rising over ``window_s`` to a pedal note's impact: how much the foot's own
        lift opens the cymbals (a foot chick opens them a little and shuts them on the beat).
        The lift starts after the hi-hat note before the chick (0 at its impact), so a
        closed stroke just before a chick still lands on shut cymbals."""
        i = bisect.bisect_left(self._pedal, t)
        if i == len(self._pedal):
            return 0.0
        at = self._pedal[i]
        k = bisect.bisect_left(self._times, at) - 1  # the last hi-hat note before the chick
        if k >= 0:
            window_s = min(window_s, at - self._times[k])
        if window_s <= 0.0:
            return 0.0
        return max(0.0, 1.0 - (at - t) / window_s)

    def forget_before(self, time_s: float) -> None:
        k = max(bisect.bisect_left(self._times, time_s - 10.0) - 1, 0)
        del self._times[:k]
        del self._open[:k]
        del self._pedal[: bisect.bisect_left(self._pedal, time_s - 10.0)]

    def openness(self, t: float) -> float | None:
        """Openness at ``t``, or None when no note says (the pedal decides then)."""
        if not self._times:
            return None
        k = bisect.bisect_right(self._times, t) - 1
        n = k + 1
        upcoming = n < len(self._times) and self._times[n] - self.lead_s < t
        if k >= 0:
            since = t - self._times[k]
            cur = self._open[k]
            if cur > 0 and since > self.hold_open_s:
                cur = max(0.0, 1.0 - (since - self.hold_open_s) / self.lead_s)
        else:
            cur = 0.0
        if upcoming:
            # the change starts lead_s ahead, but not before the last note's impact:
            # that note lands on the state it asks for (a chick 49 ms before an
            # open stroke is shut, then the foot lifts)
            start = self._times[n] - self.lead_s
            if k >= 0:
                start = max(start, self._times[k])
            w = (t - start) / (self._times[n] - start)
            cur += (self._open[n] - cur) * min(max(w, 0.0), 1.0)
        return cur


__all__ = ["HihatState", "OPEN", "CLOSED", "default_articulations"]
