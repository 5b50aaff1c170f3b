"""The bench runner (`rig.commands.bench`) on toy benches: what it reads, runs, writes and prints
for any bench that keeps the contract (`rig.bench.contract`), and the subjects it registers."""

from __future__ import annotations

import argparse
import csv
import importlib
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from rig.bench import SUBJECTS
from rig.bench.contract import Bench, Command, Context, SpecFile, every_one
from rig.commands import bench as runner
from rig.errors import RigError


def _count(spec: int, context: Context) -> dict[str, Any]:
    (context.folder / "made.txt").write_text("a run's file")
    return {"rows": [{"n": k, "square": k * k} for k in range(spec)], "folder": str(context.folder)}


def _plot(report: dict[str, Any], path: Path) -> None:
    path.write_text(f"plot of {len(report['rows'])} rows")


def _size(text: str) -> int:
    return int(text.split("=")[1])


COUNT = Bench(
    spec=lambda args: args.spec + args.extra,
    read_spec=lambda path: _size(path.read_text()),
    run=_count,
    table=lambda report: f"{len(report['rows'])} rows",
    record=lambda report: report["rows"],
    plot=_plot,
    targets=lambda report: {"enough rows": len(report["rows"]) >= 3, "few rows": len(report["rows"]) < 3, "speed": None},
    notes=lambda report: "noted last",
)
TOY = Command(
    name="toy",
    help="counts",
    bench=lambda: COUNT,
    options=lambda parser: parser.add_argument("--extra", type=int, default=0),
    outputs={"json": "the rows", "csv": "the rows", "plot": "a picture"},
    runs="keep the runs here",
)


def _toy(**changes: Any) -> Command:
    """TOY running COUNT with `changes`."""
    bench = replace(COUNT, **changes)
    return replace(TOY, bench=lambda: bench)


DEPTH = Bench(spec=lambda args: args.depth, run=lambda depth, context: [{"depth": depth}], table=lambda rows: f"deep {rows[0]['depth']}")
DEEP = Command(
    name="deep",
    help="counts deeper",
    bench=lambda: DEPTH,
    options=lambda parser: parser.add_argument("--depth", type=int, default=7),
)


def _parse(subject: Command, *argv: str, modes: tuple[Command, ...] = ()) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="rig bench")
    runner.add_subject(parser.add_subparsers(dest="bench"), subject, modes)
    return parser.parse_args([subject.name, *argv])


def _spec_file(tmp_path: Path) -> SpecFile:
    (tmp_path / "own.txt").write_text("size=4")
    (tmp_path / "quick.txt").write_text("size=2")
    return SpecFile(tmp_path / "own.txt", tmp_path / "quick.txt", "the size", "a small size")


def test_the_runner_writes_every_output_asked_for_and_prints_table_targets_and_notes_in_order(tmp_path, capsys):
    toy = _toy(spec=lambda args: 4)
    args = _parse(toy, "--json", str(tmp_path / "rows.json"), "--csv", str(tmp_path / "rows.csv"), "--plot", str(tmp_path / "rows.png"))
    assert args.func(args) == 0
    rows = [{"n": k, "square": k * k} for k in range(4)]
    assert json.loads((tmp_path / "rows.json").read_text()) == rows
    with (tmp_path / "rows.csv").open() as stream:
        assert list(csv.DictReader(stream)) == [{"n": str(r["n"]), "square": str(r["square"])} for r in rows]
    assert (tmp_path / "rows.png").read_text() == "plot of 4 rows"
    assert capsys.readouterr().out == "4 rows\nenough rows: met\nfew rows: not met\nspeed: n/a\nnoted last\n"


def test_the_spec_file_is_read_once_the_quick_one_with_quick_and_the_options_go_over_it(tmp_path):
    toy = replace(TOY, spec_file=_spec_file(tmp_path))
    (tmp_path / "mine.txt").write_text("size=9")
    assert runner.spec(toy, _parse(toy)) == 4
    assert runner.spec(toy, _parse(toy, "--quick", "--extra", "1")) == 3
    assert runner.spec(toy, _parse(toy, "--spec", str(tmp_path / "mine.txt"))) == 9
    with pytest.raises(SystemExit):
        _parse(toy, "--quick", "--spec", str(tmp_path / "mine.txt"))


def test_runs_go_in_the_runs_folder_or_a_temporary_one_removed_afterwards(tmp_path, capsys):
    toy = _toy(spec=lambda args: 1)
    args = _parse(toy, "--runs", str(tmp_path / "kept" / "here"), "--json", str(tmp_path / "kept.json"))
    assert args.func(args) == 0
    assert (tmp_path / "kept" / "here" / "made.txt").read_text() == "a run's file"
    toy = _toy(spec=lambda args: 1, record=lambda report: {"folder": report["folder"]})
    args = _parse(toy, "--json", str(tmp_path / "report.json"))
    assert args.func(args) == 0
    folder = Path(json.loads((tmp_path / "report.json").read_text())["folder"])
    assert folder.name.startswith("rig-bench-toy-") and not folder.exists()


def test_a_mode_runs_on_its_flag_with_its_own_options_and_the_subjects_outputs(tmp_path, capsys):
    toy = replace(TOY, spec_file=_spec_file(tmp_path))
    args = _parse(toy, "--deep", "--depth", "3", "--json", str(tmp_path / "deep.json"), modes=(DEEP,))
    assert args.mode is DEEP and args.func(args) == 0
    assert json.loads((tmp_path / "deep.json").read_text()) == [{"depth": 3}]
    assert capsys.readouterr().out == "deep 3\n"
    assert _parse(toy, modes=(DEEP,)).mode is toy


def test_a_failed_write_keeps_the_others_and_the_table_then_is_one_error(tmp_path, capsys):
    def unwritable(report: dict[str, Any], path: Path) -> None:
        raise OSError(28, "No space left on device")

    toy = _toy(spec=lambda args: 2, plot=unwritable)
    args = _parse(toy, "--json", str(tmp_path / "rows.json"), "--plot", str(tmp_path / "rows.png"))
    with pytest.raises(RigError, match=r"cannot write .*rows.png \(No space left on device\); the result above stands"):
        args.func(args)
    assert len(json.loads((tmp_path / "rows.json").read_text())) == 2
    assert capsys.readouterr().out.startswith("2 rows\n")


def test_every_registered_subject_and_mode_is_a_command():
    parser = argparse.ArgumentParser(prog="rig")
    runner.add_parser(parser.add_subparsers(dest="command"))
    subjects = []
    for module in SUBJECTS:
        declared = importlib.import_module(f"rig.bench.{module}")
        subjects.append(declared.SUBJECT.name)
        assert parser.parse_args(["bench", declared.SUBJECT.name]).mode is declared.SUBJECT
        for mode in getattr(declared, "MODES", ()):
            assert parser.parse_args(["bench", declared.SUBJECT.name, f"--{mode.name}"]).mode is mode
    assert subjects == ["analyser", "predictors", "renderers", "trackers", "batch", "live", "camera-calibration"]
    with pytest.raises(SystemExit):
        parser.parse_args(["bench", "renderers", "--seed-table", "--variants"])


@pytest.mark.parametrize("module", SUBJECTS)
def test_every_subject_and_mode_loads_a_bench_that_keeps_the_contract(module: str):
    declared = importlib.import_module(f"rig.bench.{module}")
    for command in (declared.SUBJECT, *getattr(declared, "MODES", ())):
        assert isinstance(command.bench(), Bench)
    assert (declared.SUBJECT.bench().read_spec is not None) == (declared.SUBJECT.spec_file is not None)


def test_every_one_says_so_only_where_every_item_has_a_reason():
    refused = [{"refused": "too dark"}, {"refused": "no swing"}]
    assert every_one(refused, "refused", "refused every one of the {count} films") == "refused every one of the 2 films (the first: too dark)"
    assert every_one([*refused, {"refused": None}], "refused", "{count}") is None
    assert every_one([], "refused", "{count}") is None
