"""Record, or compare against, the plans of many inputs: a guard for refactors.

`virja plan INPUT --json` runs in-process for every input (the bundled demos,
every MIDI file under the given folders, any pcap recordings named) and its
output is written to, or compared byte for byte with, one file per input in
the golden folder.  With --frames the demo is also rendered at a few moments
(EGL, 640x360) and the PNGs' pixels recorded or compared.

    python tools/plan_goldens.py record /tmp/goldens ../shared/data/gmd --jobs 2
    python tools/plan_goldens.py compare /tmp/goldens ../shared/data/gmd --jobs 2

Prints one line per difference and a summary; exits 1 when anything differs.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FRAME_TIMES = (0.5, 2.0, 5.25, 9.0, 14.6, 21.0)


def _key(path: Path) -> str:
    """The golden's name: the input's stem and a hash of its path (relative to the
    checkout for files inside it, so every worktree finds the demos' goldens)."""
    full = path.resolve()
    name = str(full.relative_to(ROOT)) if full.is_relative_to(ROOT) else str(full)
    digest = hashlib.sha1(name.encode()).hexdigest()[:10]
    return f"{path.stem}_{digest}"


def _plan_json(path: str) -> tuple[str, str]:
    from virja.cli.main import main

    out = io.StringIO()
    err = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(["plan", path, "--json"])
        except SystemExit as exc:
            rc = exc.code if isinstance(exc.code, int) else 1
    return path, f"rc={rc}\n" + out.getvalue()


def _frames(folder: Path, mode: str) -> list[str]:
    from PIL import Image

    from virja.cli.main import main

    problems = []
    scratch = Path(tempfile.mkdtemp(prefix="plan-goldens-"))
    demo = str(ROOT / "virja" / "demo" / "blues.mid")
    for t in FRAME_TIMES:
        target = folder / f"frame_{t:06.2f}.png"
        out = target if mode == "record" else scratch / f"new_frame_{t:06.2f}.png"
        rc = main(["render", demo, "--at", str(t), "--size", "640x360", "--out", str(out)])
        if rc != 0:
            problems.append(f"render --at {t}: exit {rc}")
            continue
        if mode == "compare":
            a = Image.open(target).tobytes()
            b = Image.open(out).tobytes()
            if a != b:
                n = sum(1 for x, y in zip(a, b, strict=True) if x != y)
                problems.append(f"frame {t}: {n} bytes differ")
            out.unlink()
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mode", choices=("record", "compare"))
    ap.add_argument("golden", type=Path, help="folder of golden files")
    ap.add_argument("inputs", nargs="*", type=Path, help="folders of MIDI files, or files")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--frames", action="store_true", help="also the demo's frames")
    ap.add_argument("--no-demos", action="store_true", help="skip virja/demo/*.mid")
    args = ap.parse_args()

    files: list[Path] = [] if args.no_demos else sorted((ROOT / "virja" / "demo").glob("*.mid"))
    for p in args.inputs:
        if p.is_dir():
            files += sorted(q for q in p.rglob("*") if q.suffix.lower() in (".mid", ".midi"))
        else:
            files.append(p)
    args.golden.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    with ProcessPoolExecutor(args.jobs) as pool:
        for path, text in pool.map(_plan_json, [str(f) for f in files], chunksize=8):
            target = args.golden / (_key(Path(path)) + ".jsonl")
            if args.mode == "record":
                target.write_text(text)
            elif not target.exists():
                problems.append(f"{path}: no golden")
            elif target.read_text() != text:
                old = target.read_text().splitlines()
                new = text.splitlines()
                first = next(
                    (i for i, (a, b) in enumerate(zip(old, new, strict=False)) if a != b),
                    min(len(old), len(new)),
                )
                problems.append(f"{path}: differs from line {first + 1} ({len(old)} vs {len(new)})")
    if args.frames:
        problems += _frames(args.golden, args.mode)
    for p in problems:
        print(p)
    print(
        f"{args.mode}: {len(files)} plans"
        + (f" + {len(FRAME_TIMES)} frames" if args.frames else "")
        + f", {len(problems)} differences"
    )
    return 1 if problems and args.mode == "compare" else 0


if __name__ == "__main__":
    sys.exit(main())
