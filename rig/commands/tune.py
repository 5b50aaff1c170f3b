"""`rig tune`: fit a predictor's parameters to recorded motion, check them on motion held out, and
write them only if they beat the defaults there.

Each --trace is split in time: its first --split to train on, the rest to validate on (or the
--held-out files are the validation). Prints training and validation RMS errors of the tuned
parameters, the defaults, constant velocity and the default predictor (see `rig.service.tune`).
Exit status 0 when the parameters were written, 1 when they lost to the defaults on validation and
were not (--force writes them anyway), 2 for a usage error, such as a trace out of time order
(--repair sorts it).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from rig.commands import choices, options, outputs
from rig.commands.declared_options import add_declared_option
from rig.progress import ProgressBar
from rig.tune_settings import TuneSettings

if TYPE_CHECKING:
    from rig.service import TuneReport

EXIT_NOT_WRITTEN = 1


def _table(report: TuneReport) -> str:
    from rig.service.tune import PARTS

    rows = [f"RMS error at {report.horizon_ms:g} ms         training (deg, mm)    validation (deg, mm)"]
    for key, label in report.labels.items():
        cells = "   ".join(
            f"{report.errors[part][key]['angular_rms_deg']:8.4f} {report.errors[part][key]['position_rms_mm']:9.4f}" for part in PARTS
        )
        rows.append(f"  {label:28s} {cells}")
    return "\n".join(rows)


def _run(args: argparse.Namespace) -> int:
    from rig.service import split_traces, tune
    from rig.service.tune import check_scorable, read_in_time_order

    traces, repaired = read_in_time_order(args.trace, args.repair)
    held_out, repaired_held_out = read_in_time_order(args.held_out or [], args.repair)
    train, validation = split_traces(traces, held_out, args.split)
    check_scorable([*train, *validation], args.horizon_ms / 1e3)
    name, start = args.predictor
    say = (lambda line: print(line, file=sys.stderr)) if args.json else print
    for note in repaired + repaired_held_out:
        say(f"repaired {note}")
    say(f"tuning {name} at {args.horizon_ms:g} ms on {sum(len(t) for t in train)} samples, validating on "
        f"{sum(len(t) for t in validation)} ...")
    report = tune(name, start, train, validation, args.horizon_ms / 1e3, args.max_iterations,
                  ProgressBar(f"tuning {name}"), repaired + repaired_held_out)
    fit = report.fit
    fitted = ", ".join(f"{k}={fit.params[k]:.6g}" for k in fit.fitted) or "nothing (no motion to fit)"
    say(f"fitted {fitted}; training loss {fit.loss_before:.4g} -> {fit.loss_after:.4g} in {fit.iterations} iterations")
    say(_table(report))
    say(f"validation error of the tuned parameters over the defaults': {report.validation_loss:.4f} (the tuning loss; below 1 is better)")
    writes = outputs.LateWrites()
    if report.beats_defaults or args.force:
        writes.write(args.out, lambda: report.write(args.out))
        if not writes.failed:
            say(f"wrote {args.out}" + ("" if report.beats_defaults else " (--force: they lose to the defaults on validation)"))
    else:
        say(f"not written: the tuned parameters predict the validation part worse than {name}'s defaults; "
            "keep the defaults, tune on more motion, or pass --force to write them anyway")
    written = (report.beats_defaults or args.force) and not writes.failed
    if args.json:
        print(json.dumps({**report.to_dict(), "out": str(args.out), "written": written}))
    writes.check()
    return 0 if written else EXIT_NOT_WRITTEN


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `tune`."""
    parser = subparsers.add_parser(
        "tune",
        description=__doc__.split("\n\n")[0],
        listings=choices.tunable_listing,
    )
    parser.add_argument("predictor", type=options.predictor_spec, metavar="PREDICTOR[:key=value,...]",
                        help="predictor to tune, with starting or fixed parameters (e.g. the tracker's noise)")
    parser.add_argument("--trace", type=Path, action="append", required=True, metavar="FILE",
                        help="trace CSV; repeat for several")
    parser.add_argument("--held-out", type=Path, action="append", metavar="FILE",
                        help="validation trace CSV; repeat for several (default: the end of each --trace)")
    add_declared_option(parser, TuneSettings, "split")
    add_declared_option(parser, TuneSettings, "horizon_ms", required=True)
    add_declared_option(parser, TuneSettings, "max_iterations")
    parser.add_argument("--out", type=outputs.json_file, required=True, metavar="FILE.json", help="parameter file to write")
    parser.add_argument("--force", action="store_true", help="write the parameters even if they lose to the defaults on validation")
    parser.add_argument("--repair", action="store_true",
                        help="sort a trace that is out of time order and drop repeated times, instead of refusing it")
    parser.add_argument("--json", action="store_true", help="print the report as one JSON object (the rest goes to stderr)")
    parser.set_defaults(func=_run)
