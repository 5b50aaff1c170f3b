"""The batch bench (`rig bench batch`): what many measurements cost, serially and on Dask.

Declared here, without the bench's libraries, for the command line; `rig.bench.batch` runs it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

from declared import Flag, Range, check, like, setting
from rig.bench.contract import Command, bench_in
from rig.commands.declared_options import add_declared_options
from rig.errors import ConfigError
from rig.sim.config import SimulationConfig

SIMULATING_S_PER_FILM_S = 0.25
"""Seconds simulating a second of film takes: a generous rate (this machine takes about 0.75)."""
ANALYSING_S_PER_FILM_S = 0.05
"""Seconds analysing a second of film takes: a generous rate."""
MAX_HOURS = 24.0
"""The longest batch bench it starts: longer is a mistake in the options."""


@dataclass(frozen=True)
class BatchBenchOptions:
    """The batch bench's options, each declared on its field; a bench that could not finish in
    MAX_HOURS at generous rates is refused with its estimate."""

    videos: int = setting(24, "videos", "videos in the batch (a lab's day of films is tens to hundreds)", Range(1.0, 1000.0, True, True),
                          flag="--videos")  # fmt: skip
    duration_s: float = like(SimulationConfig, "duration_s", default=6.0, help="seconds per batch video", flag=Flag("--duration"))
    clip_duration_s: float = like(SimulationConfig, "duration_s", default=20.0, help="seconds of the fixed-cost clip",
                                  flag=Flag("--clip-duration"))  # fmt: skip
    workers: int = setting(2, "processes", "Dask worker processes", Range(1.0, 256.0, True, True), flag="--workers")
    rounds: int = setting(3, "", "times the batch runs serially and on Dask, alternately", Range(1.0, 100.0, True, True),
                          flag="--rounds")  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError)
        hours = self.estimated_hours()
        if hours > MAX_HOURS:
            raise ConfigError(
                f"this bench would take about {hours:.3g} hours ({self.videos} videos of {self.duration_s:g} s, each "
                f"analysed {3 * self.rounds} times), more than the {MAX_HOURS:g} hours the rig starts: fewer videos, "
                "shorter ones or fewer rounds"
            )

    def estimated_hours(self) -> float:
        """Hours at the generous rates above: every film simulated once, each batch video analysed
        three times a round (serially, serially as a worker, on Dask), the clip three times."""
        batch_s = self.videos * self.duration_s
        simulating = (batch_s + self.clip_duration_s) * SIMULATING_S_PER_FILM_S
        analysing = (3 * self.rounds * batch_s + 3 * self.clip_duration_s) * ANALYSING_S_PER_FILM_S
        return (simulating + analysing) / 3600.0


SUBJECT = Command(
    name="batch",
    help="what many measurements cost: a batch serially and on Dask, and the fixed cost per video",
    bench=bench_in("batch"),
    options=partial(add_declared_options, kind=BatchBenchOptions),
    outputs={"json": "write the figures as JSON", "plot": "draw the wall times"},
)
