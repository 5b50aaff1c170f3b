"""Shared by every test: property tests are deterministic, and no test may leave a thread running."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Callable, Iterator

import pytest
from hypothesis import settings

if TYPE_CHECKING:
    from matplotlib.figure import Figure

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


def _legends_clear_of_data(figure: Figure) -> None:
    """Every axis is labelled, and every legend lies outside its axes (so it covers no data)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure).draw()
    renderer = figure.canvas.get_renderer()
    for axes in figure.axes:
        if axes.get_label() == "<colorbar>" or not axes.get_visible():
            continue
        assert axes.get_xlabel() and axes.get_ylabel(), axes.get_title()
        legend = axes.get_legend()
        if legend is not None:
            box, area = legend.get_window_extent(renderer), axes.get_window_extent(renderer)
            assert box.x0 >= area.x1 - 1 or box.y1 <= area.y0 + 1 or box.x1 <= area.x0 + 1 or box.y0 >= area.y1 - 1


@pytest.fixture
def legends_clear_of_data() -> Callable[[Figure], None]:
    """Checks a figure: every axis labelled, every legend outside its axes (covering no data)."""
    return _legends_clear_of_data
