"""Where jobs run: a local process pool (the default) or a Ray cluster.

Both take ``(job, input bytes)`` pairs and yield :class:`JobResult` as jobs
finish, in whatever order they finish, with at most a few jobs in flight per
worker (inputs are read as they are submitted, not all at once).  A worker
that dies (a crash in a native library, the OOM killer) fails only the job it
was running: the local pool is rebuilt and the other jobs are submitted again.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol

from virja.batch.jobs import Job
from virja.batch.manifest import JobResult, Status
from virja.batch.work import BatchSettings, run_job
from virja.errors import ConfigError, NotAvailableError

Item = tuple[Job, bytes]
JobFn = Callable[[Job, bytes, BatchSettings], JobResult]
IN_FLIGHT_PER_WORKER = 2


class Executor(Protocol):
    workers: int
    description: str

    def run(self, items: Iterable[Item], settings: BatchSettings) -> Iterator[JobResult]: ...

    def close(self) -> None: ...


def default_workers() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _die_with_parent() -> None:
    """Pool initializer: on Linux, ask the kernel to kill this worker when the batch
    process dies (a SIGKILLed batch must not leave workers behind, stuck on a pipe)."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes
    import signal

    PR_SET_PDEATHSIG = 1
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # no prctl here: the worker lives on until its job ends
        return
    if os.getppid() == 1:  # the parent died before prctl took effect
        os._exit(1)


def _died(job: Job, why: str) -> JobResult:
    return JobResult(job.rel, Status.ERROR, 0.0, error=f"the worker died: {why}")


class LocalPool:
    """A pool of ``workers`` processes on this machine (spawned, so each has its
    own GL context when it renders video)."""

    def __init__(self, workers: int, job_fn: JobFn = run_job) -> None:
        if workers < 1:
            raise ConfigError(f"--workers must be at least 1, got {workers}")
        self.workers = workers
        self._job_fn = job_fn  # a top-level function (it is pickled by name for the workers)
        self.description = f"{workers} local worker process{'es' if workers != 1 else ''}"
        self._pool = self._new_pool()

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_die_with_parent,
        )

    def run(self, items: Iterable[Item], settings: BatchSettings) -> Iterator[JobResult]:
        todo = iter(items)
        running: dict[Future[JobResult], Item] = {}

        def top_up() -> None:
            while len(running) < self.workers * IN_FLIGHT_PER_WORKER:
                item = next(todo, None)
                if item is None:
                    return
                running[self._pool.submit(self._job_fn, item[0], item[1], settings)] = item

        top_up()
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            suspects: list[Item] = []
            for fut in done:
                item = running.pop(fut)
                try:
                    yield fut.result()
                except BrokenProcessPool:
                    suspects.append(item)
            if suspects:
                # a dead worker breaks the whole pool and every job in flight with it:
                # run those one at a time, so only the input that kills a worker fails
                suspects.extend(running.values())
                running.clear()
                self._restart()
                for item in suspects:
                    yield self._run_alone(item, settings)
            top_up()

    def _restart(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._new_pool()

    def _run_alone(self, item: Item, settings: BatchSettings) -> JobResult:
        try:
            return self._pool.submit(self._job_fn, item[0], item[1], settings).result()
        except BrokenProcessPool as exc:
            self._restart()
            return _died(item[0], str(exc) or "the process pool broke")

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)


class RayPool:
    """Jobs as Ray tasks: a local Ray instance when ``address`` is empty, else the
    cluster at ``address`` (``ray://HOST:10001`` or ``HOST:6379``; or ``auto``).
    Inputs travel to the tasks and outputs back as bytes, so the nodes need
    virja installed but no shared filesystem."""

    def __init__(self, address: str, workers: int | None) -> None:
        try:
            import ray
        except ImportError:
            raise NotAvailableError(
                "--ray needs Ray: pip install 'virja[ray]' (or pip install ray)"
            ) from None
        self._ray: Any = ray
        init: dict[str, Any] = {
            "ignore_reinit_error": True,
            "include_dashboard": False,
            "log_to_driver": False,
            "configure_logging": False,
        }
        if address:
            init["address"] = address
        elif workers is not None:
            init["num_cpus"] = workers
        try:
            ray.init(**init)
        except Exception as exc:  # Ray's own connection errors have no common base
            where = address or "a local Ray instance"
            raise NotAvailableError(f"--ray: cannot start or reach {where}: {exc}") from None
        cpus = int(ray.cluster_resources().get("CPU", 1))
        self.workers = workers if workers is not None else max(1, cpus)
        self.description = (
            f"Ray ({'cluster at ' + address if address else 'local'}, {cpus} CPUs, "
            f"{self.workers} tasks at a time)"
        )
        self._remote = ray.remote(num_cpus=1, max_retries=0)(run_job)

    def run(self, items: Iterable[Item], settings: BatchSettings) -> Iterator[JobResult]:
        ray = self._ray
        todo = iter(items)
        settings_ref = ray.put(settings)
        running: dict[Any, Item] = {}

        def top_up() -> None:
            while len(running) < self.workers * IN_FLIGHT_PER_WORKER:
                item = next(todo, None)
                if item is None:
                    return
                running[self._remote.remote(item[0], item[1], settings_ref)] = item

        top_up()
        while running:
            done, _ = ray.wait(list(running), num_returns=1)
            for ref in done:
                item = running.pop(ref)
                try:
                    yield ray.get(ref)
                except Exception as exc:  # the task's worker died (run_job itself never raises)
                    yield _died(item[0], f"{type(exc).__name__}: {exc}".splitlines()[0])
            top_up()

    def close(self) -> None:
        self._ray.shutdown()
