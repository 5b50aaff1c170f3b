"""The firmware builds for the ATmega328P within half of its flash and RAM, and its host-side unit
tests pass."""

from __future__ import annotations

import re
from pathlib import Path

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"


def test_firmware_builds_within_half_the_chip(avr_toolchain: None, make_firmware) -> None:
    output = make_firmware("all").stdout
    flash = re.search(r"flash: (\d+) of (\d+) bytes", output)
    ram = re.search(r"ram: +(\d+) of (\d+) bytes", output)
    assert flash and ram, output
    assert int(flash[2]) == 32768 // 2 and int(ram[2]) == 2048 // 2
    assert int(flash[1]) <= int(flash[2]) and int(ram[1]) <= int(ram[2])
    assert (FIRMWARE / "build" / "rig.hex").stat().st_size > 0


def test_host_unit_tests_of_the_firmware_pass(host_compiler: str, make_firmware) -> None:
    summary = re.search(r"^(\d+) passed, (\d+) failed$", make_firmware("test").stdout, re.MULTILINE)
    assert summary is not None
    passed, failed = int(summary[1]), int(summary[2])
    assert failed == 0 and passed >= 30
