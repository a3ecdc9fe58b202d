"""The window under load, N times: `virja serve` in a window (Xvfb), a process keeping
every core busy, `virja send` of the demo; prints each run's notes planned and dropped.

    .venv/bin/python tools/live_load.py --runs 10
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import virja

VIRJA = [sys.executable, "-m", "virja"]
DEMO = Path(virja.__file__).parent / "demo" / "blues.mid"


def spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        pass


def xvfb() -> tuple[subprocess.Popen[bytes], str]:
    r, w = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(w), "-screen", "0", "1400x900x24", "-nolisten", "tcp"],
        pass_fds=(w,),
        stderr=subprocess.DEVNULL,
    )
    os.close(w)
    with os.fdopen(r) as f:
        return proc, ":" + f.readline().strip()


def one_run(display: str, size: str, headless: bool = False) -> str:
    env = dict(os.environ, DISPLAY=display, PYTHONUNBUFFERED="1")
    with tempfile.TemporaryDirectory() as tmp:
        plan = Path(tmp) / "plan.jsonl"
        serve = subprocess.Popen(
            [*VIRJA, "serve", "--quiet", "--listen", "127.0.0.1:0", "--size", size]
            + ["--plan-log", str(plan), "--duration", "120"]
            + (["--headless"] if headless else []),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        assert serve.stdout is not None
        m = re.search(r":(\d+)", serve.stdout.readline())
        if not m:
            serve.kill()
            return "serve did not start: " + serve.communicate()[1].strip()
        hogs = [mp.Process(target=spin, args=(40.0,)) for _ in range(os.cpu_count() or 2)]
        for h in hogs:
            h.start()
        subprocess.run([*VIRJA, "send", str(DEMO), "--to", f"127.0.0.1:{m.group(1)}"], check=True)
        time.sleep(1.0)
        serve.send_signal(2)
        out, _ = serve.communicate(timeout=60)
        for h in hogs:
            h.terminate()
            h.join()
        keep = ("notes:", "dropped on arrival", "dropped:", "window:")
        return " | ".join(
            line.strip() for line in out.splitlines() if line.strip().startswith(keep)
        )


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=10)
    p.add_argument("--size", default="1280x720")
    p.add_argument("--headless", action="store_true", help="the same without the window")
    args = p.parse_args()
    proc, display = xvfb()
    try:
        for i in range(args.runs):
            print(f"run {i + 1}: {one_run(display, args.size, args.headless)}", flush=True)
    finally:
        proc.terminate()
        proc.wait()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
