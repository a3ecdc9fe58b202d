"""Shared fixtures: MIDI files built in the test, the session EGL context."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import mido
import pytest

REPO = Path(__file__).resolve().parent.parent
DEMO_MID = REPO / "virja" / "demo" / "blues.mid"


@pytest.fixture(scope="session")
def gl_ctx() -> Iterator[object]:
    """One headless EGL context for the whole session (Mesa llvmpipe without a GPU)."""
    from virja.render.hosts import create_headless_context

    ctx = create_headless_context()
    assert ctx.error == "GL_NO_ERROR"
    yield ctx
    ctx.release()


def save_midi(
    path: Path, tracks: list[list[mido.Message | mido.MetaMessage]], tpb: int = 480, type_: int = 1
) -> Path:
    mf = mido.MidiFile(type=type_, ticks_per_beat=tpb)
    for msgs in tracks:
        mf.tracks.append(mido.MidiTrack(msgs))
    mf.save(str(path))
    return path
