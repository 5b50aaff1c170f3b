"""The bench contract: what a benchmark declares, and what `rig bench` does with every one alike.

A bench is declared twice over, so that `rig bench --help` loads nothing a bench runs on. Its
`Command`, in a light module registered in `rig.bench.SUBJECTS`, is what the command line shows:
the subject `rig bench` names it by, its help and description, options, outputs and spec file (a
grid written as TOML, or its options alone). Its `Bench`, in the module the command loads only
when the bench runs, is what it does: read its spec file, make its spec (the options over it),
measure (`run(spec, context) -> rows`), and turn its rows into the printed table, the targets met,
notes on what the figures carry, the JSON record, a plot and CSV. The runner (`rig.commands.bench`)
does the rest: the command line, the folder the runs go in (`--runs`, or a temporary one), the
run, the outputs asked for (`rig.commands.outputs.LateWrites`: a failed write loses neither the
others nor the table), the printing and the exit status.

A subject may have modes (`rig bench renderers --seed-table`): benches in modules of their own,
each chosen by a flag of its name, whose options join the subject's command line and which use
the subject's spec file, folder and outputs.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from rig.progress import ProgressBar

Log = Callable[[str], None]


def log_to_stderr(message: str) -> None:
    """A bench's running commentary: a line on stderr, at once."""
    print(message, file=sys.stderr, flush=True)


@dataclass(frozen=True)
class Context:
    """Where a bench runs: the folder its runs go in, its log and progress bars, and the executor
    its independent jobs go to (`rig.executor`; neither `workers` nor `scheduler`: serially, here)."""

    folder: Path
    log: Log = log_to_stderr
    progress: Callable[[str], Callable[[float, float], object]] = ProgressBar
    workers: int | None = None
    scheduler: str | None = None


@dataclass(frozen=True)
class SpecFile:
    """A spec written as TOML: the bench's own file, the small one --quick runs, and the help of
    --spec and --quick (its `Bench.read_spec` reads any of them, a user's copy too)."""

    default: Path | None
    """the bench's own file; None: its spec's declared defaults"""
    quick: Path
    help: str
    quick_help: str


@dataclass(frozen=True)
class Bench:
    """What one benchmark does (see the module docstring); its `Command` is what the command line
    shows of it."""

    run: Callable[[Any, Context], Any]
    table: Callable[[Any], str]
    """the rows as the text printed"""
    spec: Callable[[argparse.Namespace], Any] = lambda options: options
    """the parsed options (`spec` among them the spec read, where there is a SpecFile) -> the spec"""
    read_spec: Callable[[Path | None], Any] | None = None
    """reads a spec file checking every key, or (given None) makes the spec of the defaults; None:
    the bench has no SpecFile"""
    record: Callable[[Any], Any] = lambda rows: rows
    """the rows as JSON-ready values (a list of flat dicts where the bench writes CSV)"""
    plot: Callable[[Any, Path], None] | None = None
    targets: Callable[[Any], dict[str, bool | None]] | None = None
    """each target and whether this run met it (None: not measured)"""
    notes: Callable[[Any], str] | None = None
    """what else the figures carry (machine noise, time taken), printed last"""
    all_failed: Callable[[Any], str | None] | None = None
    """a sentence where every item the bench measured failed (its figures are of nothing), else
    None: `rig bench` then exits with status 2 once it has written and printed what it has"""


def bench_in(module: str) -> Callable[[], Bench]:
    """The loader of the `BENCH` of `rig.bench.MODULE`: the module is imported when the bench runs."""
    return lambda: importlib.import_module(f"rig.bench.{module}").BENCH


@dataclass(frozen=True)
class Command:
    """What the command line shows of one benchmark, declared without importing what it runs (a
    subject's description is its declaring module's first paragraph). The fields from `outputs` on
    are a subject's; a mode leaves them out and has its subject's."""

    name: str
    """the subject (`rig bench NAME`), or a mode's flag (`--NAME`)"""
    help: str
    bench: Callable[[], Bench]
    """loads the bench (`bench_in`)"""
    options: Callable[[argparse.ArgumentParser], object] = lambda parser: None
    """adds the bench's own options (a mode's join its subject's)"""
    outputs: dict[str, str] = field(default_factory=dict)
    """the help of each output it writes, by kind: json, plot, csv"""
    spec_file: SpecFile | None = None
    runs: str | None = None
    """the help of --runs (what it keeps there); None: no --runs, the runs are temporary"""
    executor: str | None = None
    """what runs on --workers or --scheduler; None: no such options"""


def every_one(items: list[dict[str, Any]], reason: str, sentence: str) -> str | None:
    """Where every one of `items` has a `reason` (not None: every case failed, or was refused), `sentence`
    (its {count}, how many) with the first one's; else None: `rig bench` then exits with status 2."""
    if not items or any(item[reason] is None for item in items):
        return None
    return f"{sentence.format(count=len(items))} (the first: {items[0][reason]})"


def new_figure(size: tuple[float, float], **subplots: Any) -> tuple[Any, Any]:
    """A matplotlib figure of `size` inches and its axes (`Figure.subplots(**subplots)`)."""
    from matplotlib.figure import Figure  # loaded where a bench plots, never by its help

    figure = Figure(figsize=size)
    return figure, figure.subplots(**subplots)


def cell(value: float | None, spec: str = ".1f") -> str:
    """A table's cell: the number formatted by `spec`, or "-" where there is none."""
    return "-" if value is None else format(value, spec)


def given(options: argparse.Namespace, *names: str) -> dict[str, Any]:
    """The options among `names` given on the command line (not None), by name: what overrides a spec."""
    return {name: getattr(options, name) for name in names if getattr(options, name) is not None}
