"""Hints for routing that did not find the band: which flag or config line would.

After a file is routed, a part nobody plays that looks like a bass line, or a
file whose drums no channel carries, gets one line saying what to type.  Pure:
the notes and what the router decided go in, sentences come out.
"""

from __future__ import annotations

import statistics
from collections import defaultdict
from collections.abc import Iterable, Mapping

from virja.events import NoteOn
from virja.vocab import Performer

BASS_TOP_NOTE = 55  # G3: a bass line lives below it (the open G string is G2, 43)
# the kit's core in the GM drum map: a drum part is mostly these, from two families or more
KIT_FAMILIES = (
    frozenset({35, 36}),  # kick
    frozenset({37, 38, 40}),  # snare, side stick
    frozenset({42, 44, 46, 49, 51, 53, 57, 59}),  # hi-hat, crash, ride
)


def _name(note: int) -> str:
    names = ("C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B")
    return f"{names[note % 12]}{note // 12 - 1}"


def _monophonic_share(onsets: list[float]) -> float:
    """The share of notes that start alone (no other onset within 30 ms)."""
    if len(onsets) < 2:
        return 1.0
    onsets = sorted(onsets)
    alone = sum(
        1
        for i, t in enumerate(onsets)
        if (i == 0 or t - onsets[i - 1] > 0.03)
        and (i + 1 == len(onsets) or onsets[i + 1] - t > 0.03)
    )
    return alone / len(onsets)


def _looks_like_drums(pitches: list[int]) -> bool:
    """Mostly (80 %) the kit's core notes, from at least two of its families (kick, snare,
    cymbals), on few pitches: a walking line's wider range of pitches reads as a bass."""
    core = [p for p in pitches if any(p in fam for fam in KIT_FAMILIES)]
    families = sum(1 for fam in KIT_FAMILIES if any(p in fam for p in pitches))
    return len(core) >= 0.8 * len(pitches) and families >= 2 and len(set(pitches)) <= 8


def routing_hints(
    notes: Iterable[tuple[NoteOn, Performer | None]], track_names: Mapping[int, str]
) -> list[str]:
    """Lines of advice: for each unrouted part that looks like a bass line, and when no
    note went to the drummer although a channel looks like a drum part."""
    parts: dict[tuple[int | None, int], list[NoteOn]] = defaultdict(list)
    routed: set[Performer] = set()
    for note, who in notes:
        if who is None:
            parts[(note.track, note.channel)].append(note)
        else:
            routed.add(who)
    hints: list[str] = []
    for (track, channel), part in sorted(parts.items(), key=lambda kv: (kv[0][0] or -1, kv[0][1])):
        where = f"channel {channel + 1}"
        name = track_names.get(track, "") if track is not None else ""
        if track is not None:
            where = f"track {track}" + (f" {name!r}" if name else "") + f", {where}"
        pitches = [n.note for n in part]
        median = statistics.median(pitches)
        if "drums" not in routed and len(part) >= 8 and _looks_like_drums(pitches):
            hints.append(
                f"hint: {where} ({len(part)} notes on {len(set(pitches))} pitches of the GM "
                f"drum map) may be the drums; to give it to the drummer: --drums-channel "
                f'{channel + 1}, or [routing] channels = {{ "{channel + 1}" = "drums" }}'
            )
        elif (
            "bass" not in routed
            and len(part) >= 8
            and median < BASS_TOP_NOTE
            and _monophonic_share([n.time_s for n in part]) >= 0.8
        ):
            flag = f"--bass-track {name!r}" if name else f"--bass-channel {channel + 1}"
            hints.append(
                f"hint: {where} ({len(part)} notes, a single line around {_name(round(median))}) "
                f"looks like a bass part nobody plays; to give it to the bassist: {flag}, or "
                f'[routing] channels = {{ "{channel + 1}" = "bass" }} in a --config file'
            )
    return hints
