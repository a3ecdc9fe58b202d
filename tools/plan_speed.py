"""The planner's speed, before and after a change, measured paired on a noisy machine.

    git archive main virja motions | (mkdir -p /tmp/before && tar -x -C /tmp/before)
    .venv/bin/python tools/plan_speed.py --before /tmp/before [--rounds 10]

Runs ``virja bench``'s two planning figures (``virja.bench.plan_beat_ms``: one beat of
16 notes per performer planned at once, p50 and p99 over 300 beats; and
``plan_streamed_ms``: the live case, note by note) in a fresh process, alternately
with the source tree ``--before`` (a copy of another commit's ``virja`` package) and
with this checkout, ``--rounds`` times each.  It prints, per side, the medians over
the rounds of each figure, the best round's p99, and the p50 and p99 of each beat's
least time over the rounds (the same 300 beats each round: what is left when the
other jobs on the machine are taken off), and which path the DPs took on that side
(``virja.plan.fastdp.path``: "compiled", or "pure" and why).  ``git archive`` carries
no build: copy or build ``virja/plan/_dpcore*.so`` into the ``--before`` tree when it has
a ``_dpcore.c``, or its side runs the Python loops (and says "pure (not built...)").
Nothing is written.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

# Run in the child: the beats of plan_beat_ms timed one by one, then both figures.
CHILD = """
import json, time
from virja.bench import plan_beat_ms, plan_streamed_ms
from virja.plan.bench import beat_workload, plan_one_beat
from virja.plan.config import default_config

config = default_config()
workloads = [beat_workload(seed, 16) for seed in range(300)]
plan_one_beat(workloads[0], config)
beats = []
for w in workloads:
    start = time.perf_counter()
    plan_one_beat(w, config)
    beats.append((time.perf_counter() - start) * 1000)
p50, p99 = plan_beat_ms(300)[:2]  # a third value (the cold start) since round 7
s50, s99 = plan_streamed_ms(200)
from virja.plan import fastdp
# a tree from before the path was reported says only whether its build was used
path = fastdp.path() if hasattr(fastdp, "path") else (
    "compiled" if fastdp.core is not None else "pure")
print(json.dumps({"beats": beats, "figures": [p50, p99, s50, s99], "path": path}))
"""


def run_side(source: Path | None) -> dict[str, Any]:
    """One round in a fresh process: ``source``'s virja package first on the path
    (None: this checkout's)."""
    env = dict(os.environ)
    cwd = ROOT
    if source is not None:
        env["PYTHONPATH"] = str(source)
        cwd = source
    out = subprocess.run(
        [sys.executable, "-c", CHILD], cwd=cwd, env=env, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise SystemExit(f"plan_speed: the round failed: {out.stderr.strip().splitlines()[-1]}")
    result: dict[str, Any] = json.loads(out.stdout)
    return result


def summary(name: str, rounds: list[dict[str, Any]]) -> str:
    paths = sorted({r.get("path", "?") for r in rounds})
    figures = np.array([r["figures"] for r in rounds])
    least = np.array([r["beats"] for r in rounds]).min(axis=0)
    med = [statistics.median(figures[:, i]) for i in range(4)]
    return (
        f"{name}: {len(rounds)} rounds | medians: plan p50 {med[0]:.3f} p99 {med[1]:.3f} ms, "
        f"streamed p50 {med[2]:.3f} p99 {med[3]:.3f} ms | best round's plan p99 "
        f"{figures[:, 1].min():.3f} ms | each beat's least: p50 "
        f"{np.percentile(least, 50):.3f} p99 {np.percentile(least, 99):.3f} ms | DP path: "
        f"{', '.join(paths)}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="a copy of the virja tree")
    parser.add_argument("--rounds", type=int, default=10, help="rounds per side (default 10)")
    args = parser.parse_args()
    if not (args.before / "virja" / "__init__.py").is_file():
        parser.error(f"--before {args.before}: no virja package there")
    if args.rounds < 1:
        parser.error("--rounds must be >= 1")
    before: list[dict[str, Any]] = []
    after: list[dict[str, Any]] = []
    for _ in range(args.rounds):
        before.append(run_side(args.before.resolve()))
        after.append(run_side(None))
    print(summary("before", before))
    print(summary("after ", after))
    return 0


if __name__ == "__main__":
    sys.exit(main())
