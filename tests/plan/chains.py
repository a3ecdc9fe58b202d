"""Helpers for the tests of the planner's chains: a context, notes held."""

from __future__ import annotations

from virja.events import NoteOn
from virja.plan.bounds import DEFAULT_BOUNDS, PlanBounds
from virja.plan.chain import ChainContext, Ledger
from virja.plan.config import PlanConfig, default_config

SPB = 0.5  # 120 bpm


def context(config: PlanConfig | None = None, bounds: PlanBounds = DEFAULT_BOUNDS) -> ChainContext:
    return ChainContext(config or default_config(), bounds, Ledger(), lambda _t: SPB)


def drum(t: float, note: int, velocity: int = 100) -> NoteOn:
    return NoteOn(t, 9, note, velocity)


def bass(t: float, note: int, velocity: int = 90) -> NoteOn:
    return NoteOn(t, 0, note, velocity)
