"""A config's settings as a Markdown table, for the docs: every setting (nested configs' by their
dotted key, as a spec writes them) with its command-line option, unit, default, what it allows and
what it does, all from the declarations."""

from __future__ import annotations

import typing
from typing import Any

from declared.settings import Entry, whole_numbers, walk

COLUMNS = ("setting", "option", "unit", "default", "allowed", "what it is")


def markdown_table(kind: type, options: bool = True) -> str:
    """The settings of the dataclass `kind` as a Markdown table, one row each (see COLUMNS); the
    option column empty unless `options` (a command's options are made from `kind`)."""
    rows = [COLUMNS, ("---",) * len(COLUMNS), *(row(entry, options) for entry in walk(kind))]
    return "\n".join("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |" for cells in rows) + "\n"


def row(entry: Entry, options: bool = True) -> tuple[str, ...]:
    """One setting's cells."""
    setting, flag = entry.setting, entry.setting.flag if options else None
    option = ""
    if flag is not None:
        unit = f" ({flag.unit or 'no unit'})" if flag.unit is not None and flag.unit != setting.unit else ""
        option = f"`{flag.name}`{unit}"
    default = f"none ({setting.unset})" if entry.default is None and setting.unset else f"`{_text(entry.default)}`"
    return (f"`{entry.path}`", option, setting.unit, default, _allowed(entry), (flag.help if flag and flag.help else setting.help))


def _allowed(entry: Entry) -> str:
    setting = entry.setting
    words = []
    if setting.range is not None:
        allowed = setting.range.describe(setting.unit).replace("number", "whole number" if whole_numbers(entry.hint) else "number", 1)
        words.append(f"each item {allowed}" if typing.get_origin(entry.hint) is tuple else allowed)
    if setting.allowed() is not None:
        words.append("one of " + ", ".join(f"`{name}`" for name in setting.allowed()))
    if setting.rule is not None and setting.rule.__doc__:
        words.append(setting.rule.__doc__.strip().rstrip("."))
    if setting.none:
        words.append(f'or `"{setting.none}"`')
    return "; ".join(words)


def _text(value: Any) -> str:
    """A default as a spec writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple):
        return "[" + ", ".join(_text(item) for item in value) + "]"
    if isinstance(value, str):
        return f'"{value}"'
    return "none" if value is None else repr(value)
