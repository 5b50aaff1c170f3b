"""Shared by the tracker tests: an emulated tracker streaming on a thread of the test's process, and
the compiled reader threads this process has."""

from __future__ import annotations

import csv
import os
import threading
from contextlib import contextmanager
from typing import Callable, Iterator

import pytest

from rig.emulate import EmulatorConfig, make_sink, run_emulator
from rig.emulate.streamer import SentCounts


class EmulatedTracker:
    def __init__(self, config: EmulatorConfig) -> None:
        self.config = config
        self.sink = make_sink(config)
        self.counts: SentCounts | None = None
        self.events: list[str] = []
        self._thread = threading.Thread(target=self._run, name="emulated tracker")

    def _run(self) -> None:
        self.counts = run_emulator(self.config, self.sink, self.events.append)

    def join(self, timeout_s: float) -> bool:
        """Waits up to `timeout_s` for the emulator to end; whether it has."""
        self._thread.join(timeout_s)
        return not self._thread.is_alive()

    def fates(self) -> dict[str, list[int]]:
        """The emulator's log (config.log): record numbers by fate."""
        fates: dict[str, list[int]] = {"intact": [], "damaged": [], "lost": [], "unread": []}
        with self.config.log.open() as stream:
            for row in csv.DictReader(stream):
                fates[row["fate"]].append(int(row["seq"]))
        return fates

    @property
    def spec(self) -> str:
        if self.config.transport == "lsl":
            return self.sink.address
        return f"serial:{self.sink.address}?profile={self.config.profile}"


@pytest.fixture
def emulated_tracker() -> Iterator:
    """emulated_tracker(config) starts an emulator on a thread; it is joined and closed afterwards."""
    started: list[EmulatedTracker] = []

    @contextmanager
    def start(config: EmulatorConfig) -> Iterator[EmulatedTracker]:
        tracker = EmulatedTracker(config)
        started.append(tracker)
        tracker._thread.start()
        yield tracker

    yield start
    for tracker in started:
        tracker._thread.join(timeout=120)
        tracker.sink.close()


@pytest.fixture
def reader_threads() -> Callable[[str], set[str]]:
    """reader_threads(name): the ids of this process's threads called `name` (the compiled readers
    name theirs: "rig fd reader", "rig lsl reader"), so a test tells its own from others' (liblsl's)."""

    def named(name: str) -> set[str]:
        threads = set()
        for tid in os.listdir("/proc/self/task"):
            try:
                with open(f"/proc/self/task/{tid}/comm") as comm:
                    if comm.read().strip() == name:
                        threads.add(tid)
            except FileNotFoundError:  # a thread that ended meanwhile
                pass
        return threads

    return named
