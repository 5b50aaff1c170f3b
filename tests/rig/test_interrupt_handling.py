"""An interrupt that a library swallows (a garbage-collector callback, a bare except) is raised
again by the next progress report, and a SIGTERM stays a SIGTERM."""

from __future__ import annotations

import gc
import signal
import sys
from typing import Iterator

import pytest

from rig import interrupts
from rig.progress import ProgressBar


@pytest.fixture
def handlers() -> Iterator[None]:
    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    hook = sys.unraisablehook
    interrupts.install()
    yield
    interrupts.handled()
    sys.unraisablehook = hook
    for sig, handler in saved.items():
        signal.signal(sig, handler)


def _swallowed(sig: signal.Signals) -> None:
    try:
        signal.raise_signal(sig)
    except KeyboardInterrupt:
        pass


@pytest.mark.parametrize("sig, kind", [(signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, interrupts.Terminated)])
def test_a_swallowed_interrupt_is_raised_again_by_the_next_progress_report(handlers: None, sig: signal.Signals, kind: type) -> None:
    _swallowed(sig)
    assert interrupts.pending() is kind
    with pytest.raises(kind):
        ProgressBar("working", enabled=False)(1, 2)


def test_an_interrupt_raised_in_a_gc_callback_is_kept(handlers: None, monkeypatch: pytest.MonkeyPatch) -> None:
    # JAX's callback runs during XLA's work; Python reports what it raises as "ignored" and goes on.
    dropped: list[object] = []
    monkeypatch.setattr(sys, "unraisablehook", dropped.append)

    def interrupting(phase: str, info: dict) -> None:
        if phase == "start":
            gc.callbacks.remove(interrupting)
            signal.raise_signal(signal.SIGINT)

    gc.callbacks.append(interrupting)
    gc.collect()
    assert [type(report.exc_value) for report in dropped] == [KeyboardInterrupt]
    assert interrupts.pending() is KeyboardInterrupt


def test_python_reports_a_dropped_error_but_not_a_dropped_interrupt(handlers: None, capsys: pytest.CaptureFixture[str]) -> None:
    def report(kind: type[BaseException]) -> None:
        def failing(phase: str, info: dict) -> None:
            if phase == "start":
                gc.callbacks.remove(failing)
                raise kind("from a gc callback")

        gc.callbacks.append(failing)
        gc.collect()

    report(KeyboardInterrupt)
    assert capsys.readouterr().err == ""
    report(ValueError)
    assert "ValueError: from a gc callback" in capsys.readouterr().err


def test_a_handled_interrupt_is_not_raised_again(handlers: None) -> None:
    _swallowed(signal.SIGINT)
    interrupts.handled()
    ProgressBar("working", enabled=False)(1, 2)
    assert interrupts.pending() is None


def test_an_interrupt_in_a_deferred_section_comes_at_its_end(handlers: None) -> None:
    reached = []
    with pytest.raises(KeyboardInterrupt):
        with interrupts.deferred():
            signal.raise_signal(signal.SIGINT)
            reached.append("the rest of the section")
    assert reached == ["the rest of the section"]
