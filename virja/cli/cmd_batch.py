"""Turn a folder of MIDI files (and pcap recordings) into plans, motion, notation or video.

Walks INPUT_DIR for MIDI files and pcaps, and for each writes the outputs named
by --export under OUT_DIR, mirroring the input's path below INPUT_DIR:

  plan      NAME.plan.jsonl                the plan, as `virja plan --json` prints it
  bvh       NAME_drums.bvh, NAME_bass.bvh  each figure's motion (as `virja export --bvh`)
  gltf      NAME.glb                       the band animated (as `virja export --gltf`)
  musicxml  NAME.musicxml                  notation, string/fret and sticking (`virja export`)
  mp4       NAME.mp4                       video with sound (as `virja render`)

OUT_DIR/manifest.jsonl gets one JSON object per input: input, status (ok, error
or skipped), outputs, seconds, and error (the message) when it failed.  A bad
file never stops the batch.  Outputs appear atomically, so --skip-existing
resumes a batch that was killed halfway without taking a partial file as done.

By default the inputs run on a pool of --workers local processes (default: the
cores); with --ray on a Ray cluster: a local one, or the one at ADDRESS
(needs `pip install 'virja[ray]'` on every node; see docs/batch.md).

examples:
  virja batch ../shared/data/gmd --out out/gmd --export plan,bvh
  virja batch corpus/ --out out/corpus --export plan --skip-existing --workers 2
  virja batch corpus/ --out out/corpus --export gltf,musicxml --ray       # local Ray
  virja batch corpus/ --out /shared/out --export plan --ray ray://head:10001
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path
from typing import IO

from virja.batch.jobs import OutputKind, discover, make_jobs, parse_kinds
from virja.batch.manifest import MANIFEST_NAME, Status
from virja.cli.common import add_routing_arguments, finite_float, routing_config
from virja.errors import ConfigError

MAX_WORKERS = 1024  # processes (or Ray tasks in flight) at once; more is a typo


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("input_dir", metavar="INPUT_DIR", help="folder walked for .mid/.midi/.pcap")
    p.add_argument("--out", required=True, metavar="OUT_DIR", help="where the outputs go")
    p.add_argument(
        "--export",
        default="plan",
        metavar="KINDS",
        help="comma-separated outputs: "
        + ", ".join(k.value for k in OutputKind)
        + " (default plan)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="parallel workers (default: the cores)",
    )
    p.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="run on Ray: a local instance, or the cluster at ADDRESS",
    )
    p.add_argument(
        "--skip-existing",
        action="store_true",
        help="skip an input whose outputs are all there (resume a killed batch)",
    )
    p.add_argument(
        "--lookahead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="MIDI files: each note is known B beats ahead (default 1)",
    )
    p.add_argument(
        "--fps", type=finite_float, default=30.0, help="bvh and mp4: frames per second (default 30)"
    )
    p.add_argument("--size", default="1280x720", metavar="WxH", help="mp4: frame size")
    p.add_argument("--soundfont", metavar="FILE.sf2", help="mp4: General MIDI soundfont")
    add_routing_arguments(p)


class BatchProgress:
    """Files done and failed, and the time left, on one line of stderr (a line
    per tenth when stderr is not a terminal)."""

    def __init__(self, stream: IO[str] | None = None) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.tty = self.stream.isatty()
        self._last_decile = -1

    def __call__(self, counts: Counter[Status], total: int, elapsed_s: float) -> None:
        done = sum(counts.values())
        ran = counts[Status.OK] + counts[Status.ERROR]
        left = total - done
        eta = f"{elapsed_s / ran * left:.0f} s left" if ran and left else "-"
        text = (
            f"batch: {done}/{total} files ({counts[Status.OK]} ok, "
            f"{counts[Status.ERROR]} failed, {counts[Status.SKIPPED]} skipped), {eta}"
        )
        if self.tty:
            self.stream.write("\r" + text + ("\n" if done == total else ""))
            self.stream.flush()
            return
        decile = int(10 * done / max(total, 1))
        if decile != self._last_decile or done == total:
            self._last_decile = decile
            self.stream.write(text + "\n")
            self.stream.flush()


def run(args: argparse.Namespace) -> int:
    from virja.batch.executors import Executor, LocalPool, RayPool, default_workers
    from virja.batch.run import run_batch
    from virja.batch.work import BatchSettings
    from virja.plan.config import load_plan_config
    from virja.render.offline import parse_size

    kinds = parse_kinds(args.export)
    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise ConfigError(f"--workers must be 1-{MAX_WORKERS}, got {args.workers}")
    if not 0 < args.fps <= 240:
        raise ConfigError(f"--fps must be in (0, 240], got {args.fps}")
    if args.lookahead_beats < 0:
        raise ConfigError("--lookahead-beats must be >= 0")
    input_dir, out_dir = Path(args.input_dir), Path(args.out)
    jobs = make_jobs(discover(input_dir), kinds)
    # every setting is checked here, before any work: a bad config fails once, not per file
    settings = BatchSettings(
        plan=load_plan_config(args.config),
        routing=routing_config(args),
        lookahead_beats=args.lookahead_beats,
        fps=args.fps,
        size=parse_size(args.size),
        soundfont=args.soundfont,
    )
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / MANIFEST_NAME).touch()
    except OSError as exc:
        raise ConfigError(f"--out {out_dir}: cannot write there: {exc.strerror or exc}") from None
    executor: Executor = (
        RayPool(args.ray, args.workers)
        if args.ray is not None
        else LocalPool(args.workers or default_workers())
    )
    print(
        f"batch: {len(jobs)} inputs from {input_dir}, {', '.join(kinds)}, on {executor.description}"
    )
    try:
        summary = run_batch(
            input_dir,
            out_dir,
            jobs,
            settings,
            executor,
            skip_existing=args.skip_existing,
            progress=BatchProgress(),
        )
    finally:
        executor.close()
    for path, message in summary.errors[:20]:
        print(f"  failed: {path}: {message}")
    if len(summary.errors) > 20:
        print(f"  ... and {len(summary.errors) - 20} more (see the manifest)")
    rate = summary.ran / summary.seconds if summary.seconds > 0 else 0.0
    print(
        f"batch: {summary.counts[Status.OK]} ok, {summary.counts[Status.ERROR]} failed, "
        f"{summary.counts[Status.SKIPPED]} skipped in {summary.seconds:.1f} s "
        f"({rate:.2f} files/s, {summary.worked_seconds:.1f} s of work); "
        f"manifest: {out_dir / MANIFEST_NAME}"
    )
    return 1 if summary.counts[Status.ERROR] else 0
