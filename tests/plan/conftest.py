"""Shared helpers for the scheduler tests."""

from __future__ import annotations

import pytest

from virja.plan import PlanConfig, default_config


@pytest.fixture(scope="session")
def config() -> PlanConfig:
    return default_config()
