"""The plan as notation: MusicXML 4.0 with the bassist's strings and frets and the drummer's sticking.

Two parts:

- **Bass** (``P1``): two staves, a bass clef written an octave above sounding
  (the part says so with ``<transpose>``: octave-change -1, as bass parts are
  written) and a tablature staff (one line per string of the planned tuning,
  ``<staff-tuning>`` in written pitch).  Every note carries
  ``<technical><string>N</string><fret>F</fret></technical>`` as the scheduler
  chose it (string 1 is the highest string, MusicXML's numbering).
- **Drums** (``P2``): a five-line percussion staff; the GM/TD note's piece and
  articulation from the kit map (``motions/drum_kit.toml``) choose the staff
  position and notehead (:data:`NOTATION`); voice 1 the hands (stems up), with
  the sticking ``R``/``L`` the scheduler chose as a lyric under each stroke
  (two hands at once read top to bottom, e.g. ``RL``); voice 2 the feet
  (stems down).

Times are quantised to sixteenths of a quarter-note beat of the input's tempo
map (a MIDI file's; a recording's BEAT messages); a note lasts until the next
one in its voice, at most to the bar line.  Tempo marks and time signatures
come from the input (4/4 and 120 bpm when it says nothing).
"""

from __future__ import annotations

import bisect
import xml.etree.ElementTree as ET
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from virja.events import Beat
from virja.plan.config import PlanConfig
from virja.plan.types import PlannedNote
from virja.tempo import Tempo
from virja.vocab import FEET

DIVISIONS = 4  # per quarter note: sixteenth-note resolution
# sixteenths -> (type, dots), the values a note or rest may take
VALUES = {
    16: ("whole", 0),
    12: ("half", 1),
    8: ("half", 0),
    6: ("quarter", 1),
    4: ("quarter", 0),
    3: ("eighth", 1),
    2: ("eighth", 0),
    1: ("16th", 0),
}
STEPS = ("C", "D", "D", "E", "E", "F", "G", "G", "A", "A", "B", "B")
ALTERS = (0, -1, 0, -1, 0, 0, -1, 0, -1, 0, -1, 0)  # flats, as jazz charts spell them

# (piece, articulation) -> (display step, display octave, notehead); the usual
# drum-set staff (PAS / Weinberg): kick F4, snare C5, toms E5 D5 A4, hi-hat G5 (x),
# hi-hat pedal D4 (x), ride F5 (x), crash A5 (x), crash 2 B5 (x: the space above
# crash 1's ledger line, where drum charts put a second crash)
NOTATION: dict[tuple[str, str | None], tuple[str, int, str]] = {
    ("kick", None): ("F", 4, "normal"),
    ("snare", None): ("C", 5, "normal"),
    ("snare", "rim"): ("C", 5, "x"),
    ("tom_high", None): ("E", 5, "normal"),
    ("tom_low", None): ("D", 5, "normal"),
    ("tom_floor", None): ("A", 4, "normal"),
    ("hihat", None): ("G", 5, "x"),
    ("hihat", "closed"): ("G", 5, "x"),
    ("hihat", "open"): ("G", 5, "circle-x"),
    ("hihat", "pedal"): ("D", 4, "x"),
    ("ride", None): ("F", 5, "x"),
    ("ride", "bell"): ("F", 5, "diamond"),
    ("crash", None): ("A", 5, "x"),
    ("crash2", None): ("B", 5, "x"),
}
STICKING = {"right_hand": "R", "left_hand": "L"}


def notation(piece: str, articulation: str | None) -> tuple[str, int, str]:
    """Staff position and notehead of a kit piece played with ``articulation``."""
    return NOTATION.get((piece, articulation)) or NOTATION.get((piece, None)) or ("C", 5, "normal")


@dataclass(frozen=True)
class Mark:
    """One note on the grid: ``at`` in sixteenths from the score's origin."""

    at: int
    note: PlannedNote
    articulation: str | None = None


@dataclass
class Score:
    """The quantised plan: measures (start, length in sixteenths, num, den) and the marks."""

    title: str
    measures: list[tuple[int, int, int, int]]
    tempos: dict[int, float]  # measure index -> quarter notes per minute
    bass: list[Mark]
    drums: list[Mark]
    strings: tuple[tuple[str, int], ...]  # low to high: (name, open MIDI note)
    kit_names: dict[int, str] = field(default_factory=dict)  # GM note -> instrument name

    @classmethod
    def build(
        cls,
        notes: list[PlannedNote],
        config: PlanConfig,
        *,
        tempo: Tempo | None,
        beats: list[Beat],
        time_signatures: list[tuple[float, int, int]],
        title: str = "virja",
        origin_s: float = 0.0,
    ) -> Score:
        """``origin_s``: the session time of the input's start (a recording's first
        packet), beat 0 when neither a tempo map nor BEATs give the beats."""
        grid = _Grid(tempo, beats, origin_s)
        marks = [(grid.sixteenth(p.time), p) for p in notes]
        lo = min((m for m, _ in marks), default=0)
        hi = max((m for m, _ in marks), default=0)
        sigs = [(grid.sixteenth(t), n, d) for t, n, d in time_signatures] or [
            (grid.origin, grid.beats_per_bar, 4)
        ]
        measures = _measures(sigs, lo, hi)
        starts = [m[0] for m in measures]
        tempos: dict[int, float] = {}
        for t, qpm in grid.tempo_changes():
            k = max(bisect.bisect_right(starts, grid.sixteenth(t)) - 1, 0)
            tempos[k] = qpm
        if 0 not in tempos:
            tempos[0] = grid.tempo_changes()[0][1] if grid.tempo_changes() else 120.0
        bass, drums = [], []
        names: dict[int, str] = {}
        for at, p in marks:
            if p.performer == "bass":
                bass.append(Mark(at, p))
            else:
                entry = config.kit.lookup(p.note)
                names[p.note] = entry.name if entry is not None else f"note {p.note}"
                drums.append(Mark(at, p, entry.articulation if entry is not None else None))
        return cls(title, measures, tempos, bass, drums, config.bass.strings, names)


class _Grid:
    """Session seconds -> sixteenths of the quarter-note beat, from a tempo map or BEATs."""

    def __init__(self, tempo: Tempo | None, beats: list[Beat], origin_s: float = 0.0) -> None:
        self.tempo = tempo
        self.origin_s = origin_s
        self.beat_times = [b.time_s for b in beats]
        self.beats = beats
        self.origin = 0
        self.beats_per_bar = 4
        if beats and not hasattr(tempo, "beat_at"):
            heads = [b for b in beats if b.beat == 1]
            if heads:
                self.origin = self.sixteenth(heads[0].time_s)
            self.beats_per_bar = max(beats[0].beats_per_bar, 1)

    def quarters(self, t: float) -> float:
        beat_at = getattr(self.tempo, "beat_at", None)
        if beat_at is not None:
            return float(beat_at(t))
        bt = self.beat_times
        if len(bt) < 2:
            spb = self.tempo.seconds_per_beat_at(t) if self.tempo is not None else 0.5
            return (t - (bt[0] if bt else self.origin_s)) / spb
        i = min(max(bisect.bisect_right(bt, t) - 1, 0), len(bt) - 2)
        return i + (t - bt[i]) / (bt[i + 1] - bt[i])

    def sixteenth(self, t: float) -> int:
        return round(self.quarters(t) * DIVISIONS)

    def tempo_changes(self) -> list[tuple[float, float]]:
        changes = getattr(self.tempo, "changes", None)
        if changes is not None:
            return [(float(t), 60.0 / float(spb)) for t, spb in changes]
        out: list[tuple[float, float]] = []
        for b in self.beats:
            qpm = 60e6 / b.tempo_us
            if not out or abs(qpm - out[-1][1]) > 0.01 * out[-1][1]:
                out.append((b.time_s, qpm))
        return out


def _measures(
    sigs: list[tuple[int, int, int]], lo: int, hi: int
) -> list[tuple[int, int, int, int]]:
    """Bars covering sixteenths [lo, hi]: (start, length, num, den), signatures from ``sigs``."""
    sigs = sorted(sigs)
    at, num, den = sigs[0]
    length = max(num * 16 // den, 1)
    start = at
    while start > lo:
        start -= length
    out: list[tuple[int, int, int, int]] = []
    k = 1
    while start <= hi or not out:
        while k < len(sigs) and sigs[k][0] <= start:
            _, num, den = sigs[k]
            length = max(num * 16 // den, 1)
            k += 1
        out.append((start, length, num, den))
        start += length
    return out


# ---------------------------------------------------------------- writing


def _sub(parent: ET.Element, tag: str, text: str | None = None, **attrib: str) -> ET.Element:
    e = ET.SubElement(parent, tag, attrib)
    if text is not None:
        e.text = text
    return e


def _split(n: int) -> list[int]:
    """Sixteenths as note values, longest first."""
    out = []
    while n > 0:
        v = max(v for v in VALUES if v <= n)
        out.append(v)
        n -= v
    return out


def _rests(m: ET.Element, n: int, voice: str, staff: str | None, whole_bar: bool = False) -> None:
    if whole_bar:
        note = _sub(m, "note")
        _sub(note, "rest", measure="yes")
        _sub(note, "duration", str(n))
        _sub(note, "voice", voice)
        if staff:
            _sub(note, "staff", staff)
        return
    for v in _split(n):
        note = _sub(m, "note")
        _sub(note, "rest")
        _sub(note, "duration", str(v))
        _sub(note, "voice", voice)
        kind, dots = VALUES[v]
        _sub(note, "type", kind)
        for _ in range(dots):
            _sub(note, "dot")
        if staff:
            _sub(note, "staff", staff)


NoteWriter = Callable[[ET.Element, Mark, int, str, bool, list[Mark]], None]


def _voice(
    m: ET.Element,
    start: int,
    length: int,
    chords: list[tuple[int, list[Mark]]],
    voice: str,
    staff: str | None,
    write_note: NoteWriter,
) -> None:
    """Fill one voice of one bar: rests, then each chord until the next, rests to the bar line."""
    if not chords:
        _rests(m, length, voice, staff, whole_bar=True)
        return
    pos = 0
    for k, (at, group) in enumerate(chords):
        rel = at - start
        if rel > pos:
            _rests(m, rel - pos, voice, staff)
        nxt = chords[k + 1][0] - start if k + 1 < len(chords) else length
        dur = max(v for v in VALUES if v <= nxt - rel)
        for i, mark in enumerate(group):
            note = _sub(m, "note")
            if i:
                _sub(note, "chord")
            write_note(note, mark, dur, voice, i == 0, group)
        if nxt - rel > dur:
            _rests(m, nxt - rel - dur, voice, staff)
        pos = nxt


def _type(note: ET.Element, dur: int) -> None:
    kind, dots = VALUES[dur]
    _sub(note, "type", kind)
    for _ in range(dots):
        _sub(note, "dot")


def _by_bar(
    marks: list[Mark], measures: list[tuple[int, int, int, int]]
) -> list[list[tuple[int, list[Mark]]]]:
    starts = [m[0] for m in measures]
    bars: list[dict[int, list[Mark]]] = [defaultdict(list) for _ in measures]
    for mk in marks:
        k = bisect.bisect_right(starts, mk.at) - 1
        if 0 <= k < len(measures):
            bars[k][mk.at].append(mk)
    return [sorted(b.items()) for b in bars]


def _attributes(
    m: ET.Element, k: int, meas: tuple[int, int, int, int], prev: tuple[int, int] | None
) -> ET.Element | None:
    _, _, num, den = meas
    if k > 0 and prev == (num, den):
        return None
    a = _sub(m, "attributes")
    if k == 0:
        _sub(a, "divisions", str(DIVISIONS))
        key = _sub(a, "key")
        _sub(key, "fifths", "0")
    t = _sub(a, "time")
    _sub(t, "beats", str(num))
    _sub(t, "beat-type", str(den))
    return a


def _tempo(m: ET.Element, qpm: float) -> None:
    d = _sub(m, "direction", placement="above")
    dt = _sub(d, "direction-type")
    mt = _sub(dt, "metronome")
    _sub(mt, "beat-unit", "quarter")
    _sub(mt, "per-minute", f"{qpm:.0f}")
    _sub(d, "sound", tempo=f"{qpm:.2f}")


def _bass_part(root: ET.Element, s: Score) -> None:
    part = _sub(root, "part", id="P1")
    names = [n for n, _ in s.strings]
    number = {n: len(names) - i for i, n in enumerate(names)}  # 1 = highest string
    bars = _by_bar(s.bass, s.measures)
    prev = None

    def write(
        note: ET.Element, mk: Mark, dur: int, voice: str, first: bool, _g: list[Mark], staff: str
    ) -> None:
        written = mk.note.note + 12  # bass parts are written an octave above sounding
        p = _sub(note, "pitch")
        _sub(p, "step", STEPS[written % 12])
        if ALTERS[written % 12]:
            _sub(p, "alter", str(ALTERS[written % 12]))
        _sub(p, "octave", str(written // 12 - 1))
        _sub(note, "duration", str(dur))
        _sub(note, "voice", voice)
        _type(note, dur)
        _sub(note, "staff", staff)
        tech = _sub(_sub(note, "notations"), "technical")
        _sub(tech, "string", str(number.get(mk.note.string or "", 1)))
        _sub(tech, "fret", str(mk.note.fret or 0))

    for k, meas in enumerate(s.measures):
        m = _sub(part, "measure", number=str(k + 1))
        a = _attributes(m, k, meas, prev)
        if a is not None and k == 0:
            _sub(a, "staves", "2")
            c1 = _sub(a, "clef", number="1")
            _sub(c1, "sign", "F")
            _sub(c1, "line", "4")
            c2 = _sub(a, "clef", number="2")
            _sub(c2, "sign", "TAB")
            _sub(c2, "line", "5")
            sd = _sub(a, "staff-details", number="2")
            _sub(sd, "staff-lines", str(len(s.strings)))
            for line, (_, open_note) in enumerate(s.strings, 1):
                wt = open_note + 12
                st = _sub(sd, "staff-tuning", line=str(line))
                _sub(st, "tuning-step", STEPS[wt % 12])
                if ALTERS[wt % 12]:
                    _sub(st, "tuning-alter", str(ALTERS[wt % 12]))
                _sub(st, "tuning-octave", str(wt // 12 - 1))
            tr = _sub(a, "transpose")
            _sub(tr, "diatonic", "0")
            _sub(tr, "chromatic", "0")
            _sub(tr, "octave-change", "-1")  # sounding = written an octave lower
        prev = (meas[2], meas[3])
        if k in s.tempos:
            _tempo(m, s.tempos[k])
        for voice, staff in (("1", "1"), ("5", "2")):
            if staff == "2":
                b = _sub(m, "backup")
                _sub(b, "duration", str(meas[1]))

            def w(
                note: ET.Element,
                mk: Mark,
                dur: int,
                v: str,
                f: bool,
                g: list[Mark],
                st: str = staff,
            ) -> None:
                write(note, mk, dur, v, f, g, st)

            _voice(m, meas[0], meas[1], bars[k], voice, staff, w)


def _drum_part(root: ET.Element, s: Score) -> None:
    part = _sub(root, "part", id="P2")
    hands = [mk for mk in s.drums if mk.note.limb not in FEET]
    feet = [mk for mk in s.drums if mk.note.limb in FEET]
    hand_bars = _by_bar(hands, s.measures)
    foot_bars = _by_bar(feet, s.measures)
    prev = None

    def write(
        note: ET.Element, mk: Mark, dur: int, voice: str, first: bool, group: list[Mark]
    ) -> None:
        step, octave, head = notation(mk.note.piece or "", mk.articulation)
        u = _sub(note, "unpitched")
        _sub(u, "display-step", step)
        _sub(u, "display-octave", str(octave))
        _sub(note, "duration", str(dur))
        _sub(note, "instrument", id=f"P2-I{mk.note.note}")
        _sub(note, "voice", voice)
        _type(note, dur)
        _sub(note, "stem", "up" if voice == "1" else "down")
        _sub(note, "notehead", head)
        if first and voice == "1":
            sticking = "".join(STICKING.get(g.note.limb, "") for g in group)
            if sticking:
                ly = _sub(note, "lyric", number="1")
                _sub(ly, "syllabic", "single")
                _sub(ly, "text", sticking)

    for k, meas in enumerate(s.measures):
        m = _sub(part, "measure", number=str(k + 1))
        a = _attributes(m, k, meas, prev)
        if a is not None and k == 0:
            c = _sub(a, "clef")
            _sub(c, "sign", "percussion")
            sd = _sub(a, "staff-details")
            _sub(sd, "staff-lines", "5")
        prev = (meas[2], meas[3])
        # hands top to bottom on the staff, so the sticking reads like the chord
        hb = [(at, sorted(g, key=_height, reverse=True)) for at, g in _dedupe(hand_bars[k])]
        _voice(m, meas[0], meas[1], hb, "1", None, write)
        b = _sub(m, "backup")
        _sub(b, "duration", str(meas[1]))
        _voice(m, meas[0], meas[1], _dedupe(foot_bars[k]), "2", None, write)


def _height(mk: Mark) -> int:
    step, octave, _ = notation(mk.note.piece or "", mk.articulation)
    return octave * 7 + "CDEFGAB".index(step)


def _dedupe(chords: list[tuple[int, list[Mark]]]) -> list[tuple[int, list[Mark]]]:
    """One notehead per staff position and limb in a chord (a flam's grace is not written)."""
    out = []
    for at, group in chords:
        seen: set[tuple[int, str]] = set()
        keep = []
        for mk in group:
            key = (_height(mk), mk.note.limb)
            if key not in seen:
                seen.add(key)
                keep.append(mk)
        out.append((at, keep))
    return out


def to_element(s: Score) -> ET.Element:
    root = ET.Element("score-partwise", version="4.0")
    work = _sub(root, "work")
    _sub(work, "work-title", s.title)
    ident = _sub(root, "identification")
    enc = _sub(ident, "encoding")
    _sub(enc, "software", "virja export")
    pl = _sub(root, "part-list")
    sp = _sub(pl, "score-part", id="P1")
    _sub(sp, "part-name", "Bass")
    si = _sub(sp, "score-instrument", id="P1-I1")
    _sub(si, "instrument-name", "Acoustic Bass")
    mi = _sub(sp, "midi-instrument", id="P1-I1")
    _sub(mi, "midi-channel", "2")
    _sub(mi, "midi-program", "33")
    sp = _sub(pl, "score-part", id="P2")
    _sub(sp, "part-name", "Drums")
    for note, name in sorted(s.kit_names.items()):
        si = _sub(sp, "score-instrument", id=f"P2-I{note}")
        _sub(si, "instrument-name", name)
    for note in sorted(s.kit_names):
        mi = _sub(sp, "midi-instrument", id=f"P2-I{note}")
        _sub(mi, "midi-channel", "10")
        _sub(mi, "midi-unpitched", str(note + 1))
    _bass_part(root, s)
    _drum_part(root, s)
    return root


def write_musicxml(s: Score, path: Path) -> Path:
    """Write ``s`` as an uncompressed MusicXML 4.0 partwise file."""
    tree = ET.ElementTree(to_element(s))
    ET.indent(tree, space=" ")
    with path.open("wb") as f:
        f.write(b'<?xml version="1.0" encoding="UTF-8"?>\n')
        f.write(
            b'<!DOCTYPE score-partwise PUBLIC "-//Recordare//DTD MusicXML 4.0 Partwise//EN" '
            b'"http://www.musicxml.org/dtds/partwise.dtd">\n'
        )
        tree.write(f, encoding="utf-8", xml_declaration=False)
    return path
