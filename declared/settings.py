"""A setting declared once, on its dataclass field: its unit, range or choices, help, and the
command-line option that sets it (`setting`, `Setting`, `Flag`); `check` holds an instance to its
declarations, and `walk` lists a config's settings, nested configs included."""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from declared.ranges import Range

_KEY = "setting"


@dataclass(frozen=True)
class Flag:
    """The command-line option that sets a setting, where it says more than its name.

    unit, factor: the option's unit where it is not the setting's: option = setting x factor (1e3:
    a setting in seconds given in ms). per: the option is the setting x this sibling setting (an
    exposure in seconds given as a fraction of the frame interval: exposure x fps). range, default:
    the option's, where they are not the setting's own converted (None: they are; needed with
    `per`). help: the option's, where it is not the setting's. group: the title of the --help
    section it is listed in ("" for the command's main one).
    """

    name: str
    unit: str | None = None
    factor: float = 1.0
    per: str | None = None
    range: Range | None = None
    default: Any = None
    metavar: str | None = None
    help: str = ""
    group: str = ""


@dataclass(frozen=True)
class Setting:
    """What a setting means to a user.

    unit: as a message reads it ("seconds", "Hz"); "" for a pure number or a name.
    help: one line for --help and the docs tables.
    range: the numbers allowed (for a list, each item's). choices: the names allowed, or a function
    that lists them when asked (a registry that grows). rule: a check of the whole value, giving a
    sentence saying what is wrong or None ("LOW must be below HIGH").
    none: the word that sets None on the command line and in a spec ("measured").
    unset: what None does, where the default is None ("found in the video"), for --help and the docs.
    flag: the command-line option, if there is one.
    """

    unit: str
    help: str
    range: Range | None = None
    choices: tuple[str, ...] | Callable[[], tuple[str, ...]] | None = None
    rule: Callable[[Any], str | None] | None = None
    none: str = ""
    unset: str = ""
    flag: Flag | None = None

    def allowed(self) -> tuple[str, ...] | None:
        """The names allowed, if the setting is one of a list."""
        return self.choices() if callable(self.choices) else self.choices

    def problem(self, value: Any, whole: bool = False, range_: Range | None = None, unit: str | None = None) -> str | None:
        """What is wrong with a value that is not None ("must ..." or the rule's sentence), or None.
        `whole`: the setting holds whole numbers; `range_` and `unit` replace the setting's own (an
        option in another unit)."""
        range_, unit = range_ or self.range, self.unit if unit is None else unit
        items = value if isinstance(value, (tuple, list)) else (value,)
        if range_ is not None and not all(_is_number(item) and range_.contains(item) for item in items):
            allowed = range_.describe(unit).replace("number", "whole number" if whole else "number", 1)
            return f"must have each item {allowed}" if items is value else f"must be {allowed}"
        choices = self.allowed()
        if choices is not None and value not in choices:
            return f"must be one of {', '.join(choices)}"
        return self.rule(value) if self.rule is not None else None


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def setting(default: Any, unit: str, help: str, range: Range | None = None, *, flag: str | Flag | None = None,
            **declared: Any) -> Any:  # fmt: skip
    """A dataclass field with its `Setting` (`declared`: choices, rule, none, unset); `flag` the option's
    name, or a `Flag` where the option differs from the setting."""
    flag = Flag(flag) if isinstance(flag, str) else flag
    return dataclasses.field(default=default, metadata={_KEY: Setting(unit, help, range, flag=flag, **declared)})


def like(kind: type, name: str, *, default: Any = dataclasses.MISSING, **changes: Any) -> Any:
    """A field declared as the field `name` of the dataclass `kind` is, with its default (or
    `default`: None where the second place may leave it unsaid): the same setting held in a second
    place (`changes` to its `Setting`, such as a flag of its own)."""
    field = next(field for field in dataclasses.fields(kind) if field.name == name)
    declared = dataclasses.replace(setting_of(field), **changes)
    return dataclasses.field(default=field.default if default is dataclasses.MISSING else default, metadata={_KEY: declared})


def setting_of(field: dataclasses.Field) -> Setting | None:
    """A field's declaration, if it has one."""
    return field.metadata.get(_KEY)


@functools.cache
def hints(kind: type) -> dict[str, Any]:
    """The resolved type of each field of the dataclass `kind`."""
    return typing.get_type_hints(kind)


def optional(hint: Any) -> tuple[Any, bool]:
    """The type a field holds, and whether it may hold None too."""
    if typing.get_origin(hint) in (types.UnionType, typing.Union):
        inner = [arg for arg in typing.get_args(hint) if arg is not type(None)]
        return inner[0], len(inner) < len(typing.get_args(hint))
    return hint, False


def check(instance: Any, error: type[Exception], prefix: str = "") -> None:
    """`error` naming the first field of the dataclass `instance` whose value its setting does not
    allow: "{prefix}{name} must be {the range in words}, got {value!r}" (or the rule's sentence)."""
    for field in dataclasses.fields(instance):
        declared = setting_of(field)
        value = getattr(instance, field.name)
        if declared is None:
            continue
        if value is None:
            if optional(hints(type(instance))[field.name])[1]:
                continue
            problem: str | None = "must be given"
        else:
            problem = declared.problem(value, whole_numbers(hints(type(instance))[field.name]))
        if problem is not None:
            name = f"{prefix}{field.name}"
            raise error(f"{name} {problem}, got {value!r}" if problem.startswith("must") else f"{name}: {problem}, got {value!r}")


def whole_numbers(hint: Any) -> bool:
    """Whether a field of this type holds whole numbers (or a tuple of them)."""
    inner, _ = optional(hint)
    args = typing.get_args(inner) if typing.get_origin(inner) is tuple else (inner,)
    return bool(args) and all(arg is int or arg is Ellipsis for arg in args) and args[0] is int


@dataclass(frozen=True)
class Entry:
    """One setting of a config, nested ones included: its dotted path (the spec's key), type,
    declaration and default."""

    path: str
    hint: Any
    setting: Setting
    default: Any


def default_of(field: dataclasses.Field) -> Any:
    """A field's default value (None where it has none)."""
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return None if field.default is dataclasses.MISSING else field.default


def walk(kind: type, instance: Any = None, prefix: str = "") -> Iterator[Entry]:
    """Every declared setting of the dataclass `kind`, in field order, nested configs' included at
    their place (with the defaults `instance`, else the kind's, gives them)."""
    for field in dataclasses.fields(kind):
        hint, _ = optional(hints(kind)[field.name])
        value = getattr(instance, field.name) if instance is not None else default_of(field)
        declared = setting_of(field)
        if dataclasses.is_dataclass(hint):
            yield from walk(hint, value, f"{prefix}{field.name}.")
        elif declared is not None:
            yield Entry(f"{prefix}{field.name}", hint, declared, value)
