"""Shared by the bad-input matrices: `rig` run in this process as a user would, and what a folder
held."""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Callable

import pytest

from rig.cli import EXIT_USER_ERROR, main

RigRun = Callable[[list[str], pytest.CaptureFixture[str]], tuple[int, str, str]]
Snapshot = Callable[[Path], dict[Path, str]]


def _run_rig(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def _snapshot(folder: Path) -> dict[Path, str]:
    return {path: hashlib.sha256(path.read_bytes()).hexdigest() for path in sorted(folder.rglob("*")) if path.is_file()}


def _assert_one_line_error(code: int, err: str, *words: str) -> None:
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert code == EXIT_USER_ERROR, err
    for word in words:
        assert word in lines[0], lines[0]
    assert "np.float64" not in lines[0] and "Config." not in lines[0]


@pytest.fixture
def assert_one_line_error() -> Callable[..., None]:
    """Checks a user error: exit status 2, one line on stderr holding each word, no traceback and
    no Python value's representation."""
    return _assert_one_line_error


@pytest.fixture
def run_rig() -> RigRun:
    """`rig ARGV` through `rig.cli.main`: its exit status (argparse's too), stdout and stderr."""
    return _run_rig


@pytest.fixture
def snapshot() -> Snapshot:
    """Every file under a folder with a digest of its bytes."""
    return _snapshot
