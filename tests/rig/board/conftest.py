"""Shared by the rig board's tests: the synthetic board recording of the estimator tests
(tests/analysis/board/conftest.py), which `rig board latency` is run on. Test folders are not
packages, so that conftest is loaded from its path."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Callable

import pytest

SYNTHESIS = Path(__file__).resolve().parents[2] / "analysis" / "board" / "conftest.py"
MODULE_NAME = "board_recording_synthesis"


def _synthesis() -> ModuleType:
    if MODULE_NAME not in sys.modules:
        spec = importlib.util.spec_from_file_location(MODULE_NAME, SYNTHESIS)
        module = importlib.util.module_from_spec(spec)
        sys.modules[MODULE_NAME] = module  # dataclasses look their module up while it runs
        spec.loader.exec_module(module)
    return sys.modules[MODULE_NAME]


@pytest.fixture(scope="session")
def synthetic_recording() -> Callable[..., object]:
    """synthetic_recording(latency, **options): see synthesise_recording in tests/analysis/board/conftest.py."""
    return _synthesis().synthesise_recording
