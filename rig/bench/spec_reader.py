"""A bench's grid from its TOML spec: a frozen dataclass whose every key and value is checked
against the fields' declared types, so that a typo or a wrong type is one line naming the key.

Numbers, strings and booleans are themselves; a tuple field is a TOML array (a tuple of tuples, an
array of arrays); a nested dataclass is a table; a field that may be None is None by leaving its
key out (TOML has no null).
"""

from __future__ import annotations

import dataclasses
import types
import typing
from pathlib import Path
from typing import Any, TypeVar

from rig.errors import ConfigError
from rig.service.sweep import read_toml

Spec = TypeVar("Spec")


def read_spec(kind: type[Spec], path: Path) -> Spec:
    """The `kind` dataclass a TOML file sets (its defaults where the file is silent); ConfigError on
    a file that cannot be read, an unknown key, or a value of the wrong type."""
    return _dataclass(kind, read_toml(path, "spec"), "", str(path))


def _dataclass(kind: type[Spec], table: dict[str, Any], prefix: str, where: str) -> Spec:
    hints = typing.get_type_hints(kind)
    names = [f.name for f in dataclasses.fields(kind)]
    unknown = [key for key in table if key not in names]
    if unknown:
        raise ConfigError(f"{where}: unknown key {prefix}{unknown[0]}; {kind.__name__} takes {', '.join(names)}")
    values = {key: _value(hints[key], value, f"{prefix}{key}", where) for key, value in table.items()}
    try:
        return kind(**values)
    except ConfigError as error:
        raise ConfigError(f"{where}: {error}") from None


def _value(hint: Any, value: Any, key: str, where: str) -> Any:
    """`value` as a field declared `hint` holds it."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (types.UnionType, typing.Union):
        return _value(next(arg for arg in args if arg is not type(None)), value, key, where)
    if dataclasses.is_dataclass(hint):
        if not isinstance(value, dict):
            raise ConfigError(f"{where}: {key} must be {_described(hint)}, not {value!r}")
        return _dataclass(hint, value, f"{key}.", where)
    if origin is tuple:
        repeated = len(args) == 2 and args[1] is Ellipsis
        if not isinstance(value, list) or (not repeated and len(value) != len(args)):
            raise ConfigError(f"{where}: {key} must be {_described(hint)}, not {value!r}")
        items = [args[0]] * len(value) if repeated else args
        return tuple(_value(item, v, f"{key}[{i}]", where) for i, (item, v) in enumerate(zip(items, value)))
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    fits = {bool: isinstance(value, bool), int: number and isinstance(value, int), float: number, str: isinstance(value, str)}
    if hint not in fits:
        raise ConfigError(f"{where}: {key} cannot be set in a spec")
    if not fits[hint]:
        raise ConfigError(f"{where}: {key} must be {_described(hint)}, not {value!r}")
    return float(value) if hint is float else value


def _described(hint: Any) -> str:
    """What a value of `hint` looks like in TOML, for a message."""
    args = typing.get_args(hint)
    if dataclasses.is_dataclass(hint):
        return f"a table of {hint.__name__} settings"
    if typing.get_origin(hint) is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"a list, each item {_described(args[0])}"
        if len(set(args)) == 1:
            return f"a list of {len(args)} items, each {_described(args[0])}"
        return f"a list of {len(args)} items: {', '.join(_described(arg) for arg in args)}"
    return {bool: "true or false", int: "a whole number", float: "a number", str: "a string"}.get(hint, str(hint))
