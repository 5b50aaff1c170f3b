"""`rig bench analyser`: simulate videos of known latency over two grids, analyse each with every
method, and report per method the median and worst error, the coverage of the 95 % intervals, the
confidently wrong answers (truth outside the interval by more than max(0.5 ms, its half-width)),
the refusals and the speed against decoding alone. The mixed grid spans periods, frame rates,
refresh rates, swings, damping and impairments; the hard grid, what goes wrong in a lab: camera
rates that lock to the display's, short exposures, a dim LED or sphere, swapped sides, a second
bright object, a partly hidden blob, decimated films. Both take about forty minutes on two cores;
--quick runs three tiny cases. The cases are a sweep: `rig sweep` on its spec gives the same
summary rows.

Declared here, without the bench's libraries, for the command line; `rig.bench.analyser` runs it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from rig.bench.contract import Command, SpecFile, bench_in

SPECS = Path(__file__).parent / "specs"
SPEC = SPECS / "analyser.toml"
QUICK_SPEC = SPECS / "analyser-quick.toml"
GROUPS = {"all": ("mixed", "named", "hard"), "mixed": ("mixed", "named"), "hard": ("hard",)}
"""Each grid --grid names, and the groups of points (a point's "group" label) it runs."""


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--grid", choices=tuple(GROUPS), default="all", help="which grid to run, by the points' group (default: %(default)s)")


SUBJECT = Command(
    name="analyser",
    help="error, interval coverage, confidently wrong answers and speed of each latency estimator on simulated videos",
    bench=bench_in("analyser"),
    options=_options,
    outputs={"json": "write the summaries, every case and the sweep's rows as JSON", "plot": "plot speed against error per method"},
    spec_file=SpecFile(SPEC, QUICK_SPEC,
                       help="the cases, as a sweep whose points are labelled case, group (mixed, named or hard) and impairment "
                       "(default: the bench's own)", quick_help=f"three short cases (a smoke test; {QUICK_SPEC.name})"),
    runs="keep the simulated videos and the sweep's summary.csv here (default: a temporary folder)",
    executor="the grid",
)  # fmt: skip
