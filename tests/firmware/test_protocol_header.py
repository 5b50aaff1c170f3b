"""The Python parse of protocol.h (the firmware's header, as rig.board ships it) against what the C
compilers make of it: the same macros, values, struct sizes, field offsets, sizes and signedness."""

from __future__ import annotations

import re
import struct
import subprocess
from importlib import resources
from pathlib import Path
from typing import Iterator

import pytest

from rig.board.protocol import HEADER_FILE, protocol

NOT_VALUES = {"RIG_PROTOCOL_H", "RIG_PACKED"}


@pytest.fixture
def header_path() -> Iterator[Path]:
    """The header the Python side reads, as a file the compilers can include."""
    with resources.as_file(HEADER_FILE) as path:
        yield path


def compile_and_run(source: str, directory: Path, header_path: Path) -> str:
    (directory / "dump.c").write_text(source)
    subprocess.run(
        ["gcc", "-std=c11", "-Wall", "-Werror", "-I", str(header_path.parent), "-o", str(directory / "dump"), str(directory / "dump.c")],
        check=True,
        capture_output=True,
        text=True,
    )
    return subprocess.run([str(directory / "dump")], check=True, capture_output=True, text=True).stdout


def test_every_macro_of_the_header_is_read(host_compiler: str, header_path: Path) -> None:
    spec = protocol()
    listing = subprocess.run(
        [host_compiler, "-dM", "-E", "-x", "c", str(header_path)], check=True, capture_output=True, text=True
    ).stdout
    macros = set(re.findall(r"^#define (RIG_\w+)", listing, re.MULTILINE)) - NOT_VALUES
    assert macros == set(spec.constants) | set(spec.strings)


def test_values_and_layouts_agree_with_the_compiler(host_compiler: str, tmp_path: Path, header_path: Path) -> None:
    spec = protocol()
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "protocol.h"', "int main(void) {"]
    for name in spec.constants:
        lines.append(f'printf("value {name} %lld\\n", (long long)({name}));')
    for name in spec.strings:
        lines.append(f'printf("string {name} %s\\n", {name});')
    layouts = [layout for layout in spec.layouts.values() if layout.fields]
    for layout in layouts:
        t = layout.name
        lines.append(f'printf("size {t} %zu\\n", sizeof({t}));')
        for f, code in zip(layout.fields, re.findall(r"\d*[a-zA-Z]", layout.format[1:])):
            member = f"((({t} *)0)->{f})"
            signed = "0" if code.endswith("s") else f"(__typeof__({member}))-1 < 0"
            lines.append(f'printf("field {t}.{f} %zu %zu %d\\n", offsetof({t}, {f}), sizeof {member}, {signed});')
    lines.append("return 0; }")
    output = compile_and_run("\n".join(lines), tmp_path, header_path)
    compiled = dict(line.split(" ", 1)[1].split(" ", 1) for line in output.splitlines())

    for name, value in spec.constants.items():
        assert int(compiled[name]) == value, name
    for name, value in spec.strings.items():
        assert compiled[name] == value, name
    for layout in layouts:
        assert int(compiled[layout.name]) == layout.size, layout.name
        codes = re.findall(r"\d*[a-zA-Z]", layout.format[1:])
        for index, (f, code) in enumerate(zip(layout.fields, codes)):
            offset, size, signed = (int(v) for v in compiled[f"{layout.name}.{f}"].split())
            assert offset == struct.calcsize("<" + "".join(codes[:index])), f
            assert size == struct.calcsize("<" + code), f
            assert bool(signed) == (code.islower() and not code.endswith("s")), f


def test_the_avr_sees_the_same_layouts(avr_toolchain: None, tmp_path: Path, header_path: Path) -> None:
    spec = protocol()
    checks = [f'_Static_assert(sizeof({l.name}) == {l.size}, "{l.name}");' for l in spec.layouts.values() if l.fields]
    (tmp_path / "layouts.c").write_text('#include "protocol.h"\n' + "\n".join(checks) + "\n")
    result = subprocess.run(
        ["avr-gcc", "-mmcu=atmega328p", "-std=gnu11", "-c", "-I", str(header_path.parent), "-o", str(tmp_path / "layouts.o"), str(tmp_path / "layouts.c")],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
