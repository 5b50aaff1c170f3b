"""Shared by the tracker tests: an emulated tracker streaming on a thread of the test's process."""

from __future__ import annotations

import csv
import threading
from contextlib import contextmanager
from typing import Iterator

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

    def fates(self) -> dict[str, list[int]]:
        """The emulator's log (config.log): record numbers by fate."""
        fates: dict[str, list[int]] = {"intact": [], "damaged": [], "lost": []}
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
