"""Predictor parameter files: JSON that `predictors.make` and `rig simulate --predictor NAME:FILE.json` read.

    {"predictor": "kalman-cv", "params": {"acceleration_noise": 0.8, ...}, ...anything else}

Only "params" is needed to make a predictor; `rig tune` also records what it was fitted on and how
well it did, under other keys.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Mapping

from predictors.errors import PredictorError


def write_params(path: str | os.PathLike[str], predictor: str, params: Mapping[str, Any], **details: Any) -> None:
    """Write a parameter file for `predictor`; `details` go beside "params"."""
    record = {"predictor": predictor, "params": dict(params), **details}
    Path(path).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")


def read_params(path: str | os.PathLike[str]) -> tuple[str, dict[str, Any]]:
    """(predictor name, params) from a file `write_params` wrote: `make(name, **params)`."""
    path = Path(path)
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise PredictorError(f"cannot read predictor parameters from {path}: {error}") from None
    if not (isinstance(record, dict) and isinstance(record.get("params"), dict) and isinstance(record.get("predictor"), str)):
        raise PredictorError(f"{path} is not a predictor parameter file: it needs \"predictor\" and a \"params\" object")
    return record["predictor"], record["params"]
