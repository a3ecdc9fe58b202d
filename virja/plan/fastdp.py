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
    if os.environ.get("VIRJA_PLAN_PURE"):
        return None
    try:
        module = importlib.import_module("virja.plan._dpcore")
    except ImportError:
        return None
    try:
        digest = source_digest()
    except OSError:  # installed without the source: trust the build
        return module
    return module if getattr(module, "SOURCE_DIGEST", None) == digest else None


core: ModuleType | None = load()
