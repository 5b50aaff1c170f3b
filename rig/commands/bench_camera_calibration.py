"""`rig bench camera-calibration`: `rig calibrate-camera`'s error on simulated films (see `rig.bench.camera_calibration`)."""

from __future__ import annotations

import argparse
import sys
import time

from rig.commands import outputs


def _run(args: argparse.Namespace) -> int:
    from rig.bench import camera_calibration as bench

    started = time.perf_counter()
    found = bench.rows(bench.QUICK_GRID if args.quick else bench.CalibrationGrid(), lambda message: print(message, file=sys.stderr, flush=True))
    summaries = bench.summary(found)
    met = bench.targets_met(found)
    writes = outputs.LateWrites()
    if args.json is not None:
        writes.json(args.json, {"summary": summaries, "targets_met": met, "rows": found, "seconds": time.perf_counter() - started})
    if args.plot is not None:
        writes.write(args.plot, lambda: bench.plot(found, args.plot))
    print(bench.table(summaries))
    for target, ok in met.items():
        print(f"{target}: {'met' if ok else 'not met'}")
    print(f"{len(found)} films in {(time.perf_counter() - started) / 60:.1f} minutes")
    writes.check()
    return 0


def add_camera_calibration(benchmarks: argparse._SubParsersAction) -> None:
    """Register `bench camera-calibration`."""
    parser = benchmarks.add_parser(
        "camera-calibration",
        help="rig calibrate-camera's readout and exposure error on simulated films, 30 to 240 fps",
        description="Film a flashing light (50 % and 25 % duty) and a display flashing full-field with the simulated "
        "camera at 30, 60, 120 and 240 fps, readouts of 0 (a global shutter) to 95 % of the frame interval and "
        "exposures of an eighth to a whole frame interval, measure each film as `rig calibrate-camera` does, and "
        "report per source the readout's and the exposure's error, the refusals, how many are within 5 % and 10 % "
        "and how many 95 % intervals hold the truth, and the seconds per film. About 15 minutes on two cores; "
        "--quick films four small cases.",
    )
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the summaries and every film's row as JSON")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="plot seconds per film against each error")
    parser.add_argument("--quick", action="store_true", help="four small films (a smoke test)")
    parser.set_defaults(func=_run)
