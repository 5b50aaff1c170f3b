"""Compiled programs kept between runs: JAX's persistent compilation cache, on by default for the
`rig` command line (and the Dask workers it starts, which inherit its environment).

What runs on JAX (the `bayes` estimator's likelihood, predictor tuning) is compiled by XLA on its
first use in a process, which costs seconds. The cache holds every compiled program on disk, so a
later process loads it instead. Set JAX_COMPILATION_CACHE_DIR to choose the folder. The default
analysis (`sinefit`) is numpy and compiles nothing.
"""

from __future__ import annotations

import os
from pathlib import Path


def default_cache_dir() -> Path:
    """$XDG_CACHE_HOME/latency-rig/jax, or ~/.cache/latency-rig/jax."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "latency-rig" / "jax"


def keep_compiled_fits() -> None:
    """Turn JAX's persistent compilation cache on for this process and its children, unless the
    user set it; every compiled program is kept, however quickly it compiled. Sets environment
    variables only: JAX reads them when it is imported, which the command line does lazily."""
    os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", str(default_cache_dir()))
    os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "0")
