"""Shared by every test: property tests are deterministic, and no test may leave a thread running."""

from __future__ import annotations

import threading
from typing import Iterator

import pytest
from hypothesis import settings

# Seeded property tests: the same examples on every machine and every run (failures found once
# are pinned with @example where they are tested).
settings.register_profile("deterministic", derandomize=True, database=None, deadline=None)
settings.load_profile("deterministic")


# Thread pools a library starts once for the whole process, on first use, and keeps: not leaks.
PROCESS_WIDE_POOLS = ("Dask-Offload",)


@pytest.fixture(autouse=True)
def no_threads_left() -> Iterator[None]:
    """Fails a test that leaves a thread running (after giving stragglers two seconds to end)."""
    before = set(threading.enumerate())
    yield
    left = [
        thread
        for thread in threading.enumerate()
        if thread not in before and thread.is_alive() and not thread.name.startswith(PROCESS_WIDE_POOLS)
    ]
    for thread in left:
        thread.join(timeout=2.0)
    still = [thread.name for thread in left if thread.is_alive()]
    assert not still, f"threads left running: {still}"
