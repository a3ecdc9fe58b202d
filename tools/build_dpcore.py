"""Build the planner's C inner loops in place: virja/plan/_dpcore.c -> _dpcore<EXT>.so.

    python tools/build_dpcore.py [--check]

Compiles with the C compiler and the Python headers of the running interpreter (gcc
and the headers are on every machine the project is set up on; tools/setup.sh runs
this after installing virja).  Nothing to do when the module is already built from
the same source (its digest matches).  ``-ffp-contract=off``: no multiply-add is fused,
so each sum is rounded as the Python loops round it (the plans stay the same to the
bit).  Without the module the planner runs its Python loops (virja.plan.fastdp).
``--check``: exit 1 unless a module matching the source is importable.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLAN = ROOT / "virja" / "plan"
SOURCE = PLAN / "_dpcore.c"


def digest() -> str:
    import hashlib

    return hashlib.sha256(SOURCE.read_bytes()).hexdigest()[:16]


def target() -> Path:
    return PLAN / ("_dpcore" + sysconfig.get_config_var("EXT_SUFFIX"))


def built_digest() -> str | None:
    """The digest recorded in the built module, read in a fresh interpreter."""
    if not target().exists():
        return None
    code = "import virja.plan._dpcore as m; print(m.SOURCE_DIGEST)"
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
    )
    return out.stdout.strip() if out.returncode == 0 else None


def build() -> Path:
    cc = os.environ.get("CC") or shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        raise SystemExit("build_dpcore: no C compiler (gcc) found")
    include = sysconfig.get_paths()["include"]
    out = target()
    with tempfile.TemporaryDirectory() as tmp:
        so = Path(tmp) / out.name
        cmd = [
            cc,
            "-O2",
            "-ffp-contract=off",
            "-fno-fast-math",
            "-fPIC",
            "-shared",
            "-Wall",
            f"-I{include}",
            f'-DDPCORE_SOURCE_DIGEST="{digest()}"',
            str(SOURCE),
            "-o",
            str(so),
        ]
        subprocess.run(cmd, check=True)
        shutil.move(str(so), out)  # replaced whole: a running process keeps the old file
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only check that it is built")
    args = parser.parse_args(argv)
    current = built_digest() == digest()
    if args.check:
        print(
            f"build_dpcore: {target().name} {'matches' if current else 'does not match'} the source"
        )
        return 0 if current else 1
    if current:
        return 0
    path = build()
    if built_digest() != digest():
        raise SystemExit(f"build_dpcore: {path} was built but does not import")
    print(f"build_dpcore: built {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
