"""The batch driver: skip what is done, run the rest, place outputs, write the manifest."""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from virja.batch.executors import Executor, Item
from virja.batch.jobs import Job
from virja.batch.manifest import (
    JobResult,
    Manifest,
    Status,
    clear_partial,
    outputs_exist,
    place_outputs,
)
from virja.batch.work import BatchSettings

# called after each input: (results so far by status, inputs in all, seconds since start)
Progress = Callable[[Counter[Status], int, float], None]


@dataclass
class BatchSummary:
    counts: Counter[Status] = field(default_factory=Counter)
    seconds: float = 0.0
    worked_seconds: float = 0.0  # sum of the jobs' own times (ok and error)
    errors: list[tuple[str, str]] = field(default_factory=list)  # (input, message)

    @property
    def ran(self) -> int:
        return self.counts[Status.OK] + self.counts[Status.ERROR]


def run_batch(
    input_dir: Path,
    out_dir: Path,
    jobs: list[Job],
    settings: BatchSettings,
    executor: Executor,
    *,
    skip_existing: bool = False,
    progress: Progress | None = None,
) -> BatchSummary:
    """Run every job; returns the counts.  The manifest lists every input once."""
    out_dir.mkdir(parents=True, exist_ok=True)
    clear_partial(out_dir)
    manifest = Manifest(input_dir, out_dir)
    summary = BatchSummary()
    started = time.perf_counter()

    def record(result: JobResult) -> None:
        manifest.add(result)
        summary.counts[result.status] += 1
        if result.status is not Status.SKIPPED:
            summary.worked_seconds += result.seconds
        if result.status is Status.ERROR:
            summary.errors.append((str(input_dir / result.rel), result.error or ""))
        if progress is not None:
            progress(summary.counts, len(jobs), time.perf_counter() - started)

    def items() -> Iterator[Item]:
        for job in jobs:
            if skip_existing and outputs_exist(out_dir, job.all_outputs()):
                record(JobResult(job.rel, Status.SKIPPED, 0.0, outputs=list(job.all_outputs())))
                continue
            try:
                data = (input_dir / job.rel).read_bytes()
            except OSError as exc:
                record(
                    JobResult(
                        job.rel, Status.ERROR, 0.0, error=f"cannot read: {exc.strerror or exc}"
                    )
                )
                continue
            yield job, data

    try:
        for result in executor.run(items(), settings):
            if result.status is Status.OK:
                place_outputs(result, out_dir)
            record(result)
    finally:
        manifest.close()
        clear_partial(out_dir)
        summary.seconds = time.perf_counter() - started
    return summary
