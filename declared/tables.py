"""A config dataclass from a table of settings (a TOML spec, a sweep's point), every key and type
checked against the fields, so that a typo or a wrong type is one line naming the key.

Numbers, strings and booleans are themselves; a tuple field is an array (a tuple of tuples, an
array of arrays); a nested dataclass is a table (or, from Python, the dataclass); a dict field is a table taken as it is; a field
that may be None is None by leaving its key out (TOML has no null), or by its setting's `none` word
where the default is not None ("measured"); None itself, from Python, where the field may hold
it. The values are then checked by the dataclass itself
(`declared.check` in its `__post_init__`).
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Mapping
from typing import Any, TypeVar

from declared.settings import Setting, hints, optional, setting_of

Config = TypeVar("Config")


def from_table(kind: type[Config], table: Mapping[str, Any], error: type[Exception], where: str = "", prefix: str = "") -> Config:
    """The `kind` dataclass `table` sets (its defaults where the table is silent); `error` naming
    the key for an unknown key or a value of the wrong type, or the dataclass's own message, each
    after "`where`: " where given."""
    at = f"{where}: " if where else ""
    fields = {field.name: field for field in dataclasses.fields(kind)}
    unknown = [key for key in table if key not in fields]
    if unknown:
        raise error(f"{at}unknown key {prefix}{unknown[0]}; {kind.__name__} takes {', '.join(fields)}")
    types_ = hints(kind)
    values = {
        key: _value(types_[key], setting_of(fields[key]), value, f"{prefix}{key}", at, error) for key, value in table.items()
    }
    try:
        return kind(**values)
    except error as problem:
        raise error(f"{at}{problem}") from None


def _value(hint: Any, declared: Setting | None, value: Any, key: str, at: str, error: type[Exception]) -> Any:
    """`value` as a field declared `hint` holds it."""
    hint, nullable = optional(hint)
    if (declared is not None and declared.none and value == declared.none) or (value is None and nullable):
        return None
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if dataclasses.is_dataclass(hint):
        if isinstance(value, hint):
            return value
        if not isinstance(value, Mapping):
            raise error(f"{at}{key} must be {words(hint, declared)}, not {value!r}")
        return from_table(hint, value, error, at.removesuffix(": "), f"{key}.")
    if hint is dict or origin is dict:
        if not isinstance(value, Mapping):
            raise error(f"{at}{key} must be {words(hint, declared)}, not {value!r}")
        return dict(value)
    if origin is tuple:
        repeated = len(args) == 2 and args[1] is Ellipsis
        if not isinstance(value, (list, tuple)) or (not repeated and len(value) != len(args)):
            raise error(f"{at}{key} must be {words(hint, declared)}, not {value!r}")
        items = [args[0]] * len(value) if repeated else args
        return tuple(_value(item, None, v, f"{key}[{i}]", at, error) for i, (item, v) in enumerate(zip(items, value)))
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    fits = {bool: isinstance(value, bool), int: number and isinstance(value, int), float: number, str: isinstance(value, str)}
    if hint not in fits:
        raise error(f"{at}{key} cannot be set in a spec")
    if not fits[hint]:
        raise error(f"{at}{key} must be {words(hint, declared)}, not {value!r}")
    return float(value) if hint is float else value


def words(hint: Any, declared: Setting | None = None) -> str:
    """What a value of type `hint` looks like in a spec, for a message: "a list, each item a number"."""
    hint, _ = optional(hint)
    args = typing.get_args(hint)
    if dataclasses.is_dataclass(hint):
        return f"a table of {hint.__name__} settings"
    if hint is dict or typing.get_origin(hint) is dict:
        return "a table"
    if typing.get_origin(hint) is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"a list, each item {words(args[0])}"
        if len(set(args)) == 1:
            return f"a list of {len(args)} items, each {words(args[0])}"
        return f"a list of {len(args)} items: {', '.join(words(arg) for arg in args)}"
    kind = {bool: "true or false", int: "a whole number", float: "a number", str: "a string"}.get(hint, str(hint))
    return f'{kind} or "{declared.none}"' if declared is not None and declared.none else kind
