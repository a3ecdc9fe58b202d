"""The animators' constant files, each as one schema (virja.tomlconf):
motions/animation.toml -> :class:`~virja.motion.band.AnimationSettings`,
motions/drummer_body.toml -> :class:`~virja.motion.drummer_body.BodySettings` and
motions/drummer_hands.toml -> :class:`~virja.motion.drummer_hands.HandSettings`.

A wrong type, a missing or an unknown key is a ConfigError naming the file and the
key path; the reasons for each number are in the files' comments.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from virja import tomlconf
from virja.errors import ConfigError
from virja.motion.bassist import BassistSettings
from virja.tomlconf import Schema

if TYPE_CHECKING:
    from virja.motion.band import AnimationSettings
    from virja.motion.drummer_body import BodySettings
    from virja.motion.drummer_hands import HandSettings

Swing = tuple[float, float, float]  # angle (rad), per velocity gain, decay (s)


class VelocityTable(Schema):
    floor: float
    ceiling: float


class TempoTable(Schema):
    reference_spb: float
    max_rate: float


class IdleTable(Schema):
    nod_rad: float
    sway_rad: float
    sway_period_s: float


class KitTable(Schema):
    head_decay_s: float
    ride_swing: Swing
    crash_swing: Swing
    hihat_swing: Swing
    hihat_travel_m: float
    crash2_swing: Swing | None = None  # absent (a file older than crash 2): crash 1's swing
    hihat_lead_s: float | None = None  # absent: AnimationSettings' default
    hihat_hold_open_s: float | None = None


class StringsTable(Schema):
    amplitude_m: float
    decay_s: float


BassistTable = tomlconf.schema_of(BassistSettings)


class AnimationFile(Schema):
    """motions/animation.toml"""

    velocity: VelocityTable
    tempo: TempoTable
    idle: IdleTable
    kit: KitTable
    strings: StringsTable
    bassist: BassistTable = msgspec.field(default_factory=BassistTable)  # type: ignore[valid-type]


def animation_settings(path: Path) -> AnimationSettings:
    """The settings of an animation.toml at ``path`` (every time or rate finite and > 0)."""
    from virja.motion.band import AnimationSettings

    f = tomlconf.load(path, AnimationFile)
    k = f.kit
    settings = AnimationSettings(
        vel_floor=f.velocity.floor,
        vel_ceiling=f.velocity.ceiling,
        reference_spb=f.tempo.reference_spb,
        max_rate=f.tempo.max_rate,
        nod_rad=f.idle.nod_rad,
        sway_rad=f.idle.sway_rad,
        sway_period_s=f.idle.sway_period_s,
        head_decay_s=k.head_decay_s,
        swing=(
            ("ride", *k.ride_swing),
            ("crash", *k.crash_swing),
            ("hihat", *k.hihat_swing),
            ("crash2", *(k.crash_swing if k.crash2_swing is None else k.crash2_swing)),
        ),
        hihat_travel_m=k.hihat_travel_m,
        hihat_lead_s=AnimationSettings.hihat_lead_s if k.hihat_lead_s is None else k.hihat_lead_s,
        hihat_hold_open_s=(
            AnimationSettings.hihat_hold_open_s
            if k.hihat_hold_open_s is None
            else k.hihat_hold_open_s
        ),
        string_amp_m=f.strings.amplitude_m,
        string_decay_s=f.strings.decay_s,
        bassist=BassistSettings(**tomlconf.fields(f.bassist)),
    )
    positive = {
        "tempo.reference_spb": settings.reference_spb,
        "tempo.max_rate": settings.max_rate,
        "idle.sway_period_s": settings.sway_period_s,
        "kit.head_decay_s": settings.head_decay_s,
        "strings.decay_s": settings.string_decay_s,
        "kit.hihat_lead_s": settings.hihat_lead_s,
        "kit.hihat_hold_open_s": settings.hihat_hold_open_s,
    }
    for name, value in positive.items():
        if not (math.isfinite(value) and value > 0):
            raise ConfigError(f"{path}: {name} must be a finite number > 0, got {value}")
    return settings


class TurnTable(Schema):
    gain: float
    max_deg: float
    smooth_s: float
    chest_share: float
    head_share: float


class BreathTable(Schema):
    chest_deg: float
    period_s: float


class BeatTable(Schema):
    spine_deg: float
    sway_deg: float
    reference_spb: float
    sway_floor: float | None = None  # absent: BodySettings' default
    sway_ceiling: float | None = None  # absent: BodySettings' default
    sway_follow_deg: float | None = None  # absent: BodySettings' default
    feather_deg: float | None = None
    feather_width_s: float | None = None
    feather_clear_s: float | None = None


class ArmsTable(Schema):
    engage_s: float
    release_s: float


class DrummerBodyFile(Schema):
    """motions/drummer_body.toml"""

    turn: TurnTable
    breath: BreathTable
    beat: BeatTable
    arms: ArmsTable


def body_settings(path: Path) -> BodySettings:
    """The settings of a drummer_body.toml at ``path``."""
    from virja.motion.drummer_body import BodySettings

    f = tomlconf.load(path, DrummerBodyFile)
    return BodySettings(
        gain=f.turn.gain,
        max_turn_deg=f.turn.max_deg,
        smooth_s=f.turn.smooth_s,
        chest_share=f.turn.chest_share,
        head_share=f.turn.head_share,
        breath_deg=f.breath.chest_deg,
        breath_period_s=f.breath.period_s,
        beat_deg=f.beat.spine_deg,
        sway_deg=f.beat.sway_deg,
        sway_floor=BodySettings.sway_floor if f.beat.sway_floor is None else f.beat.sway_floor,
        sway_ceiling=(
            BodySettings.sway_ceiling if f.beat.sway_ceiling is None else f.beat.sway_ceiling
        ),
        sway_follow_deg=(
            BodySettings.sway_follow_deg
            if f.beat.sway_follow_deg is None
            else f.beat.sway_follow_deg
        ),
        reference_spb=f.beat.reference_spb,
        engage_s=f.arms.engage_s,
        release_s=f.arms.release_s,
        **{
            k: v
            for k, v in (
                ("feather_deg", f.beat.feather_deg),
                ("feather_width_s", f.beat.feather_width_s),
                ("feather_clear_s", f.beat.feather_clear_s),
            )
            if v is not None
        },
    )


class HandLiftTable(Schema):
    soft_m: float
    loud_m: float
    curve: float
    per_s: float
    hover_m: float
    wrist_share: float


class HandTimeTable(Schema):
    down_share: float
    down_min_s: float
    down_max_s: float
    rebound_share: float
    rebound_max_s: float


class HandMoveTable(Schema):
    speed_m_s: float
    rest_after_s: float
    rest_move_s: float
    early: float = 2.0


class HandReachTable(Schema):
    speed_m_s: float
    max_m: float


class HandArticulationTable(Schema):
    side_stick_m: float
    rim_min_m: float


class DrummerHandsFile(Schema):
    """motions/drummer_hands.toml"""

    lift: HandLiftTable
    time: HandTimeTable
    move: HandMoveTable
    reach: HandReachTable
    articulation: HandArticulationTable
    enabled: bool = True


def hand_settings(path: Path) -> HandSettings:
    """The settings of a drummer_hands.toml at ``path`` (speeds and times finite and > 0)."""
    from virja.motion.drummer_hands import HandSettings

    f = tomlconf.load(path, DrummerHandsFile)
    settings = HandSettings(
        enabled=f.enabled,
        lift_soft_m=f.lift.soft_m,
        lift_loud_m=f.lift.loud_m,
        lift_curve=f.lift.curve,
        lift_per_s=f.lift.per_s,
        hover_m=f.lift.hover_m,
        wrist_share=f.lift.wrist_share,
        side_stick_m=f.articulation.side_stick_m,
        rim_min_m=f.articulation.rim_min_m,
        down_share=f.time.down_share,
        down_min_s=f.time.down_min_s,
        down_max_s=f.time.down_max_s,
        rebound_share=f.time.rebound_share,
        rebound_max_s=f.time.rebound_max_s,
        move_speed_m_s=f.move.speed_m_s,
        rest_after_s=f.move.rest_after_s,
        rest_move_s=f.move.rest_move_s,
        move_early=f.move.early,
        reach_speed_m_s=f.reach.speed_m_s,
        reach_max_m=f.reach.max_m,
    )
    if not settings.move_early >= 1:
        raise ConfigError(f"{path}: move.early must be a number >= 1, got {settings.move_early}")
    positive = {
        "lift.per_s": settings.lift_per_s,
        "lift.curve": settings.lift_curve,
        "time.down_max_s": settings.down_max_s,
        "move.speed_m_s": settings.move_speed_m_s,
        "move.rest_after_s": settings.rest_after_s,
        "move.rest_move_s": settings.rest_move_s,
        "reach.speed_m_s": settings.reach_speed_m_s,
    }
    for name, value in positive.items():
        if not value > 0:
            raise ConfigError(f"{path}: {name} must be a number > 0, got {value}")
    return settings
