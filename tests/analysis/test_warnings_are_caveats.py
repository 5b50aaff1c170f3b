"""Every warning the analysis writes is made by `analysis.caveat`: one line of cause, one of remedy.
Checked in the source, so that a new warning cannot be plain text."""

from __future__ import annotations

import ast
from pathlib import Path

import analysis

PACKAGE = Path(analysis.__file__).parent


def _plain_warnings(tree: ast.AST) -> list[int]:
    """The lines where text is appended to a list of warnings, or passed to `note` as its warning,
    without `caveat`."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        target = node.func.value
        named = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if node.func.attr == "append" and named.endswith("warnings"):
            given = node.args[0]
        elif node.func.attr == "note" and len(node.args) == 5:
            given = node.args[4]
        else:
            continue
        if isinstance(given, (ast.Constant, ast.JoinedStr, ast.BinOp)):
            found.append(node.lineno)
    return found


def test_no_warning_is_plain_text() -> None:
    plain = {
        str(path.relative_to(PACKAGE)): lines
        for path in sorted(PACKAGE.rglob("*.py"))
        if (lines := _plain_warnings(ast.parse(path.read_text(encoding="utf-8"))))
    }
    assert plain == {}
