from __future__ import annotations

from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent.parent / "data" / "rmcp"


def golden(name: str) -> bytes:
    return (DATA / name).read_bytes()


@pytest.fixture
def data_dir() -> Path:
    return DATA
