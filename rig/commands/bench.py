"""`rig bench SUBJECT`: the benchmarks of `rig.bench`, one command each, made from its `Command`
(`rig.bench.contract`), and the one runner that runs any of them: load its `Bench`, read its spec,
run it in its folder, write the outputs asked for, print its table, targets and notes. The help
imports no bench: each is loaded when it runs."""

from __future__ import annotations

import argparse
import importlib
import sys
import tempfile
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Any, Iterator

from rig.bench import SUBJECTS
from rig.bench.contract import Bench, Command, Context
from rig.cli import EXIT_USER_ERROR
from rig.commands import options, outputs

OUTPUT_TYPES = {"json": (outputs.json_file, "OUT.json"), "csv": (outputs.csv_file, "OUT.csv"), "plot": (outputs.plot_file, "OUT.png")}


@contextmanager
def _folder(runs: Path | None, name: str) -> Iterator[Path]:
    """Where a bench's runs go: `runs`, made if need be, or a temporary folder removed afterwards."""
    if runs is not None:
        runs.mkdir(parents=True, exist_ok=True)
        yield runs
        return
    with tempfile.TemporaryDirectory(prefix=f"rig-bench-{name}-") as scratch:
        yield Path(scratch)


def spec(subject: Command, args: argparse.Namespace) -> Any:
    """The spec of the bench the options chose (`subject`, or the mode named): the subject's spec
    file read where it has one (the quick one with --quick; the bench's `spec` sees it as
    `args.spec`), then the options over it."""
    if subject.spec_file is not None:
        path = subject.spec_file.quick if args.quick else args.spec
        read = subject.bench().read_spec
        assert read is not None, f"the bench {subject.name} declares a spec file but no reader"
        args = argparse.Namespace(**{**vars(args), "spec": read(path)})
    return args.mode.bench().spec(args)


def run(subject: Command, args: argparse.Namespace) -> int:
    """Run the bench the options chose, then write its outputs, print its table, targets and notes."""
    bench: Bench = args.mode.bench()
    chosen = spec(subject, args)
    executor = {"workers": args.workers, "scheduler": args.scheduler} if subject.executor else {}
    with _folder(args.runs if subject.runs else None, subject.name) as folder:
        rows = bench.run(chosen, Context(folder, **executor))
    writes = outputs.LateWrites()
    if getattr(args, "json", None) is not None:
        writes.json(args.json, bench.record(rows))
    if getattr(args, "plot", None) is not None and bench.plot is not None:
        writes.write(args.plot, partial(bench.plot, rows, args.plot))
    if getattr(args, "csv", None) is not None:
        writes.csv(args.csv, bench.record(rows))
    print(bench.table(rows))
    for target, met in (bench.targets(rows) if bench.targets else {}).items():
        print(f"{target}: {'met' if met else 'not met' if met is not None else 'n/a'}")
    if bench.notes is not None:
        print(bench.notes(rows))
    writes.check()
    failed = bench.all_failed(rows) if bench.all_failed is not None else None
    if failed is not None:
        print(f"rig bench {subject.name}: error: {failed}", file=sys.stderr)
        return EXIT_USER_ERROR
    return 0


def add_subject(
    benchmarks: argparse._SubParsersAction, subject: Command, modes: tuple[Command, ...] = (), description: str = ""
) -> None:
    """`rig bench SUBJECT`, described by `description`: its modes' flags, outputs, spec file, options
    (its modes' too), runs folder and executor."""
    files = subject.spec_file
    own = files.default if files is not None and files.default is not None else "its settings' defaults"
    where = f" Its spec: {own} (--quick: {files.quick.name}); --spec runs an edited copy." if files else ""
    parser = benchmarks.add_parser(subject.name, help=subject.help, description=description + where)
    if modes:
        chosen = parser.add_mutually_exclusive_group()
        for mode in modes:
            chosen.add_argument(f"--{mode.name}", dest="mode", action="store_const", const=mode, help=mode.help)
    for kind, text in subject.outputs.items():
        kind_type, metavar = OUTPUT_TYPES[kind]
        parser.add_argument(f"--{kind}", type=kind_type, metavar=metavar, help=text)
    if files is not None:
        either = parser.add_mutually_exclusive_group()
        either.add_argument("--spec", type=Path, default=files.default, metavar="SPEC.toml", help=files.help)
        either.add_argument("--quick", action="store_true", help=files.quick_help)
    for bench in (subject, *modes):
        bench.options(parser)
    if subject.runs is not None:
        parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR", help=subject.runs)
    if subject.executor is not None:
        options.add_executor_options(parser, subject.executor)
    parser.set_defaults(func=partial(run, subject), mode=subject)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "bench",
        description="Benchmarks are commands, not tests: each prints a table and writes JSON and a PNG.",
    )
    benchmarks = parser.add_subparsers(dest="bench", required=True, metavar="SUBJECT")
    for module in SUBJECTS:
        declared = importlib.import_module(f"rig.bench.{module}")
        add_subject(benchmarks, declared.SUBJECT, getattr(declared, "MODES", ()), declared.__doc__.split("\n\n")[0])
