"""The rig clock: virtual time moves only forward when told; monotonic time sleeps until it is due."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rig.clock import Clock, MonotonicClock, VirtualClock


class FakeSystem:
    """A monotonic nanosecond counter that sleeping advances, waking early once if asked."""

    def __init__(self, start_ns: int, early_wake_s: float = 0.0) -> None:
        self.ns = start_ns
        self.sleeps: list[float] = []
        self._early = early_wake_s

    def read_ns(self) -> int:
        return self.ns

    def sleep(self, seconds: float) -> None:
        self.sleeps.append(seconds)
        slept = seconds - self._early if self._early else seconds
        self._early = 0.0
        self.ns += round(slept * 1e9)


@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=30))
def test_virtual_time_never_goes_backwards(targets: list[float]) -> None:
    clock = VirtualClock(start=-0.5)
    latest = -0.5
    for t in targets:
        clock.wait_until(t)
        latest = max(latest, t)
        assert clock.now() == latest


@pytest.mark.parametrize("kind", ["virtual", "monotonic"])
def test_each_clock_keeps_the_clock_contract(kind: str) -> None:
    # Waiting until a time leaves the clock at or after it, and time never runs backwards.
    system = FakeSystem(start_ns=5_000_000_000)
    clock: Clock = VirtualClock() if kind == "virtual" else MonotonicClock(system.read_ns, system.sleep)
    readings = [clock.now()]
    for target in (0.25, 0.1, 1.75, 1.75):
        clock.wait_until(target)
        readings.append(clock.now())
        assert clock.now() >= target
    assert readings == sorted(readings) and readings[-1] == pytest.approx(1.75)


def test_monotonic_time_counts_from_when_the_clock_was_made() -> None:
    system = FakeSystem(start_ns=123_456_789_000)
    clock = MonotonicClock(system.read_ns, system.sleep)
    assert clock.origin_ns == 123_456_789_000
    assert clock.now() == 0.0
    system.ns += 1_500_000_000
    assert clock.now_ns() == 1_500_000_000
    assert clock.now() == pytest.approx(1.5)


def test_waiting_sleeps_until_the_time_and_resumes_an_early_wake() -> None:
    system = FakeSystem(start_ns=10**12, early_wake_s=0.3)
    clock = MonotonicClock(system.read_ns, system.sleep)
    clock.wait_until(1.0)
    assert clock.now() >= 1.0
    assert system.sleeps == [pytest.approx(1.0), pytest.approx(0.3)]


def test_waiting_for_a_time_already_past_does_not_sleep() -> None:
    system = FakeSystem(start_ns=0)
    clock = MonotonicClock(system.read_ns, system.sleep)
    system.ns = 2_000_000_000
    clock.wait_until(1.0)
    assert system.sleeps == []
