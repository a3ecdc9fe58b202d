"""The cyclic collector's pauses in `virja serve`: the daemon and, with --window, its viewer.

    .venv/bin/python tools/gc_pauses.py [--seconds 20] [--port 50621]
    xvfb-run -a -s "-screen 0 1280x800x24" .venv/bin/python tools/gc_pauses.py --window
    ... --no-freeze      # the same with every gc.freeze() left out (what it saves)

Runs ``virja serve`` (``--headless`` unless ``--window``) in this process for
``--seconds``, fed the demo (virja/demo/blues.mid) by ``virja send --loop`` over
loopback, and times every collection (``gc.callbacks``) once start-up is over (from
the daemon's ``gc.freeze()``; in the viewer process from its first frame).  At the end
each process prints, per generation, the count and the median, p99 and longest pause,
then the time of one full collection made there and then (what an oldest-generation
collection would cost it).  The viewer runs in a spawned process, which imports this
file as its main module: the timing is installed there at import.
"""

from __future__ import annotations

import argparse
import gc
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

NO_FREEZE_ENV = "VIRJA_GC_PAUSES_NO_FREEZE"
_pauses: list[tuple[int, float]] = []
_state: dict[str, float | None] = {"start": None, "up": None}


def _collector(phase: str, info: dict[str, Any]) -> None:
    if phase == "start":
        _state["start"] = time.perf_counter()
    elif _state["up"] is not None and _state["start"] is not None:
        _pauses.append((int(info["generation"]), (time.perf_counter() - _state["start"]) * 1000))


def _report(who: str) -> None:
    _state["up"] = None
    lines = [f"{who}: {len(gc.get_objects())} objects tracked, {gc.get_freeze_count()} frozen"]
    for g in (0, 1, 2):
        ms = sorted(p for gen, p in _pauses if gen == g)
        if not ms:
            lines.append(f"{who} generation {g}: 0 collections")
            continue
        p99 = ms[min(len(ms) - 1, round(0.99 * (len(ms) - 1)))]
        lines.append(
            f"{who} generation {g}: {len(ms)} collections, median {statistics.median(ms):.3f} ms,"
            f" p99 {p99:.3f} ms, longest {ms[-1]:.3f} ms"
        )
    a = time.perf_counter()
    gc.collect()
    lines.append(f"{who}: a full collection now {(time.perf_counter() - a) * 1000:.1f} ms")
    print("\n".join(lines), file=sys.stderr, flush=True)


def _instrument() -> None:
    """Time collections; mark start-up's end at gc.freeze() (left out with the
    environment's NO_FREEZE_ENV) or at the viewer's first frame; report the viewer's
    collections when its process ends."""
    import virja.live.frames as frames
    import virja.live.viewer as viewer

    gc.callbacks.append(_collector)
    real_freeze = gc.freeze
    skip = bool(os.environ.get(NO_FREEZE_ENV))

    def freeze() -> None:
        _state["up"] = time.perf_counter()
        if not skip:
            real_freeze()

    gc.freeze = freeze
    real_step = frames.FrameLoop.step

    def step(self: Any) -> bool:
        if _state["up"] is None:
            _state["up"] = time.perf_counter()
        return bool(real_step(self))

    frames.FrameLoop.step = step  # type: ignore[method-assign]
    _real_viewer_main[:] = [viewer.viewer_main]
    viewer.viewer_main = _viewer_main  # type: ignore[assignment]


_real_viewer_main: list[Any] = []


def _viewer_main(*args: Any) -> None:
    """The viewer process's body, then its report (module level: the spawned process is
    handed it by name)."""
    try:
        _real_viewer_main[0](*args)
    finally:
        _report("viewer")


if __name__ == "__mp_main__":  # the spawned viewer process imports this file so
    _instrument()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--port", type=int, default=50621)
    ap.add_argument("--window", action="store_true", help="a window (needs a display)")
    ap.add_argument("--no-freeze", action="store_true", help="leave every gc.freeze() out")
    args = ap.parse_args()
    if args.no_freeze:
        os.environ[NO_FREEZE_ENV] = "1"
    _instrument()
    from virja.cli.main import main as virja_main

    demo = Path(__file__).resolve().parent.parent / "virja" / "demo" / "blues.mid"
    to = f"127.0.0.1:{args.port}"
    sender = subprocess.Popen(
        [sys.executable, "-m", "virja", "send", str(demo), "--to", to, "--start-in", "3"]
        + ["--loop"],
        stdout=subprocess.DEVNULL,
    )
    try:
        argv = ["serve", "--listen", to, "--duration", f"{args.seconds:g}"]
        rc = virja_main(argv + ([] if args.window else ["--headless"]))
    finally:
        sender.terminate()
        sender.wait(timeout=10)
    _report("daemon")
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
