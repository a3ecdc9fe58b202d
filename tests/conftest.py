"""Shared fixtures: MIDI files built in the test, the session EGL context."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import mido
import pytest

REPO = Path(__file__).resolve().parent.parent
DEMO_MID = REPO / "virja" / "demo" / "blues.mid"


@pytest.fixture(scope="session")
def _session_gl_ctx() -> Iterator[Any]:
    """One headless EGL context for the whole session (Mesa llvmpipe without a GPU)."""
    from virja.render.hosts import create_headless_context

    ctx = create_headless_context()
    yield ctx
    ctx.release()


@pytest.fixture
def gl_ctx(_session_gl_ctx: Any) -> Iterator[Any]:
    """The session context, made current for this test (a CLI test in between may have
    made and released a context of its own, leaving none current), error flag clear."""
    ctx = _session_gl_ctx
    ctx.__enter__()
    _ = ctx.error  # reading the flag clears it
    assert ctx.error == "GL_NO_ERROR"
    try:
        yield ctx
    finally:
        ctx.__exit__(None, None, None)


def save_midi(
    path: Path, tracks: list[list[mido.Message | mido.MetaMessage]], tpb: int = 480, type_: int = 1
) -> Path:
    mf = mido.MidiFile(type=type_, ticks_per_beat=tpb)
    for msgs in tracks:
        mf.tracks.append(mido.MidiTrack(msgs))
    mf.save(str(path))
    return path
