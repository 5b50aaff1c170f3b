"""Shared by the live-rig tests: a virtual X server for the tests that open windows.

Tests that need one skip where Xvfb is missing, except on CI (CI=true), where they fail: CI must
not pass by skipping them (`make test` installs it from tests/system-packages.txt).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from typing import Iterator

import pytest

SCREEN = "800x600x24"
START_TIMEOUT_S = 10.0


def require(condition: bool, what: str) -> None:
    """Skips the test when `what` is missing, or fails it on CI."""
    if condition:
        return
    message = f"{what} is missing: apt-get install $(cat tests/system-packages.txt)"
    if os.environ.get("CI") == "true":
        pytest.fail(message)
    pytest.skip(message)


@pytest.fixture(scope="session")
def x_server() -> Iterator[str]:
    """A virtual X server for the whole session; its DISPLAY name."""
    require(shutil.which("Xvfb") is not None, "Xvfb (Debian: xvfb)")
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", SCREEN, "-nolisten", "tcp"], pass_fds=(write,),
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    os.close(write)
    with os.fdopen(read) as stream:
        number = stream.readline().strip()
    if not number:
        server.kill()
        server.wait()
        pytest.fail("Xvfb did not start")
    yield f":{number}"
    server.terminate()
    server.wait(timeout=START_TIMEOUT_S)


@pytest.fixture
def x_display(x_server: str, monkeypatch: pytest.MonkeyPatch) -> str:
    """DISPLAY set to the virtual X server for this test (and the processes it starts)."""
    monkeypatch.setenv("DISPLAY", x_server)
    return x_server
