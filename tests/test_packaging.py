"""What a wheel of the project holds, checked without building one (`tests/firmware/test_installed_wheel.py`
builds and installs one, marked slow): every package the code imports is one the build includes."""

from __future__ import annotations

import ast
import fnmatch
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _included(package: str) -> bool:
    patterns = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]["find"]["include"]
    return any(fnmatch.fnmatch(package, pattern) for pattern in patterns)


def _project_packages() -> set[str]:
    return {path.parent.name for path in ROOT.glob("*/__init__.py")}


def test_every_project_package_a_module_imports_is_built_into_the_wheel() -> None:
    packages = _project_packages()
    imported = set()
    for package in packages & {"rig", "analysis", "predictors", "declared"}:
        for path in (ROOT / package).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    imported.update(alias.name.split(".")[0] for alias in node.names)
                elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                    imported.add(node.module.split(".")[0])
    needed = imported & packages
    assert {"rig", "analysis", "predictors", "declared"} <= needed
    assert [package for package in sorted(needed) if not _included(package)] == []


def test_a_package_left_out_of_the_build_is_found() -> None:
    assert not _included("tests") and not _included("notebooks")
