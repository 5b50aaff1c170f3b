"""A package that exports its names lazily (`declared.lazy`) also imports them under TYPE_CHECKING,
for the API reference and type checkers: the two lists must stay the same names from the same modules."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path
from types import ModuleType

import pytest


def _typed_imports(package: ModuleType) -> dict[str, str]:
    tree = ast.parse(Path(package.__file__).read_text(encoding="utf-8"))
    guarded = [node for node in tree.body if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING"]
    return {
        alias.asname or alias.name: statement.module
        for node in guarded
        for statement in node.body
        if isinstance(statement, ast.ImportFrom)
        for alias in statement.names
    }


@pytest.mark.parametrize("name", ["analysis", "predictors"])
def test_the_names_documentation_reads_are_the_names_the_package_exports(name: str) -> None:
    package = importlib.import_module(name)
    typed = _typed_imports(package)
    exported = {export for export in dir(package) if not isinstance(getattr(package, export), ModuleType)}
    assert set(typed) == exported
    for export, module in typed.items():
        assert getattr(package, export) is getattr(importlib.import_module(module), export), export
