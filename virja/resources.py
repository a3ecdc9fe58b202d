"""Where the package data lives: shaders/ and motions/.

In a wheel they are carried as ``virja/_data/{shaders,motions}`` (hatch
force-include) and found through :mod:`importlib.resources`; in a checkout
(editable install or ``python -m virja``) the top-level folders are used.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def _data_dir(name: str) -> Path:
    packaged = Path(str(resources.files("virja"))) / "_data" / name
    if packaged.is_dir():
        return packaged
    checkout = Path(__file__).resolve().parent.parent / name
    if checkout.is_dir():
        return checkout
    raise FileNotFoundError(
        f"virja package data folder {name!r} not found (looked in {packaged} and {checkout})"
    )


def shaders_dir() -> Path:
    """The folder of GLSL programs."""
    return _data_dir("shaders")


def motions_dir() -> Path:
    """The folder of basic-motion data and cost tables (TOML, BVH)."""
    return _data_dir("motions")


def motions_file(name: str, path: Path | None = None) -> Path | None:
    """``path``, else motions/``name``; None when that file is absent (the caller's
    defaults then stand)."""
    found = motions_dir() / name if path is None else path
    return found if found.is_file() else None
