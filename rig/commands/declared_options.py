"""Command-line options made from declared settings (`declared`): every setting of a config with a
`Flag` becomes an option, typed, checked against its range or choices when the command line is read
(one line naming the option, exit status 2), its help with the unit and the default; and the values
given become the config again (`config_from_args`), converted back to the setting's unit."""

from __future__ import annotations

import argparse
import typing
from typing import Any, Callable, TypeVar

from declared import Entry, Flag, from_table, walk
from declared.settings import whole_numbers

Config = TypeVar("Config")


def add_declared_options(parser: argparse.ArgumentParser, kind: type, groups: dict[str, str] | None = None) -> dict[str, Any]:
    """An option for each setting of `kind` with a flag (nested configs' included), in declaration
    order; a flag's group is a section titled as `groups` says (a group not named there is left out:
    its options are not this command's). The sections by title, for options of the command's own."""
    groups = {"": "", **(groups or {})}
    sections = {title: parser.add_argument_group(title) if title else parser for title in groups.values()}
    for entry in walk(kind):
        flag = entry.setting.flag
        if flag is not None and flag.group in groups:
            sections[groups[flag.group]].add_argument(flag.name, dest=_dest(entry), **_argument(entry))
    return sections


def add_declared_option(parser: argparse.ArgumentParser, kind: type, path: str, required: bool = False) -> None:
    """The option of the setting `path` (dotted) of `kind` alone, as `add_declared_options` makes it
    (`required`: with no default): a command that takes one setting of a config, checked against
    the same range."""
    entry = next(entry for entry in walk(kind) if entry.path == path)
    argument = _argument(entry)
    if required:
        argument |= {"required": True, "default": None, "help": argument["help"].rpartition(" (")[0] + f" ({entry.setting.unit})"}
    parser.add_argument(entry.setting.flag.name, dest=_dest(entry), **argument)


def declared_type(kind: type, path: str) -> Callable[[str], Any]:
    """The type of an option for the setting `path` (dotted) of `kind`, as `add_declared_options`
    makes it: for an option a command adds itself (one of alternatives, or whose absence means
    something of its own), read and checked against the setting's range."""
    return _parser(next(entry for entry in walk(kind) if entry.path == path))


def config_from_args(kind: type[Config], args: argparse.Namespace, error: type[Exception], **given: Any) -> Config:
    """The `kind` the options given make (every setting without an option at its default, and the
    fields in `given` as given, their options' values, nested ones' included, left aside), each
    value in its setting's unit; `error` is what `kind` raises for a value it does not allow."""
    table: dict[str, Any] = dict(given)
    per: list[tuple[Entry, Any]] = []
    for entry in walk(kind):
        flag = entry.setting.flag
        if flag is None or not hasattr(args, _dest(entry)) or entry.path.partition(".")[0] in given:
            continue
        value = getattr(args, _dest(entry))
        if flag.per is not None and value is not None:
            per.append((entry, value))
            continue
        _put(table, entry.path, value / flag.factor if flag.factor != 1.0 and value is not None else value)
    for entry, value in per:
        parent = entry.path.rpartition(".")[0]
        sibling = _get(table, f"{parent}.{entry.setting.flag.per}" if parent else entry.setting.flag.per)
        _put(table, entry.path, value / sibling)
    return from_table(kind, table, error)


def _dest(entry: Entry) -> str:
    return entry.setting.flag.name.removeprefix("--").replace("-", "_")


def _put(table: dict[str, Any], path: str, value: Any) -> None:
    *parents, name = path.split(".")
    for parent in parents:
        table = table.setdefault(parent, {})
    table[name] = value


def _get(table: dict[str, Any], path: str) -> Any:
    for name in path.split("."):
        table = table[name]
    return table


def _argument(entry: Entry) -> dict[str, Any]:
    """argparse's keywords for the entry's option: its help ends with its unit and default."""
    setting, flag = entry.setting, entry.setting.flag
    default = flag.default if flag.default is not None else _converted(entry.default, flag.factor)
    unit = flag.unit if flag.unit is not None else setting.unit
    shown = setting.unset if default is None else ",".join(f"{v:g}" for v in default) if isinstance(default, tuple) else str(default)
    about = "; ".join(part for part in (unit, f"default: {shown}" if shown and entry.hint is not bool else "") if part)
    text = flag.help or setting.help
    keywords: dict[str, Any] = {"help": (f"{text} ({about})" if about else text).replace("%", "%%")}
    if entry.hint is bool:
        return keywords | {"action": "store_true"}
    keywords |= {"default": default, "metavar": flag.metavar}
    choices = setting.allowed()
    return keywords | ({"choices": choices} if choices is not None else {"type": _parser(entry)})


def _converted(value: Any, factor: float) -> Any:
    return value * factor if factor != 1.0 and value is not None else value


def _parser(entry: Entry) -> Callable[[str], Any]:
    """Text to the option's value (a list is comma-separated), checked against the setting's range
    in the option's unit (the setting's own where it declares no option)."""
    setting, flag = entry.setting, entry.setting.flag or Flag("")
    kinds = typing.get_args(entry.hint) if typing.get_origin(entry.hint) is tuple else (entry.hint,)
    listed = len(kinds) > 1
    allowed = flag.range or (setting.range.scaled(flag.factor) if setting.range is not None else None)
    unit = flag.unit if flag.unit is not None else setting.unit
    expected = _expected(kinds, flag.metavar, setting.none)

    def parse(text: str) -> Any:
        if setting.none and text == setting.none:
            return None
        parts = text.split(",") if listed else [text]
        items = [kinds[0]] * len(parts) if kinds[-1] is Ellipsis else kinds
        try:
            if len(parts) != len(items):
                raise ValueError
            values = tuple((_whole if kind is int else kind)(part) for kind, part in zip(items, parts))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}") from None
        value = values if listed else values[0]
        problem = setting.problem(value, whole_numbers(entry.hint), allowed, unit)
        if problem is not None:
            raise argparse.ArgumentTypeError(f"{problem}, got {text}")
        return value

    return parse


def _whole(text: str) -> int:
    """A whole number, written as one or in exponent form ("1e6"); ValueError for anything else."""
    try:
        return int(text)
    except ValueError:
        value = float(text)
        if not value.is_integer():
            raise
        return int(value)


def _expected(kinds: tuple[Any, ...], metavar: str | None, none: str) -> str:
    noun = "whole number" if kinds[0] is int else "number" if kinds[0] is float else "value"
    count = "" if kinds[-1] is Ellipsis else f"{len(kinds)} "
    what = f"a {noun}" if len(kinds) == 1 else f"{metavar or 'values'}, {count}{noun}s"
    return f"{what} or '{none}'" if none else what
