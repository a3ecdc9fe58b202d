"""The planner's compiled inner loops (``_dpcore.c``), when built; None otherwise.

:data:`core` is the extension module ``virja.plan._dpcore`` when it was built from
this very source (tools/build_dpcore.py, run by tools/setup.sh: it compiles
``_dpcore.c`` in place and records the source's digest in the module); a module
built from another version of the source, none at all, or ``VIRJA_PLAN_PURE=1`` in
the environment leave it None, and the solvers run their Python loops.  Both give the
same plans to the bit (tests/plan/test_solver_equivalence.py runs both).
"""

from __future__ import annotations

import hashlib
import importlib
import os
from pathlib import Path
from types import ModuleType

SOURCE = Path(__file__).with_name("_dpcore.c")


def source_digest() -> str:
    """The first 16 hex digits of the SHA-256 of ``_dpcore.c`` (what a build records)."""
    return hashlib.sha256(SOURCE.read_bytes()).hexdigest()[:16]


def load() -> ModuleType | None:
    """The built extension if it matches the source next to it, else None."""
    return load_with_path()[0]


def load_with_path() -> tuple[ModuleType | None, str]:
    """:func:`load`, and which path the planner's DPs take with it, in words: "compiled",
    or "pure" and why (``VIRJA_PLAN_PURE=1``, not built, a stale build)."""
    if os.environ.get("VIRJA_PLAN_PURE"):
        return None, "pure (VIRJA_PLAN_PURE=1)"
    try:
        module = importlib.import_module("virja.plan._dpcore")
    except ImportError:
        return None, "pure (not built: python tools/build_dpcore.py)"
    try:
        digest = source_digest()
    except OSError:  # installed without the source: trust the build
        return module, "compiled"
    if getattr(module, "SOURCE_DIGEST", None) != digest:
        return (
            None,
            "pure (stale build of another _dpcore.c fell back: python tools/build_dpcore.py)",
        )
    return module, "compiled"


core, _PATH = load_with_path()


def path() -> str:
    """Which path the planner's DPs take in this process: "compiled" (``_dpcore.c``) or
    "pure" with the reason (what ``virja bench`` and tools/plan_speed.py report, so that
    a missing or stale build is seen)."""
    if core is None and _PATH == "compiled":  # set aside in this process (tests do)
        return "pure (set aside in this process)"
    return _PATH
