"""Option parsers shared by the subcommands: each rejects bad values with a message naming the range."""

from __future__ import annotations

import argparse
import inspect
import json
import math
import re
from pathlib import Path
from typing import Any, Mapping

from rig.commands.declared_options import declared_type
from rig.live.config import LiveConfig


def _number(kind: type[float] | type[int], text: str) -> Any:
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a {'whole ' if kind is int else ''}number, got {text!r}") from None


def positive_float(text: str) -> float:
    value = _number(float, text)
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def non_negative_int(text: str) -> int:
    value = _number(int, text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


MAX_WORKERS = 256
"""The most local Dask processes: more than the cores of any one machine a lab runs the rig on."""


def workers(text: str) -> int:
    """A local cluster's processes: 1 to MAX_WORKERS."""
    value = non_negative_int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    if value > MAX_WORKERS:
        raise argparse.ArgumentTypeError(f"must be 1 to {MAX_WORKERS} processes, got {text}")
    return value


def run_seconds(text: str) -> float:
    """How long a live run or a recording lasts, as a live run's duration is declared
    (`rig.live.config.LiveConfig`: at most a day)."""
    return declared_type(LiveConfig, "duration_s")(text)


def roi(text: str) -> tuple[int, int, int, int]:
    """X,Y,W,H in pixels."""
    parts = text.split(",")
    try:
        x, y, w, h = (int(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,W,H as four whole numbers of pixels, got {text!r}") from None
    if x < 0 or y < 0 or w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"X and Y must be >= 0 and W, H > 0, got {text}")
    return (x, y, w, h)


def _scalar(text: str) -> Any:
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def predictor_spec(text: str) -> tuple[str, dict[str, Any]]:
    """NAME[:key=value,...] or NAME:FILE.json (parameters from a file, such as `rig tune` writes)."""
    name, _, rest = text.partition(":")
    if not name:
        raise argparse.ArgumentTypeError(f"expected NAME[:key=value,...], got {text!r}")
    if not rest:
        return name, {}
    if rest.endswith(".json"):
        path = Path(rest)
        try:
            params = json.loads(path.read_text())
        except (OSError, ValueError) as error:
            raise argparse.ArgumentTypeError(f"cannot read predictor parameters from {path}: {error}") from None
        if not isinstance(params, dict):
            raise argparse.ArgumentTypeError(f"{path} must hold a JSON object of parameters")
        return name, params.get("params", params)
    params: dict[str, Any] = {}
    for item in rest.split(","):
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise argparse.ArgumentTypeError(f"predictor parameters must be key=value, got {item!r} in {text!r}")
        params[key.strip()] = _scalar(value.strip())
    return name, params


def add_executor_options(parser: argparse.ArgumentParser, what: str) -> None:
    """--workers and --scheduler: where `what` runs (`rig.executor`; neither: here, serially)."""
    parser.add_argument("--workers", type=workers, metavar="N", help=f"run {what} on a local Dask cluster of N processes (at most {MAX_WORKERS})")
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT", help=f"run {what} on an existing Dask cluster (its workers must reach the files)")


def first_sentence(obj: object) -> str:
    """The first sentence of an object's docstring, on one line."""
    paragraph = " ".join((inspect.getdoc(obj) or "").split("\n\n")[0].split())
    return re.split(r"\.\s+(?=[A-Z])", paragraph)[0].rstrip(".")


def choices_listing(title: str, choices: Mapping[str, str]) -> str:
    """A help paragraph listing `choices` a line each (name, then what it is), for an epilog."""
    width = max(map(len, choices)) + 2
    return f"{title}:\n" + "\n".join(f"  {name:<{width}}{text}" for name, text in choices.items())
