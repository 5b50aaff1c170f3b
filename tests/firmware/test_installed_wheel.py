"""`rig board` from an installed wheel, away from the checkout: the wheel must carry the board's
protocol header (rig/board/protocol.h, a link to firmware/include/protocol.h in the checkout), or
the rig cannot speak to a board. The wheel is built from a copy of the checkout's source files,
installed into a fresh virtual environment with its dependencies pinned by constraints.txt, and
that environment's `rig board info` talks to the emulated board from a folder outside the checkout.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from rig.board.protocol import protocol

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE_HEADER = ROOT / "firmware" / "include" / "protocol.h"
BUILD_TIMEOUT_S = 600
INSTALL_TIMEOUT_S = 1800
COMMAND_TIMEOUT_S = 120


def run(command: list[str], cwd: Path, timeout: float) -> subprocess.CompletedProcess[str]:
    """Runs a command with no trace of this checkout's environment; fails the test if it fails."""
    env = {name: value for name, value in os.environ.items() if name not in ("PYTHONPATH", "VIRTUAL_ENV")}
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    if result.returncode != 0:
        pytest.fail(f"{' '.join(command)} failed ({result.returncode}):\n{result.stdout}\n{result.stderr}")
    return result


def copy_source(destination: Path) -> Path:
    """The checkout's source files (tracked, or new and not ignored), links kept as links: what a
    fresh clone holds, without build outputs or virtual environments."""
    listing = run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], ROOT, 60).stdout
    for name in filter(None, listing.split("\0")):
        source = ROOT / name
        if not source.is_symlink() and not source.exists():
            continue  # deleted in the working tree
        target = destination / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target, follow_symlinks=False)
    return destination


@pytest.mark.slow
def test_rig_board_info_from_an_installed_wheel(host_compiler: str, start_board, tmp_path: Path) -> None:
    source = copy_source(tmp_path / "source")
    assert (source / "rig" / "board" / "protocol.h").is_symlink()
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--wheel-dir", str(tmp_path / "dist"), str(source)], tmp_path, BUILD_TIMEOUT_S)
    (wheel,) = (tmp_path / "dist").glob("latency_rig-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        assert archive.read("rig/board/protocol.h") == FIRMWARE_HEADER.read_bytes()

    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", str(venv)], tmp_path, COMMAND_TIMEOUT_S)
    python = venv / "bin" / "python"
    run([str(python), "-m", "pip", "install", "--constraint", str(ROOT / "constraints.txt"), str(wheel)], tmp_path, INSTALL_TIMEOUT_S)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    located = run([str(python), "-c", "import rig.board.protocol as p; print(p.HEADER_FILE)"], outside, COMMAND_TIMEOUT_S).stdout.strip()
    assert Path(located).is_relative_to(venv) and not Path(located).is_symlink()

    board = start_board()
    output = run([str(venv / "bin" / "rig"), "board", "info", "--port", board.url, "--json"], outside, COMMAND_TIMEOUT_S).stdout
    report = json.loads(output)
    spec = protocol()
    assert report["identity"] == {
        "name": spec.strings["RIG_BOARD_NAME"],
        "protocol": spec["RIG_PROTOCOL_VERSION"],
        "firmware": f"{spec['RIG_FIRMWARE_VERSION_MAJOR']}.{spec['RIG_FIRMWARE_VERSION_MINOR']}.{spec['RIG_FIRMWARE_VERSION_PATCH']}",
        "tick_hz": spec["RIG_TICK_HZ"],
        "cpu_hz": 16_000_000,
    }
    assert report["status"]["board_time"] > 0
