"""A package's public names, each imported from its module when first used (PEP 562).

A package whose `__init__` imported every public name would load its heavy modules (numpy, OpenCV,
JAX behind them) for anyone who imports one light module of it, a declaration the command line
reads to build its options. With `__getattr__, __dir__ = lazy_exports(__name__, {...})` in the
`__init__`, `from package import Name` still works and loads Name's module alone, when asked.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_exports(package: str, exports: Mapping[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The `__getattr__` and `__dir__` of `package`, whose public names are the keys of `exports`,
    each found in the module (absolute name) it maps to, or that module itself where it is
    `package.name`."""

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        loaded = importlib.import_module(module)
        return loaded if module == f"{package}.{name}" else getattr(loaded, name)

    def __dir__() -> list[str]:
        return sorted(exports)

    return __getattr__, __dir__
