"""The firmware built with the AVR toolchain, and the emulated board running it (given to tests as
fixtures).

Tests that need the toolchain or simavr skip when it is missing, except on CI (CI=true), where
they fail: CI must not pass by skipping them. `ScriptedWorld` is the pendulum and display the
harness (firmware/sim/rig_board_sim.c) plays, as its header documents them, so tests can compare
the board's reports with the truth; `world` is the one the boards here are started with.
"""

from __future__ import annotations

import math
import os
import queue
import shutil
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
import pytest

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
BUILD = FIRMWARE / "build"
SIMAVR_HEADER = Path("/usr/include/simavr/sim_avr.h")
BUILD_TIMEOUT_S = 300
START_TIMEOUT_S = 20.0
STOP_TIMEOUT_S = 10.0


def require(condition: bool, what: str) -> None:
    """Skips the test when `what` is missing, or fails it on CI."""
    if condition:
        return
    message = f"{what} is missing: apt-get install $(cat firmware/system-packages.txt)"
    if os.environ.get("CI") == "true":
        pytest.fail(message)
    pytest.skip(message)


@pytest.fixture(scope="session")
def host_compiler() -> str:
    require(shutil.which("gcc") is not None and shutil.which("make") is not None, "the host C compiler (gcc, make)")
    return "gcc"


@pytest.fixture(scope="session")
def avr_toolchain(host_compiler: str) -> None:
    require(all(shutil.which(tool) for tool in ("avr-gcc", "avr-objcopy", "avr-size")), "the AVR toolchain (gcc-avr, avr-libc)")


@pytest.fixture(scope="session")
def simavr(avr_toolchain: None) -> None:
    require(SIMAVR_HEADER.exists(), "simavr (libsimavr-dev)")


def make(*targets: str) -> subprocess.CompletedProcess[str]:
    result = subprocess.run(
        ["make", "-C", str(FIRMWARE), *targets], capture_output=True, text=True, timeout=BUILD_TIMEOUT_S
    )
    if result.returncode != 0:
        pytest.fail(f"make -C firmware {' '.join(targets)} failed:\n{result.stdout}\n{result.stderr}")
    return result


@pytest.fixture(scope="session")
def make_firmware() -> Callable[..., subprocess.CompletedProcess[str]]:
    """make_firmware(*targets) runs `make -C firmware TARGETS`; fails the test if make does."""
    return make


@pytest.fixture(scope="session")
def emulator_build(simavr: None) -> Path:
    """Builds the firmware and the emulated board; returns the emulator's path."""
    make("all", "sim")
    return BUILD / "rig_board_sim"


@dataclass(frozen=True)
class ScriptedWorld:
    """The pendulum and display the harness plays (its defaults unless given)."""

    amplitude: float = 0.3
    period: float = 1.25
    phase: float = 0.0
    counts_per_rev: int = 2400
    display_delay: float = 0.0125
    photodiode_angle: float = 0.02
    spot_width: float = 0.02
    dark_mv: float = 250.0
    bright_mv: float = 4000.0
    adc_noise_mv: float = 5.0
    seed: int = 1

    def arguments(self) -> list[str]:
        return [
            f"--amplitude={self.amplitude}",
            f"--period={self.period}",
            f"--phase={self.phase}",
            f"--counts-per-rev={self.counts_per_rev}",
            f"--display-delay={self.display_delay}",
            f"--photodiode-angle={self.photodiode_angle}",
            f"--spot-width={self.spot_width}",
            f"--dark-mv={self.dark_mv}",
            f"--bright-mv={self.bright_mv}",
            f"--adc-noise-mv={self.adc_noise_mv}",
            f"--seed={self.seed}",
        ]

    def angle(self, t: np.ndarray) -> np.ndarray:
        return self.amplitude * np.cos(2 * math.pi * np.asarray(t) / self.period + self.phase)

    def count(self, t: np.ndarray) -> np.ndarray:
        """The encoder count the harness drives at time t (s from reset)."""
        return np.floor(self.angle(t) * self.counts_per_rev / (2 * math.pi) + 0.5).astype(np.int64)

    def adc_counts(self, t: np.ndarray) -> np.ndarray:
        """The noise-free photodiode signal in ADC counts (5 V reference) at sample time t."""
        shown = self.angle(np.asarray(t) - self.display_delay)
        mv = self.dark_mv + (self.bright_mv - self.dark_mv) * np.exp(-0.5 * ((shown - self.photodiode_angle) / self.spot_width) ** 2)
        return mv * 1023 / 5000


class EmulatedBoard:
    """A running emulated board: its serial URL (a symlink that follows reconnections) and its
    output lines."""

    def __init__(self, executable: Path, world: ScriptedWorld, directory: Path, extra: list[str]) -> None:
        self.world = world
        self.url = str(directory / "board")
        self.led_log = directory / "led_pin.csv"
        command = [str(executable), f"--link={self.url}", f"--led-log={self.led_log}", "--duration=120", *world.arguments(), *extra]
        self.process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines: list[str] = []
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, name="emulated board output", daemon=True)
        self._reader.start()
        self.wait_for_line("rig-board-sim: pty ", START_TIMEOUT_S)

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._lines.put(line.rstrip("\n"))
        self._lines.put(None)

    def wait_for_line(self, prefix: str, timeout: float) -> str:
        """The next output line starting with `prefix` (earlier lines are kept in self.lines)."""
        deadline = time.monotonic() + timeout
        while (left := deadline - time.monotonic()) > 0:
            try:
                line = self._lines.get(timeout=left)
            except queue.Empty:
                break
            if line is None:
                pytest.fail(f"the emulated board exited ({self.process.wait()}):\n" + "\n".join(self.lines))
            self.lines.append(line)
            if line.startswith(prefix):
                return line
        pytest.fail(f"the emulated board printed no {prefix!r} within {timeout} s:\n" + "\n".join(self.lines))

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._reader.join(timeout=STOP_TIMEOUT_S)
        assert self.process.stdout is not None
        self.process.stdout.close()


@pytest.fixture(scope="session")
def world() -> ScriptedWorld:
    """A display 23.7 ms late, the photodiode at 0.05 rad, a little ADC noise."""
    return ScriptedWorld(display_delay=0.0237, photodiode_angle=0.05, adc_noise_mv=2.0, seed=7)


@pytest.fixture(scope="module")
def board(emulator_build: Path, world: ScriptedWorld, tmp_path_factory: pytest.TempPathFactory) -> Iterator[EmulatedBoard]:
    """An emulated board shared by the tests of a module."""
    emulated = EmulatedBoard(emulator_build, world, tmp_path_factory.mktemp("board"), [])
    yield emulated
    emulated.stop()


@pytest.fixture
def start_board(emulator_build: Path, world: ScriptedWorld, tmp_path: Path) -> Iterator[Callable[..., EmulatedBoard]]:
    """start_board(*extra_arguments) starts an emulated board of its own; stopped after the test."""
    boards: list[EmulatedBoard] = []

    def start(*extra: str) -> EmulatedBoard:
        directory = tmp_path / f"board{len(boards)}"
        directory.mkdir()
        boards.append(EmulatedBoard(emulator_build, world, directory, list(extra)))
        return boards[-1]

    yield start
    for emulated in boards:
        emulated.stop()


