"""One way to run many independent jobs (a batch of videos, a sweep, a bench grid): in this process,
on a local Dask cluster, or on an existing Dask scheduler, with the same answers whichever runs them.

A job is a pure function of picklable arguments (paths and parameters), so any worker can run it;
results come back as they complete, tagged with their place in the input, so a caller can record
each as soon as it exists and still put them in input order at the end.

    with executor(workers=2) as run:
        for index, result in run(analyse_one, requests):
            ...
"""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import time
from typing import Any, Callable, Iterator, Sequence

from rig.errors import ConfigError, RigError

def worker_environment(workers: int) -> dict[str, str]:
    """The variables a local cluster of `workers` gives each worker process (Dask's own and
    `local_worker_setup`'s), for running a job elsewhere as a worker would."""
    import dask
    import distributed  # noqa: F401 - its configuration defaults load with it

    with dask.config.set(local_worker_setup(workers)):
        variables = dask.config.get("distributed.nanny.pre-spawn-environ")
        return {name: str(value) for name, value in variables.items() if value is not None}


def local_worker_setup(workers: int) -> dict[str, Any]:
    """How the local cluster's `workers` are set up: with Dask's defaults a video cost about 30% more
    CPU time on a worker than with these."""
    return {
        # The cores shared out: OpenCV's parallel regions and the frame decoder that follows OpenCV's
        # thread count (`analysis.video.decoding.decode_threads`) use this process's cores over the
        # workers (one each on two cores, where the decoder then runs in the consumer alone), unless
        # the user's environment says otherwise; numpy's BLAS keeps Dask's one thread.
        "distributed.nanny.pre-spawn-environ.OPENCV_FOR_THREADS_NUM": os.environ.get(
            "OPENCV_FOR_THREADS_NUM", max(1, len(os.sched_getaffinity(0)) // workers)
        ),
        # Dask's 64 KiB trim threshold also turns off glibc's adaptive mmap threshold, so every decoded
        # frame (a few hundred KiB) is mapped and unmapped afresh: four times the page faults.
        "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
        # The sampling profiler stops the job's thread 100 times a second to feed a dashboard we do not start.
        "distributed.worker.profile.enabled": False,
    }


Jobs = Callable[[Callable[[Any], Any], Sequence[Any]], Iterator[tuple[int, Any]]]
"""Runs `function` on each item; yields (index of the item, its result) as each completes."""


def _serial(function: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
    for index, item in enumerate(items):
        yield index, function(item)


def _on_dask(client: Any) -> Jobs:
    from distributed import as_completed

    def run(function: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
        futures = {client.submit(function, item, pure=False): index for index, item in enumerate(items)}
        try:
            for future in as_completed(futures):
                yield futures[future], future.result()
        finally:
            client.cancel(list(futures))

    return run


def _check_reachable(scheduler: str, patience_s: float = 5.0) -> None:
    """Refuse a tcp:// scheduler nobody listens at before a Dask client is made (a client that
    fails to connect leaves its event loop's thread behind); one still starting gets `patience_s`."""
    scheme, _, where = scheduler.partition("://")
    if scheme != "tcp":
        return
    host, _, port = where.rpartition(":")
    if not host or not port.isdigit():
        raise ConfigError(f"--scheduler must be tcp://HOST:PORT, got {scheduler}")
    deadline = time.monotonic() + patience_s
    while True:
        try:
            socket.create_connection((host.strip("[]"), int(port)), timeout=patience_s).close()
            return
        except OSError as error:
            if time.monotonic() >= deadline:
                raise RigError(f"cannot reach the Dask scheduler at {scheduler}: {error.strerror or error}") from None
            time.sleep(0.25)


@contextlib.contextmanager
def _environment_kept() -> Iterator[None]:
    """This process's environment as it was: a nanny sets its workers' pre-spawn variables here
    too, which would limit this process's own threads (OpenCV reads its thread count lazily)."""
    kept = dict(os.environ)
    try:
        yield
    finally:
        for name in os.environ.keys() - kept.keys():
            del os.environ[name]
        os.environ.update(kept)


@contextlib.contextmanager
def executor(workers: int | None = None, scheduler: str | None = None) -> Iterator[Jobs]:
    """Jobs run serially here (neither given), on a local Dask cluster of `workers` processes
    running one job at a time each, with no dashboard, or on the Dask scheduler at `scheduler` (tcp://HOST:PORT),
    whose workers must reach the jobs' paths."""
    if workers is not None and scheduler is not None:
        raise ConfigError("give --workers or --scheduler, not both")
    if workers is None and scheduler is None:
        yield _serial
        return
    if workers is not None and workers < 1:
        raise ConfigError(f"--workers must be at least 1, got {workers}")
    import dask
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)
    with contextlib.ExitStack() as stack:
        if scheduler is not None:
            _check_reachable(scheduler)
            try:
                client = stack.enter_context(Client(scheduler, timeout="10s"))
            except OSError as error:
                raise RigError(f"cannot reach the Dask scheduler at {scheduler}: {error}") from None
        else:
            with dask.config.set(local_worker_setup(workers)), _environment_kept():
                cluster = stack.enter_context(
                    LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
                )
            client = stack.enter_context(Client(cluster))
        yield _on_dask(client)
