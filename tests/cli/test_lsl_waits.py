"""Every wait on Lab Streaming Layer stops within a second of Ctrl-C or SIGTERM: liblsl waits in C,
deaf to signals, so the rig never leaves it waiting longer than a slice (`in_slices`). The stream
here never answers: its outlet, in this process, is gone once the inlet has found it."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from itertools import count
from typing import Any, Callable, Iterator

import pytest

from rig import interrupts
from rig.devices.trackers.lsl_tracker import CHANNELS, RESOLVE_TIMEOUT_S, WAIT_SLICE_S, open_inlet, pylsl, time_correction

WAIT_S = 60.0
"""What each wait is given: far longer than the test may take."""
SIGNAL_AFTER_S = 0.3
STOP_WITHIN_S = 1.0
_names = count()

WAITS = [pytest.param(time_correction, id="time-correction"), pytest.param(open_inlet, id="open-stream")]
SIGNALS = [pytest.param(signal.SIGINT, KeyboardInterrupt, id="sigint"), pytest.param(signal.SIGTERM, interrupts.Terminated, id="sigterm")]


@pytest.fixture
def silent_inlet() -> Iterator[Any]:
    """An inlet of a pose stream whose sender has gone: every wait on it runs to its timeout."""
    lsl = pylsl()
    name = f"rig-test-silent-{os.getpid()}-{next(_names)}"
    outlet = lsl.StreamOutlet(lsl.StreamInfo(name, "MoCap", len(CHANNELS), 1000.0, lsl.cf_double64, name))
    (info,) = lsl.resolve_byprop("name", name, timeout=RESOLVE_TIMEOUT_S)
    inlet = lsl.StreamInlet(info, recover=True)
    del outlet
    yield inlet
    inlet.close_stream()


@pytest.fixture
def signals(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[[int], threading.Timer]]:
    """The rig's handling of SIGINT and SIGTERM installed (and this process's restored after), and a
    timer sending this process a signal SIGNAL_AFTER_S from when it is started."""
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)
    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    interrupts.install()
    timers: list[threading.Timer] = []

    def after(signum: int) -> threading.Timer:
        timers.append(threading.Timer(SIGNAL_AFTER_S, os.kill, (os.getpid(), signum)))
        return timers[-1]

    try:
        yield after
    finally:
        for timer in timers:
            timer.cancel()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        interrupts.handled()


@pytest.mark.parametrize("signum, raised", SIGNALS)
@pytest.mark.parametrize("wait", WAITS)
def test_a_wait_on_a_stream_that_never_answers_stops_at_a_signal(
    wait: Callable[[Any, float], object], signum: int, raised: type[BaseException], silent_inlet: Any,
    signals: Callable[[int], threading.Timer],
) -> None:  # fmt: skip
    timer = signals(signum)
    started = time.monotonic()
    timer.start()
    with pytest.raises(raised):
        wait(silent_inlet, WAIT_S)
    assert time.monotonic() - started < SIGNAL_AFTER_S + STOP_WITHIN_S


@pytest.mark.parametrize("wait", WAITS)
def test_a_wait_on_another_thread_stops_within_a_slice_of_the_signal(
    wait: Callable[[Any, float], object], silent_inlet: Any, signals: Callable[[int], threading.Timer]
) -> None:
    outcome: list[tuple[type[BaseException], float]] = []
    ended = threading.Event()

    def waiting() -> None:
        try:
            wait(silent_inlet, WAIT_S)
        except BaseException as error:  # noqa: BLE001 - what ended the wait is the result
            outcome.append((type(error), time.monotonic()))
        finally:
            ended.set()

    worker = threading.Thread(target=waiting, name="lsl wait")
    timer = signals(signal.SIGTERM)
    worker.start()
    timer.start()
    with pytest.raises(interrupts.Terminated):
        ended.wait(WAIT_S)  # the main thread is told first, as Python tells it every signal
    signalled = time.monotonic()
    assert ended.wait(WAIT_S)
    worker.join()
    assert [kind for kind, _ in outcome] == [interrupts.Terminated]
    assert outcome[0][1] - signalled < WAIT_SLICE_S + STOP_WITHIN_S


def test_a_wait_that_runs_out_ends_in_liblsl_s_timeout_after_its_time(silent_inlet: Any) -> None:
    started = time.monotonic()
    with pytest.raises(pylsl().util.TimeoutError):
        time_correction(silent_inlet, 3 * WAIT_SLICE_S)
    assert 3 * WAIT_SLICE_S <= time.monotonic() - started < 3 * WAIT_SLICE_S + STOP_WITHIN_S
