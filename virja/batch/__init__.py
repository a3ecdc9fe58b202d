"""Corpora at scale: one input after another through the same pipeline as a performance.

``jobs`` finds the inputs and names each output; ``work`` turns one input into
its outputs (in a worker process, a Ray task, or in-process) and returns them as
bytes; ``executors`` runs jobs on a local process pool or a Ray cluster;
``manifest`` places the outputs atomically and writes one JSON line per input.
"""

from virja.batch.jobs import Job, OutputKind, discover, make_jobs
from virja.batch.manifest import JobResult, Status
from virja.batch.run import BatchSummary, run_batch

__all__ = [
    "BatchSummary",
    "Job",
    "JobResult",
    "OutputKind",
    "Status",
    "discover",
    "make_jobs",
    "run_batch",
]
