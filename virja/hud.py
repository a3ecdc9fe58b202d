"""What the heads-up display says at a moment: tempo, bar.beat and chord (pure).

Beats and chords arrive ahead of the moment they describe (RMCP sends them
about a beat early; a file's are all known at once), so they are kept as a
time line and read at the time of the frame.  Entries older than the newest
frame time minus ``KEEP_S`` are pruned: memory stays bounded in a long session.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from virja.chords import chord_name
from virja.events import Beat, Chord

KEEP_S = 30.0  # history kept behind the newest moment asked for


@dataclass(frozen=True)
class HudInfo:
    tempo_bpm: float | None
    bar: int | None  # 1-based, as musicians count
    beat: int | None  # 1-based
    chord: str | None

    def text(self) -> str:
        """One line: "132 bpm   bar 5.3   F7" (parts not known yet left out)."""
        parts = []
        if self.tempo_bpm is not None:
            parts.append(f"{self.tempo_bpm:.0f} bpm")
        if self.bar is not None and self.beat is not None:
            parts.append(f"bar {self.bar}.{self.beat}")
        if self.chord is not None:
            parts.append(self.chord)
        return "   ".join(parts)


class HudTimeline:
    """Beats and chords by time; :meth:`at` answers for any moment."""

    def __init__(self) -> None:
        self._beat_t: list[float] = []
        self._beats: list[Beat] = []
        self._chord_t: list[float] = []
        self._chords: list[Chord] = []

    def add(self, event: Beat | Chord) -> None:
        times, items = (
            (self._beat_t, self._beats)
            if isinstance(event, Beat)
            else (self._chord_t, self._chords)
        )
        i = bisect.bisect_right(times, event.time_s)
        times.insert(i, event.time_s)
        items.insert(i, event)  # type: ignore[arg-type]

    def at(self, time_s: float) -> HudInfo:
        self._prune(time_s - KEEP_S)
        tempo = bar = beat = None
        i = bisect.bisect_right(self._beat_t, time_s) - 1
        if i >= 0:
            b = self._beats[i]
            tempo, bar, beat = 60e6 / b.tempo_us, b.bar + 1, b.beat
        j = bisect.bisect_right(self._chord_t, time_s) - 1
        chord = chord_name(self._chords[j]) if j >= 0 else None
        return HudInfo(tempo, bar, beat, chord)

    def _prune(self, before_s: float) -> None:
        """Drop entries superseded before ``before_s`` (the last one before it stays)."""
        for times, items in ((self._beat_t, self._beats), (self._chord_t, self._chords)):
            k = bisect.bisect_left(times, before_s) - 1
            if k > 0:
                del times[:k]
                del items[:k]

    def __len__(self) -> int:
        return len(self._beats) + len(self._chords)
