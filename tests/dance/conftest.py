"""Shared synthetic teachers and music for the dance tests (seeded, built once)."""

from __future__ import annotations

import numpy as np
import pytest

from virja.dance.database import DanceDatabase, teach
from virja.dance.synth_capture import Teacher, make_teacher, random_boundaries
from virja.dance.synth_music import music


@pytest.fixture(scope="session")
def bounce() -> Teacher:
    rng = np.random.default_rng(1)
    return make_teacher("bounce", random_boundaries(20, rng), seed=1)


@pytest.fixture(scope="session")
def bounce_colours(bounce: Teacher) -> list[int]:
    """Noise colour of each music phrase (beat j to beat j + 1)."""
    return np.random.default_rng(2).integers(0, 3, len(bounce.beats_s) - 1).tolist()


@pytest.fixture(scope="session")
def bounce_music(bounce: Teacher, bounce_colours: list[int]) -> np.ndarray:
    return music(bounce.beats_s, bounce.bvh.n_frames / 30 + 0.3, bounce_colours, seed=2)


@pytest.fixture(scope="session")
def bounce_db(bounce: Teacher, bounce_music: np.ndarray) -> DanceDatabase:
    """Taught from the true beats without smoothing: cuts exactly on the boundaries."""
    return teach(
        bounce.bvh, bounce_music, "legs", beats_s=bounce.beats_s, q_over_r=None, source="bounce"
    )
