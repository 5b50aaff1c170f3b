"""A TOML file's tables, read in one place: a sweep, a bench's spec, a bench profile."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from rig.errors import ConfigError


def read_toml(path: Path, what: str) -> dict[str, Any]:
    """The tables of a TOML file (`what` it is, for the message); ConfigError if it cannot be read."""
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigError(f"cannot read the {what} {path}: {error.strerror}") from None
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"{path} is not valid TOML: {error}") from None
