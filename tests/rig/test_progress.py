"""Progress on stderr: a bar on a terminal, throttled lines elsewhere, on an injected clock."""

from __future__ import annotations

import io

from rig.progress import LINE_EVERY_S, ProgressBar


class Clock:
    """A clock the test moves."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _lines(label: str = "simulating", **options: object) -> tuple[ProgressBar, io.StringIO, Clock]:
    stream, clock = io.StringIO(), Clock()
    return ProgressBar(label, stream=stream, clock=clock, terminal=False, **options), stream, clock  # type: ignore[arg-type]


def test_off_a_terminal_a_run_done_within_the_interval_prints_nothing() -> None:
    progress, stream, clock = _lines()
    for step in range(10):
        clock.now = step * LINE_EVERY_S / 10
        progress(step, 10)
    progress(10, 10)
    assert stream.getvalue() == ""


def test_off_a_terminal_one_line_every_interval_and_one_at_the_end() -> None:
    progress, stream, clock = _lines(every_s=5.0)
    for step in range(1, 21):  # one step a second, twenty steps
        clock.now = float(step)
        progress(step, 20)
    assert stream.getvalue().splitlines() == [
        "simulating: 25%, about 15 s left",
        "simulating: 50%, about 10 s left",
        "simulating: 75%, about 5 s left",
        "simulating: 100%",
    ]


def test_off_a_terminal_the_end_is_said_once() -> None:
    progress, stream, clock = _lines(every_s=1.0)
    clock.now = 2.0
    progress(1, 4)
    progress(4, 4)
    progress(4, 4)
    assert stream.getvalue().splitlines() == ["simulating: 25%, about 6 s left", "simulating: 100%"]


def test_a_line_counts_in_its_unit() -> None:
    progress, stream, clock = _lines("analysing", unit="videos", every_s=1.0)
    clock.now = 90.0
    progress(3, 12)
    assert stream.getvalue() == "analysing: 25% 3/12 videos, about 4 min left\n"


def test_on_a_terminal_the_bar_is_redrawn_when_the_percentage_changes() -> None:
    stream = io.StringIO()
    progress = ProgressBar("analysing", stream=stream, clock=Clock(), terminal=True)
    progress(1, 200)
    progress(1.5, 200)  # still 0 %: not redrawn
    progress(100, 200)
    progress(200, 200)
    assert stream.getvalue().split("\r")[1:] == [
        f"analysing [{'.' * 30}]   0%",
        f"analysing [{'#' * 15}{'.' * 15}]  50%",
        f"analysing [{'#' * 30}] 100%\n",
    ]


def test_a_disabled_bar_shows_nothing_anywhere() -> None:
    for terminal in (True, False):
        stream, clock = io.StringIO(), Clock()
        progress = ProgressBar("x", stream=stream, clock=clock, terminal=terminal, enabled=False, every_s=0.0)
        clock.now = 10.0
        progress(1, 2)
        progress(2, 2)
        assert stream.getvalue() == ""


def test_a_stream_that_is_not_a_terminal_gets_lines() -> None:
    assert ProgressBar("x", stream=io.StringIO()).terminal is False
