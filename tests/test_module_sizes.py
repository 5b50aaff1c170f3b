"""No module of the project's packages is over 400 lines: past that a module holds more than one
thing, and the next reader should find each thing by its module's name."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 400


@pytest.mark.parametrize("package", ["rig", "predictors", "analysis", "declared"])
def test_no_module_is_over_400_lines(package: str) -> None:
    lengths = {path: len(path.read_text(encoding="utf-8").splitlines()) for path in (ROOT / package).rglob("*.py")}
    assert lengths, f"no modules found under {package}/"
    long = {str(path.relative_to(ROOT)): n for path, n in lengths.items() if n > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"
