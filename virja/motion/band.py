"""``BandAnimator``: planned notes in, a :class:`~virja.motion.pose.BandPose` out.

Each planned note becomes clip instances on limb timelines
(:mod:`virja.motion.timeline`): a drum note one instance on its limb; a bass
note a right-hand pluck and, for a stopped note, a left-hand hold at its
string and fret.  Each figure has an idle base layer (its rest pose, with the
head nodding on the beat); limbs are combined by joint masks over it, so the
drummer's two hands and two feet and the bassist's two hands move
independently.  Both figures share one skeleton, so FK runs once for both.
"""

from __future__ import annotations

import bisect
import logging
import math
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from virja import quat
from virja.events import Beat
from virja.geometry import GEOMETRY, Geometry
from virja.motion import bass_lean
from virja.motion.bassist import CHEST, Bassist, BassistSettings
from virja.motion.clip import Clip, MotionLibrary, UnknownMotionError, default_library
from virja.motion.drummer_body import BodySettings, DrummerBody
from virja.motion.drummer_hands import DrummerHands, HandSettings
from virja.motion.drummer_kit import HihatState, default_articulations
from virja.motion.hits import Hit, HitTable
from virja.motion.pose import BandPose, FigurePose
from virja.motion.pose_batch import BandPoses
from virja.motion.skeleton import (
    LIMB_JOINTS,
    SKELETON,
    STICK_AXIS_LOCAL,
    STICK_BUTT_M,
    STICK_TIP_M,
)
from virja.motion.timeline import Instance, Timeline, blend_many
from virja.plan.types import HandPin
from virja.vocab import (
    ALL_BASS_STRINGS,
    BASS_STRINGS,
    CYMBAL_PIECES,
    DRUM_PIECES,
    FRET_OPEN_CLIP,
    PERFORMER_LIMBS,
    BassPluck,
    DrumStroke,
    Hand,
    MotionKey,
    Performer,
    idle_clip,
)

log = logging.getLogger(__name__)

FIGURES: tuple[Performer, ...] = ("drums", "bass")  # the figures' order in poses and exports
_SK = SKELETON
_NECK = _SK.index("Neck")
_HEAD = _SK.index("Head")


class PlannedNoteLike(Protocol):
    """The fields of ``virja.plan.types.PlannedNote`` the animator reads (read-only)."""

    @property
    def time(self) -> float: ...

    @property
    def performer(self) -> str: ...

    @property
    def velocity(self) -> int: ...

    @property
    def note(self) -> int: ...

    @property
    def limb(self) -> str: ...

    @property
    def piece(self) -> str | None: ...

    @property
    def string(self) -> str | None: ...

    @property
    def fret(self) -> int | None: ...

    @property
    def motion(self) -> MotionKey: ...

    @property
    def start(self) -> float: ...

    @property
    def impact(self) -> float: ...


@dataclass(frozen=True)
class AnimationSettings:
    """Constants from motions/animation.toml (see the comments there)."""

    vel_floor: float = 0.4
    vel_ceiling: float = 1.25
    reference_spb: float = 0.5
    max_rate: float = 2.0
    nod_rad: float = 0.06
    sway_rad: float = 0.025
    sway_period_s: float = 4.0
    head_decay_s: float = 0.15
    swing: tuple[tuple[str, float, float, float], ...] = (
        ("ride", 0.08, 1.0, 1.6),
        ("crash", 0.15, 1.5, 1.2),
        ("hihat", 0.03, 0.3, 3.0),
        ("crash2", 0.13, 1.6, 1.0),
    )
    hihat_travel_m: float = 0.04
    hihat_lead_s: float = 0.06
    hihat_hold_open_s: float = 1.0
    string_amp_m: float = 0.004
    string_decay_s: float = 1.2
    bassist: BassistSettings = BassistSettings()

    @classmethod
    def load(cls, path: Path | None = None) -> AnimationSettings:
        """motions/animation.toml (or ``path``); the defaults when the file is absent.
        Its schema: :class:`virja.motion.settings_files.AnimationFile`."""
        from virja.motion.settings_files import animation_settings
        from virja.resources import motions_file

        found = motions_file("animation.toml", path)
        return cls() if found is None else animation_settings(found)


class BandAnimator:
    """Turns planned notes and beats into poses.  Not thread-safe; one per session."""

    def __init__(
        self,
        library: MotionLibrary | None = None,
        geometry: Geometry = GEOMETRY,
        settings: AnimationSettings | None = None,
        body: BodySettings | None = None,
        hands: HandSettings | None = None,
    ) -> None:
        self.library = library if library is not None else default_library()
        self.geometry = geometry
        self.settings = settings or AnimationSettings.load()
        self.idle: dict[str, Clip] = {f: self.library[idle_clip(f)] for f in FIGURES}
        self.timelines: dict[tuple[str, str], Timeline] = {
            (f, limb): Timeline(_SK.mask(LIMB_JOINTS[limb]).nonzero()[0])
            for f in FIGURES
            for limb in PERFORMER_LIMBS[f]
        }
        self._roots = np.stack([self.idle[f].root_positions[0] for f in FIGURES])
        self._beat_times: list[float] = []
        self._beat_spb: list[float] = []
        self._hits = HitTable()
        pedal = geometry.kit.hihat_pedal
        self._hihat_pressed_y = float(pedal.toe_point(True)[1])
        self._ltoe = _SK.index("LeftToe")
        self.body = DrummerBody(self._roots[0], geometry, body)
        self.hands = DrummerHands(
            self._roots[0], self.idle["drums"].rotations[0], hands, geometry.kit
        )
        self.bass_strings: tuple[str, ...] = BASS_STRINGS
        self.bassist = Bassist(geometry, self.settings.bassist)
        # where the bassist's chest stands when he stands still (the bass leans from there)
        self._bass_rest_chest = _SK.fk(self.idle["bass"].rotations[0], self._roots[1])[0][CHEST]
        self.hihat = HihatState(self.settings.hihat_lead_s, self.settings.hihat_hold_open_s)
        self.articulations: dict[int, str | None] = default_articulations()
        # when each note became known (note_known), until its plan arrives; and the
        # latest frame shown (mark_drawn): a note changes nothing at or before it
        self._known: dict[tuple[str, int, int, float], float] = {}
        self.drawn_until = -math.inf
        # the drummer's hand strokes shown before their plan is fixed (note_provisional),
        # by note: (hand, the provisional note); and how they fared (provisional_counts)
        self._provisional: dict[tuple[str, int, int, float], tuple[str, PlannedNoteLike]] = {}
        self.provisional_counts: Counter[str] = Counter()
        # provisional strokes drawn moving (shown_moving): by note, the hand and since when
        self._moving: dict[tuple[str, int, int, float], tuple[str, float]] = {}
        # each note the plan fixed to another hand than the one shown (how it fared live)
        self.hand_switches: list[HandSwitch] = []

    def set_articulations(self, articulations: Mapping[int, str | None]) -> None:
        """The kit map's articulation per drum note number (``PlanConfig.kit.notes``):
        hi-hat notes then open and close the cymbals (virja.motion.drummer_kit)."""
        self.articulations = dict(articulations)

    def use_bass_strings(self, strings: tuple[str, ...]) -> None:
        """The strings of the bass's tuning, low to high (four by default; B E A D G for a
        five-string, B E A D G C for a six-string): played, and shown in the pose."""
        unknown = [s for s in strings if s not in ALL_BASS_STRINGS]
        if unknown or not strings:
            raise UnknownMotionError(
                f"the bassist's clips cover the strings {' '.join(ALL_BASS_STRINGS)}; "
                f"got {' '.join(strings) or 'none'}"
            )
        self.bass_strings = tuple(strings)
        self.bassist.use_strings(self.bass_strings)

    # ------------------------------------------------------------------ input

    def seconds_per_beat_at(self, time_s: float) -> float:
        """The tempo from the latest beat at or before ``time_s`` (default 120 bpm)."""
        i = bisect.bisect_right(self._beat_times, time_s) - 1
        return self._beat_spb[max(i, 0)] if self._beat_spb else self.settings.reference_spb

    def add_beat(self, beat: Beat) -> None:
        """Record a beat: the idle layer nods on it and the tempo sets the rebound speed."""
        i = bisect.bisect_right(self._beat_times, beat.time_s)
        self._beat_times.insert(i, beat.time_s)
        self._beat_spb.insert(i, beat.seconds_per_beat)

    def velocity_scale(self, velocity: int, nominal: int) -> float:
        s = self.settings
        v = s.vel_floor + (1.0 - s.vel_floor) * velocity / max(nominal, 1)
        return float(min(max(v, s.vel_floor), s.vel_ceiling))

    def _rate(self, time_s: float) -> float:
        s = self.settings
        return float(min(max(s.reference_spb / self.seconds_per_beat_at(time_s), 1.0), s.max_rate))

    def mark_drawn(self, time_s: float) -> None:
        """A frame of ``time_s`` was shown (the live window, the web feed, a single
        :meth:`pose`): a note planned later changes nothing at or before it.  Frames
        posed ahead and thrown away, and measurements, are not marked."""
        self.drawn_until = max(self.drawn_until, float(time_s))
        self.body.drawn(time_s, self._beat_times, self._beat_spb)

    def note_known(self, performer: str, note: Any, at_s: float) -> None:
        """``note`` (a NoteOn) became known at ``at_s``, before it is planned: a
        drummer's hand that is free may start toward it from then (see add_planned)."""
        key = (performer, int(note.channel), int(note.note), round(float(note.time_s), 9))
        self._known[key] = min(float(at_s), self._known.get(key, math.inf))

    def _course(self, start: float, known_at: float | None) -> float:
        """When a hand may change course for a stroke starting at ``start``: from when
        its note became known (``known_at``, else its start), never at or before a
        frame already shown (:attr:`drawn_until`)."""
        course = start if known_at is None else min(known_at, start)
        return max(course, self.drawn_until)

    def note_provisional(self, notes: Iterable[PlannedNoteLike]) -> None:
        """The plan's current hand for each drum note not yet started (the whole set:
        ``OnlinePlanner.provisional``): a free hand moves toward its piece from when
        the note became known, as when the plan is fixed.  A note whose hand or stroke
        changed since last told, or that is no longer in the set, is taken back: the
        frames drawn (:attr:`drawn_until`) stay, the hand goes on from where it is.
        :meth:`add_planned` then keeps the stroke when the plan fixes the same hand,
        and re-targets both hands from their poses after the last frame drawn when it
        fixes the other."""
        new = {_note_key(p): p for p in notes if p.performer == "drums"}
        for key, (hand, old) in list(self._provisional.items()):
            p = new.get(key)
            if p is None or not _same_stroke(old, p):
                self.hands.remove_stroke(hand, key, self.drawn_until)
                del self._provisional[key]
                kind = "revised" if p is not None else "taken_back"
                self.provisional_counts[kind] += 1
                moving = self._moving.pop(key, None)
                if moving is not None:
                    self.provisional_counts[f"{kind}_moving"] += 1
                    self.hand_switches.append(
                        HandSwitch(
                            kind,
                            old.time,
                            old.impact,
                            hand,
                            None if p is None else p.limb,
                            moving[1],
                            self.drawn_until,
                        )
                    )
        for key, p in new.items():
            if key in self._provisional or not isinstance(p.motion, DrumStroke):
                continue
            clip = self.library[p.motion.clip]
            hand = clip.limb or p.limb
            if hand not in ("left_hand", "right_hand"):
                continue
            course = self._course(p.start, self._known.get(key))
            art = self.articulations.get(p.note)
            self.hands.add_stroke(
                hand, course, p.impact, clip, p.velocity, art, key=key, drawn=self.drawn_until
            )
            self._provisional[key] = (hand, p)
            self.provisional_counts["shown"] += 1

    def shown_moving(self) -> list[HandPin]:
        """The provisional strokes drawn moving: their hand has moved toward them
        (``DrummerHands.departs``) at or before the latest frame shown
        (:attr:`drawn_until`), the whole current set, as pins for the planner
        (``OnlinePlanner.pin_hands``: ``session.Performance`` passes them on before each
        commit).  Nothing drawn (the whole input known): none."""
        out: list[HandPin] = []
        drawn = self.drawn_until
        if drawn == -math.inf:
            return out
        for key, (hand, _p) in self._provisional.items():
            moving = self._moving.get(key)
            if moving is None:
                since = self.hands.departs(hand, key)
                if since is None or since > drawn:
                    continue
                moving = self._moving[key] = (hand, since)
            side: Hand = "left_hand" if hand == "left_hand" else "right_hand"
            out.append(HandPin(key[1], key[2], key[3], side, moving[1]))
        return out

    def add_planned(self, p: PlannedNoteLike, known_at: float | None = None) -> None:
        """Schedule the motions of one planned note (its start and impact are kept exactly).

        A drummer's hand may change course for it from when the note became known
        (``known_at``, else what :meth:`note_known` was told, else its ``start``), once
        its previous stroke has landed, and never at or before a frame already shown
        (:attr:`drawn_until`, :meth:`mark_drawn`): nothing drawn changes.

        Raises :class:`UnknownMotionError` when the library lacks the motion.
        """
        key = _note_key(p)
        told = self._known.pop(key, None)
        if known_at is None:
            known_at = told
        rate = self._rate(p.impact)
        if p.performer == "drums":
            if not isinstance(p.motion, DrumStroke):
                raise UnknownMotionError(f"{p.motion.name!r} is not a drummer's limb motion")
            clip = self.library[p.motion.clip]
            limb = clip.limb or p.limb
            if clip.performer != "drums" or limb not in PERFORMER_LIMBS["drums"]:
                raise UnknownMotionError(f"{p.motion.name!r} is not a drummer's limb motion")
            self.timelines[("drums", limb)].add(
                Instance(
                    clip,
                    p.start,
                    p.impact,
                    rate,
                    self.velocity_scale(p.velocity, clip.velocity),
                    p.velocity,
                    tag=p,
                )
            )
            self._hits.add(Hit(p.impact, clip.piece or p.piece or "", p.velocity))
            art = self.articulations.get(p.note)
            course = self._course(p.start, known_at)
            shown = self._provisional.pop(key, None)
            if shown is not None and key in self._moving and shown[0] == limb:
                self.provisional_counts["fixed_same_moving"] += 1
            if shown is not None and shown[0] == limb and _same_stroke(shown[1], p):
                self.hands.keep_stroke(limb, key)  # the stroke shown is the one played
                self.provisional_counts["fixed_same"] += 1
            else:
                if shown is not None:  # the plan fixed the other hand (or another stroke)
                    self.hands.remove_stroke(shown[0], key, self.drawn_until)
                    self.provisional_counts["fixed_other"] += 1
                    moving = self._moving.get(key)
                    if moving is not None:
                        self.provisional_counts["fixed_other_moving"] += 1
                    self.hand_switches.append(
                        HandSwitch(
                            "fixed",
                            p.time,
                            p.impact,
                            shown[0],
                            limb,
                            None if moving is None else moving[1],
                            self.drawn_until,
                        )
                    )
                self.hands.add_stroke(
                    limb, course, p.impact, clip, p.velocity, art, drawn=self.drawn_until
                )
            self.body.add_stroke(
                limb, p.impact, clip.piece or p.piece, known=max(p.start, self.drawn_until)
            )
            if (clip.piece or p.piece) == "hihat":
                self.hihat.add(p.impact, self.articulations.get(p.note))
        elif p.performer == "bass":
            if not isinstance(p.motion, BassPluck):
                raise UnknownMotionError(f"{p.motion.name!r} is not a bassist's motion")
            string = p.motion.string
            if string not in self.bass_strings:
                raise UnknownMotionError(
                    f"a bass note planned on the {string!r} string; this bass has "
                    f"{' '.join(self.bass_strings)} (the tuning in [plan] decides)"
                )
            pluck = self.library[p.motion.pluck_clip]
            self.timelines[("bass", "right_hand")].add(
                Instance(
                    pluck,
                    p.start,
                    p.impact,
                    rate,
                    self.velocity_scale(p.velocity, pluck.velocity),
                    p.velocity,
                    tag=p,
                )
            )
            left = self.timelines[("bass", "left_hand")]
            fret = p.fret or 0
            if fret > 0:
                left.add(self._hold(p.motion.hold_clip, p))
            else:
                current = left.active(p.start)
                if current and current[-1].clip.string == string:
                    left.add(self._hold(FRET_OPEN_CLIP, p))
            self._hits.add(Hit(p.impact, string, p.velocity))
            self.bassist.add(p.impact, p.note, string, fret, p.motion, p.velocity, p.start)
        else:
            raise UnknownMotionError(f"no figure for performer {p.performer!r}")

    # whose note-offs change the band's pose (the render loops pose ahead across the others)
    NOTE_OFF_PERFORMERS: frozenset[str] = frozenset({"bass"})

    def note_off(self, performer: str, event: Any) -> None:
        """A note-off: the bassist's fingers lift from the string (an open string rings on)."""
        if performer in self.NOTE_OFF_PERFORMERS:
            self.bassist.note_off(int(event.note), float(event.time_s))

    def _hold(self, name: str, p: PlannedNoteLike) -> Instance:
        # a hold with no predecessor fades in from the rest pose over its preparation
        return Instance(
            self.library[name], p.start, p.impact, fade_in=max(p.impact - p.start, 1e-3), tag=p
        )

    def forget_before(self, time_s: float) -> None:
        """Drop what can no longer show at ``time_s`` or later (bounds memory in long sessions)."""
        for tl in self.timelines.values():
            tl.forget_before(time_s)
        self.body.forget_before(time_s)
        self.hands.forget_before(time_s)
        self._known = {k: v for k, v in self._known.items() if k[3] >= time_s - 10.0}
        self._provisional = {k: v for k, v in self._provisional.items() if k[3] >= time_s - 10.0}
        self._moving = {k: v for k, v in self._moving.items() if k[3] >= time_s - 10.0}
        self.hihat.forget_before(time_s)
        horizon = time_s - 10.0  # kit and string states have died away long before
        self.bassist.forget_before(horizon)
        self._hits.forget_before(horizon)
        k = max(bisect.bisect_right(self._beat_times, time_s) - 1, 0)
        del self._beat_times[:k]
        del self._beat_spb[:k]

    # ------------------------------------------------------------------ output

    def local_rotations(self, time_s: float) -> np.ndarray:
        """Local rotations (2, n_joints, 4) of [drums, bass] at ``time_s``, w x y z."""
        out = np.empty((2, _SK.n_joints, 4))
        nod = self._nod(time_s)
        for fi, f in enumerate(FIGURES):
            idle = self.idle[f]
            loc = out[fi]
            loc[:] = idle.rotations[0]
            loc[_NECK] = quat.multiply(loc[_NECK], nod[0])
            loc[_HEAD] = quat.multiply(loc[_HEAD], nod[1])
            for limb in PERFORMER_LIMBS[f]:
                tl = self.timelines[(f, limb)]
                if f == "drums" and self._from_hands(limb):
                    loc[self.hands.joint_index(limb)] = self.hands.local(limb, np.array([time_s]))[
                        0
                    ]
                elif len(tl):
                    loc[tl.joint_index] = tl.blend(time_s, loc[tl.joint_index])
        out[0] = self._body(np.array([time_s]), out[None, 0])[0]
        index, phase = self._pulse_at(time_s)
        out[1] = self.bassist.body(out[1], self._roots[1], time_s, phase, index)
        return out

    def _from_hands(self, limb: str) -> bool:
        """Whether the drummer's ``limb`` moves from where it is (virja.motion.drummer_hands)
        rather than by its time-warped clips."""
        return self.hands.enabled and self.hands.has_strokes(limb)

    def _body(self, times: np.ndarray, drummer: np.ndarray) -> np.ndarray:
        """The drummer's living body over the limbs (virja.motion.drummer_body)."""
        return self.body.apply(
            times,
            drummer,
            self._roots[0],
            np.asarray(self._beat_times, dtype=np.float64),
            np.asarray(self._beat_spb, dtype=np.float64),
        )

    def _nod(self, t: float) -> np.ndarray:
        s = self.settings
        i = bisect.bisect_right(self._beat_times, t) - 1
        if i >= 0:
            spb = self._beat_spb[i]
            phase = (t - self._beat_times[i]) / spb
        else:
            spb = s.reference_spb
            phase = t / spb
        phase = min(phase, 1.0) if i >= 0 else phase % 1.0
        nod = s.nod_rad * math.sin(math.pi * phase) ** 2
        sway = s.sway_rad * math.sin(2 * math.pi * t / s.sway_period_s)
        return np.array(
            [
                [math.cos(nod / 2), math.sin(nod / 2), 0.0, 0.0],
                [math.cos(sway / 2), 0.0, math.sin(sway / 2), 0.0],
            ]
        )

    def pose(self, time_s: float) -> BandPose:
        """The band at ``time_s`` (session seconds), a frame shown (:meth:`mark_drawn`)."""
        self.mark_drawn(time_s)
        loc = self.local_rotations(time_s)
        wpos, wrot = _SK.fk(loc, self._roots)
        lean, fingers = self._bass_parts(time_s, wpos[1], self.bass_transform(wpos[1]))
        figs = [FigurePose(_SK.names, _SK.parents, wpos[i], wrot[i], _SK.radii) for i in range(2)]
        return BandPose(
            time_s=time_s,
            drums=figs[0],
            bass=figs[1],
            sticks=sticks(wpos[0], wrot[0]),
            hihat_open=self._hihat_open(wpos[0], time_s),
            cymbal_swing=self._swings(time_s),
            head_hits=self._head_hits(time_s),
            string_vibration=self._strings(time_s),
            string_stops=self._stops(time_s),
            fretting_tip=wpos[1, _SK.index("LeftHandEnd")].copy(),
            plucking_tip=wpos[1, _SK.index("RightHandEnd")].copy(),
            bass_fingers=fingers,
            bass_transform=lean,
        )

    def local_rotations_many(self, times: np.ndarray) -> np.ndarray:
        """:meth:`local_rotations` at many times at once: (m, 2, n_joints, 4).

        ``times`` (m,) must be sorted ascending.  Vectorised over times (one
        numpy pass per clip instance, not per frame) for exports; equal to
        ``local_rotations(t)`` for each ``t`` to rounding (tests/motion/test_band.py).
        """
        ts = np.asarray(times, dtype=np.float64)
        if ts.ndim != 1 or (ts.size > 1 and np.any(np.diff(ts) < 0)):
            raise ValueError("times must be a 1-D array sorted ascending")
        out = np.empty((ts.size, 2, _SK.n_joints, 4))
        nod = self._nod_many(ts)
        for fi, f in enumerate(FIGURES):
            loc = out[:, fi]
            loc[:] = self.idle[f].rotations[0]
            loc[:, _NECK] = quat.multiply(loc[:, _NECK], nod[:, 0])
            loc[:, _HEAD] = quat.multiply(loc[:, _HEAD], nod[:, 1])
            for limb in PERFORMER_LIMBS[f]:
                tl = self.timelines[(f, limb)]
                if f == "drums" and self._from_hands(limb):
                    loc[:, self.hands.joint_index(limb)] = self.hands.local(limb, ts)
                elif len(tl):
                    loc[:, tl.joint_index] = blend_many(tl, ts, loc[:, tl.joint_index])
        out[:, 0] = self._body(ts, out[:, 0])
        index, phase = self._body_pulse(ts)
        out[:, 1] = self.bassist.body_many(out[:, 1], self._roots[1], ts, phase, index)
        return out

    def _pulse_at(self, t: float) -> tuple[int, float]:
        """:meth:`_body_pulse` at one time: (pulse number, phase)."""
        index, phase = self._body_pulse(np.array([t]))
        return int(index[0]), float(phase[0])

    def _body_pulse(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The bassist's body pulse (numbers, phases) at times ``t``: the beat itself,
        or every other beat where beats are shorter than ``half_time_spb`` (half time
        over 150 bpm: his weight and dip at half the rate)."""
        index, phase, spb = self._beat_phase_many(t)
        half = spb < self.bassist.settings.half_time_spb
        return (
            np.where(half, index // 2, index),
            np.where(half, (index % 2 + phase) / 2.0, phase),
        )

    def _beat_phase_many(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(beat numbers, phases 0..1 within them, seconds per beat) at times ``t``
        (120 bpm before the first beat)."""
        bt = np.asarray(self._beat_times, dtype=np.float64)
        i = np.searchsorted(bt, t, side="right") - 1
        spb_ref = self.settings.reference_spb
        index = np.floor(t / spb_ref).astype(np.int64)
        phase = np.mod(t / spb_ref, 1.0)
        spb = np.full(t.shape, spb_ref)
        if bt.size:
            k = np.maximum(i, 0)
            spb = np.where(i >= 0, np.asarray(self._beat_spb, dtype=np.float64)[k], spb)
            p = (t - bt[k]) / spb
            whole = np.floor(p).astype(np.int64)
            index = np.where(i >= 0, np.where(p < 1.0, k, k + whole), index)
            phase = np.where(i >= 0, np.where(p < 1.0, p, np.mod(p, 1.0)), phase)
        return index, phase, spb

    def _nod_many(self, t: np.ndarray) -> np.ndarray:
        """:meth:`_nod` over an array of times: (m, 2, 4)."""
        s = self.settings
        bt = np.asarray(self._beat_times, dtype=np.float64)
        i = np.searchsorted(bt, t, side="right") - 1
        if bt.size:
            k = np.maximum(i, 0)
            spb = np.asarray(self._beat_spb, dtype=np.float64)
            beat_phase = np.minimum((t - bt[k]) / spb[k], 1.0)
        else:
            beat_phase = np.zeros_like(t)
        phase = np.where(i >= 0, beat_phase, np.mod(t / s.reference_spb, 1.0))
        nod = s.nod_rad * np.sin(np.pi * phase) ** 2
        sway = s.sway_rad * np.sin(2 * np.pi * t / s.sway_period_s)
        out = np.zeros((t.size, 2, 4))
        out[:, 0, 0] = np.cos(nod / 2)
        out[:, 0, 1] = np.sin(nod / 2)
        out[:, 1, 0] = np.cos(sway / 2)
        out[:, 1, 2] = np.sin(sway / 2)
        return out

    def poses(self, times: np.ndarray, local: np.ndarray | None = None) -> list[BandPose]:
        """:meth:`pose` at many times (sorted ascending), FK batched over all of them.

        ``local`` is :meth:`local_rotations_many` of ``times`` if the caller has it.
        """
        return self.pose_batch(times, local).all()

    def pose_batch(self, times: np.ndarray, local: np.ndarray | None = None) -> BandPoses:
        """The band at many times (sorted ascending) as arrays, one row a frame: what
        the render loops draw (:func:`virja.render.scene_batch.band_scenes`).

        Everything is computed for all the frames at once (the kit and string state
        from :class:`HitTable`'s windows, FK, sticks, the bass's lean) except the
        hi-hat's notes, the stopped frets and the bassist's fingers, which are a few
        Python look-ups or his own per-frame method.  Equal to :meth:`pose` frame by
        frame to rounding (tests/motion/test_band_batch.py).
        """
        ts = np.asarray(times, dtype=np.float64).reshape(-1)
        loc = self.local_rotations_many(ts) if local is None else local
        wpos, wrot = _SK.fk(loc, self._roots)
        leans = self.bass_transform(wpos[:, 1])  # (m, 4, 4), one pass
        s = self.settings
        tl = ts.tolist()
        by_foot = np.clip(
            (wpos[:, 0, self._ltoe, 1] - self._hihat_pressed_y) / s.hihat_travel_m, 0.0, 1.0
        )
        hihat = by_foot.copy()
        for k, t in enumerate(tl):
            by_notes = self.hihat.openness(t)
            if by_notes is not None:
                foot = float(by_foot[k])
                hihat[k] = by_notes + self.hihat.chick_weight(t) * max(foot - by_notes, 0.0)
        strings = self.bass_strings
        stops = np.array(
            [[d[n] for n in strings] for d in map(self._stops, tl)], dtype=np.int64
        ).reshape(ts.size, len(strings))
        # the fingers are laid out in the bass's own frame, then leaned with it
        rot, shift = leans[:, :3, :3], leans[:, :3, 3]
        own = (wpos[:, 1] - shift[:, None, :]) @ rot
        fingers = self.bassist.fingers_many(ts, own)  # all frames in one numpy pass
        fingers = np.einsum("mkpj,mij->mkpi", fingers, rot) + shift[:, None, None, :]
        return BandPoses(
            times=ts,
            names=_SK.names,
            parents=_SK.parents,
            radii=_SK.radii,
            positions=wpos,
            rotations=wrot,
            sticks=sticks(wpos[:, 0], wrot[:, 0]),
            hihat_open=hihat,
            cymbals=tuple(sw[0] for sw in s.swing),
            cymbal_swing=self._hits.swings_many(ts, s.swing),
            drums=tuple(DRUM_PIECES),
            head_hits=self._hits.head_hits_many(ts, DRUM_PIECES, s.head_decay_s),
            strings=strings,
            string_vibration=self._hits.strings_many(ts, strings, s.string_amp_m, s.string_decay_s),
            string_stops=stops,
            fretting_tip=wpos[:, 1, _SK.index("LeftHandEnd")],
            plucking_tip=wpos[:, 1, _SK.index("RightHandEnd")],
            bass_fingers=fingers,
            bass_transform=leans,
        )

    def bass_transform(self, bass_wpos: np.ndarray) -> np.ndarray:
        """(..., 4, 4) the bass's world transform for the bassist's joint positions
        (..., n, 3): leaning with his chest (:mod:`virja.motion.bass_lean`)."""
        q = self.bassist.lean(bass_wpos[..., CHEST, :], self._bass_rest_chest)
        return bass_lean.matrix(q, self.geometry.bass.endpin)

    def _bass_parts(
        self, t: float, bass_wpos: np.ndarray, m: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The bass's transform ``m`` (4, 4) and the finger bones (laid out in the bass's
        own frame, then leaned with it)."""
        own = bass_lean.apply(bass_lean.inverse(m), bass_wpos)
        return m, bass_lean.apply(m, self.bassist.fingers(t, own))

    def _hihat_open(self, wpos: np.ndarray, t: float) -> float:
        rise = float(wpos[self._ltoe, 1]) - self._hihat_pressed_y
        by_foot = float(min(max(rise / self.settings.hihat_travel_m, 0.0), 1.0))
        by_notes = self.hihat.openness(t)
        if by_notes is None:
            return by_foot
        return by_notes + self.hihat.chick_weight(t) * max(by_foot - by_notes, 0.0)

    def _swings(self, t: float) -> dict[str, float]:
        return self._hits.swings(t, self.settings.swing)

    def _head_hits(self, t: float) -> dict[str, float]:
        return self._hits.head_hits(t, DRUM_PIECES, self.settings.head_decay_s)

    def _strings(self, t: float) -> dict[str, float]:
        s = self.settings
        return self._hits.strings(t, self.bass_strings, s.string_amp_m, s.string_decay_s)

    def _stops(self, t: float) -> dict[str, int]:
        out = dict.fromkeys(self.bass_strings, 0)
        act = self.timelines[("bass", "left_hand")].active(t)
        for inst in reversed(act):
            if inst.impact <= t:
                if inst.clip.string is not None and inst.clip.fret:
                    out[inst.clip.string] = inst.clip.fret
                break
        return out


@dataclass(frozen=True, slots=True)
class HandSwitch:
    """A drum note the plan took from the hand shown for it: ``kind`` "fixed" (to
    another limb), or, for a hand drawn moving already, "revised" (another stroke shown)
    or "taken_back" (none: a foot's chick, a rebound); its time and impact, the hand
    shown and the limb given it (None: taken back), since when the shown hand was drawn
    moving for it (None: not yet), and the latest frame shown then."""

    kind: str
    time: float
    impact: float
    shown: str
    fixed: str | None
    moving_since: float | None
    drawn: float


def _note_key(p: Any) -> tuple[str, int, int, float]:
    """A note's identity from its arrival to its plan: performer, channel, note, time."""
    time = getattr(p, "time", None)
    if time is None:
        time = p.time_s
    return (str(p.performer), int(getattr(p, "channel", 0)), int(p.note), round(float(time), 9))


def _same_stroke(a: PlannedNoteLike, b: PlannedNoteLike) -> bool:
    """Whether two plans of one note move its hand the same way."""
    return (a.limb, a.motion, a.impact, a.velocity) == (b.limb, b.motion, b.impact, b.velocity)


def sticks(wpos: np.ndarray, wrot: np.ndarray) -> np.ndarray:
    """(..., 2, 2, 3) [left, right] x [butt, tip] stick points from the drummer's FK result
    (``wpos`` (..., n, 3), ``wrot`` (..., n, 4): one frame or many)."""
    out = np.empty(wpos.shape[:-2] + (2, 2, 3))
    for i, side in enumerate(("Left", "Right")):
        grip = wpos[..., _SK.index(f"{side}HandEnd"), :]
        axis = quat.rotate(wrot[..., _SK.index(f"{side}Hand"), :], STICK_AXIS_LOCAL)
        out[..., i, 0, :] = grip - STICK_BUTT_M * axis
        out[..., i, 1, :] = grip + STICK_TIP_M * axis
    return out


__all__ = [
    "BandAnimator",
    "AnimationSettings",
    "Hit",
    "PlannedNoteLike",
    "sticks",
    "CYMBAL_PIECES",
]
