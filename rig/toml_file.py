"""A TOML file's tables, read in one place (a sweep, a bench's spec, a bench profile), and their keys dotted."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, Mapping

from rig.errors import ConfigError


def read_toml(path: Path, what: str) -> dict[str, Any]:
    """The tables of a TOML file (`what` it is, for the message); ConfigError if it cannot be read."""
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigError(f"cannot read the {what} {path}: {error.strerror}") from None
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"{path} is not valid TOML: {error}") from None


def dotted(table: Mapping[str, Any]) -> dict[str, Any]:
    """{"camera": {"fps": 1}} and {"camera.fps": 1} alike, as dotted keys."""
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            flat.update({f"{key}.{k}": v for k, v in dotted(value).items()})
        else:
            flat[key] = value
    return flat
