"""Shared fixtures: the motion library is loaded once per test session."""

from __future__ import annotations

import pytest

from virja.motion.clip import MotionLibrary, default_library


@pytest.fixture(scope="session")
def library() -> MotionLibrary:
    return default_library()
