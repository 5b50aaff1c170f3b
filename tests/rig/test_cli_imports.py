"""What the command line loads before it runs anything: `rig --help` lists the commands without
importing any of them, and `rig COMMAND --help` builds that command's parser from light
declarations alone (the heavy libraries and the analysis load only when the command runs).
Checked in a fresh interpreter, by what lands in sys.modules."""

from __future__ import annotations

import importlib
import importlib.util
import json
import subprocess
import sys

import pytest

from rig.bench import SUBJECTS
from rig.cli import COMMANDS, build_parser, command_module, main

HEAVY = ("numpy", "cv2", "jax", "scipy", "matplotlib", "moderngl", "OpenGL", "pylsl", "serial", "dask")
"""Libraries whose import alone costs a tenth of a second or more."""
ANALYSIS_INTERNALS = ("analysis.pipeline", "analysis.estimation", "analysis.tracks", "analysis.blobs")


def _loaded(argv: list[str], shown: bool = False) -> set[str]:
    """The modules a fresh interpreter holds after importing rig.cli and building the parser for
    argv; `shown`: after printing argv's --help too."""
    code = (
        "import contextlib, io, json, sys\n"
        "import rig.cli\n"
        f"parser = rig.cli.build_parser({argv!r})\n"
        + (f"with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n    parser.parse_args({[*argv, '--help']!r})\n" if shown else "")
        + "print(json.dumps(sorted(sys.modules)))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    return set(json.loads(done.stdout))


def _heavy(modules: set[str]) -> list[str]:
    return sorted(name for name in modules if name.split(".")[0] in HEAVY or name in ANALYSIS_INTERNALS)


def test_listing_the_commands_imports_none_of_them() -> None:
    modules = _loaded([])
    assert not [name for name in modules if name.startswith("rig.commands")]
    assert _heavy(modules) == []
    assert "importlib.metadata" not in modules


@pytest.mark.parametrize("command", COMMANDS)
def test_a_commands_parser_loads_no_heavy_library(command: str) -> None:
    assert _heavy(_loaded([command])) == []


@pytest.mark.parametrize("subject", [importlib.import_module(f"rig.bench.{module}").SUBJECT.name for module in SUBJECTS])
def test_a_benchs_help_loads_no_heavy_library(subject: str) -> None:
    modules = _loaded(["bench", subject], shown=True)
    assert _heavy(modules) == []
    assert not [name for name in modules if name.startswith("predictors")]


def test_every_command_has_a_module_and_a_one_line_summary() -> None:
    assert all(importlib.util.find_spec(command_module(name)) is not None for name in COMMANDS)
    assert all(len(summary) < 120 and "\n" not in summary for summary in COMMANDS.values())


def test_the_listing_shows_each_summary() -> None:
    listing = " ".join(build_parser([]).format_help().split())
    for name, summary in COMMANDS.items():
        assert f"{name} {summary.split()[0]}" in listing


def test_version_is_the_installed_packages(capsys: pytest.CaptureFixture[str]) -> None:
    from importlib import metadata

    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == f"rig {metadata.version('latency-rig')}\n"
