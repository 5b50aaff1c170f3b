"""The docs' tables of options and settings (docs/options.md) are made from the declarations: the
file is current, and it lists every declared setting with its option, unit and default."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest

from declared import walk
from rig.option_tables import SECTIONS, options_markdown

DOCS = Path(__file__).parents[2] / "docs" / "options.md"


def test_the_docs_table_is_current() -> None:
    assert DOCS.read_text(encoding="utf-8") == options_markdown(), "run: python -m rig.option_tables > docs/options.md"


def _as_toml(value: Any) -> Any:
    return [_as_toml(item) for item in value] if isinstance(value, tuple) else value


@pytest.mark.parametrize(("kind", "options"), [(kind, options) for _, kind, options, _ in SECTIONS], ids=lambda v: getattr(v, "__name__", ""))
def test_every_declared_setting_is_a_row_with_its_option_unit_and_default(kind: type, options: bool) -> None:
    section = options_markdown().split(f".{kind.__name__}`)")[1].split("\n## ")[0]
    rows = {cells[0]: cells for cells in (line.strip("| ").split(" | ") for line in section.splitlines() if line.startswith("| `"))}
    entries = list(walk(kind))
    assert entries and len(rows) == len(entries)
    for entry in entries:
        _, option, unit, default, _, about = rows[f"`{entry.path}`"]
        flag = entry.setting.flag if options else None
        assert option.startswith(f"`{flag.name}`") if flag is not None else option == ""
        assert unit == entry.setting.unit and about
        if entry.default is None:
            assert default.startswith("none")
        else:
            assert tomllib.loads(f"value = {default.strip('`')}")["value"] == _as_toml(entry.default), entry.path
