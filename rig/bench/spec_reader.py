"""A bench's spec from its TOML file: the frozen dataclass it sets, every key and value checked
against the fields' declarations (`declared.from_table`), so that a typo or a wrong type is one
line naming the file and the key."""

from __future__ import annotations

from pathlib import Path
from typing import TypeVar

from declared import from_table
from rig.errors import ConfigError
from rig.toml_file import read_toml

Spec = TypeVar("Spec")


def read_spec(kind: type[Spec], path: Path) -> Spec:
    """The `kind` dataclass a TOML file sets (its defaults where the file is silent); ConfigError on
    a file that cannot be read, an unknown key, or a value of the wrong type or out of range."""
    return from_table(kind, read_toml(path, "spec"), ConfigError, str(path))
