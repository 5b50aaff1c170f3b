"""How well `rig calibrate-camera` measures a camera's readout and exposure: a grid of simulated
films whose camera the simulation knows (30, 60, 120 and 240 fps; readouts of 0, a global shutter,
to 95 % of the frame interval; exposures of an eighth to a whole frame interval; a light flashing
at 50 % and at 25 %, and a display flashing full-field), each measured as the command does, with
the readout's and the exposure's error, the refusals, how many are within 5 % and 10 % and how
many 95 % intervals hold the truth, and the seconds per film (5 to 8 minutes on two shared cores;
--quick films four small cases).

Declared here, without the bench's libraries, for the command line; `rig.bench.camera_calibration`
runs it.
"""

from __future__ import annotations

import argparse

from rig.bench.contract import Command, bench_in


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quick", action="store_true", help="four small films (a smoke test)")


SUBJECT = Command(
    name="camera-calibration",
    help="rig calibrate-camera's readout and exposure error on simulated films, 30 to 240 fps",
    bench=bench_in("camera_calibration"),
    options=_options,
    outputs={"json": "write the summaries and every film's row as JSON", "plot": "plot seconds per film against each error"},
    runs="keep the simulated films here (default: a temporary folder)",
)
