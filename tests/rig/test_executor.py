"""The local Dask cluster's workers: the cores shared out between them, without changing this process."""

from __future__ import annotations

import os
from typing import Any

from analysis.video.decoding import MAX_DECODE_THREADS
from rig.executor import executor, worker_environment


def test_local_workers_share_the_cores_out_without_dasks_profiler_or_trim_threshold() -> None:
    def worker_setup(_: Any) -> dict[str, Any]:
        # Nested, so that Dask ships it by value: a worker cannot import the test modules.
        import cv2
        import dask

        from analysis.video.decoding import decode_threads

        return {
            "opencv_threads": cv2.getNumThreads(),
            "decode_threads": decode_threads(),
            "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
            "profiler": dask.config.get("distributed.worker.profile.enabled"),
            "malloc_trim_threshold": os.environ.get("MALLOC_TRIM_THRESHOLD_"),
            "pid": os.getpid(),
        }

    environment = dict(os.environ)
    with executor(workers=2) as run:
        seen = [setup for _, setup in run(worker_setup, [0, 1])]
        assert dict(os.environ) == environment, "starting the workers changed this process's environment"
    assert all(setup["pid"] != os.getpid() for setup in seen)
    threads = int(environment.get("OPENCV_FOR_THREADS_NUM", max(1, len(os.sched_getaffinity(0)) // 2)))
    for setup in seen:
        assert {key: value for key, value in setup.items() if key != "pid"} == {
            "opencv_threads": threads,
            "decode_threads": min(threads, MAX_DECODE_THREADS),
            "blas_threads": environment.get("OPENBLAS_NUM_THREADS", "1"),
            "profiler": False,
            "malloc_trim_threshold": environment.get("MALLOC_TRIM_THRESHOLD_"),
        }


def test_worker_environment_is_what_a_local_worker_starts_with() -> None:
    expected = worker_environment(2)

    def seen(names: list[str]) -> dict[str, str | None]:
        return {name: os.environ.get(name) for name in names}

    with executor(workers=2) as run:
        [(_, variables)] = list(run(seen, [sorted(expected)]))
    assert variables == expected and "OPENCV_FOR_THREADS_NUM" in expected
