"""A job function for the pool tests: dies like a crashed native library on one input."""

from __future__ import annotations

import os

from virja.batch.jobs import Job
from virja.batch.manifest import JobResult
from virja.batch.work import BatchSettings, run_job


def run_or_die(job: Job, data: bytes, settings: BatchSettings) -> JobResult:
    if "crash" in job.rel:
        os._exit(3)
    return run_job(job, data, settings)
