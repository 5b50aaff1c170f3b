"""Importing the analyser does no work: it changes no JAX setting and does not even import JAX."""

import os
import subprocess
import sys


def run_python(code: str) -> str:
    """What ``code`` prints, run by a fresh interpreter that JAX_ENABLE_X64 does not configure."""
    environment = {name: value for name, value in os.environ.items() if name != "JAX_ENABLE_X64"}
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=environment, timeout=300
    ).stdout


def test_importing_analysis_imports_no_jax():
    assert run_python("import sys, analysis; print('jax' in sys.modules)").split() == ["False"]


def test_importing_every_analysis_module_leaves_jax_in_32_bit_mode():
    code = (
        "import importlib, pkgutil, analysis\n"
        "names = [module.name for module in pkgutil.walk_packages(analysis.__path__, 'analysis.')]\n"
        "for name in names:\n"
        "    importlib.import_module(name)\n"
        "import jax\n"
        "print('analysis.fit.model' in names, jax.config.jax_enable_x64)\n"
    )
    assert run_python(code).split() == ["True", "False"]


def test_the_least_squares_fit_imports_no_jax():
    code = (
        "import sys\n"
        "import numpy as np\n"
        "import analysis.estimators.sinefit\n"
        "from analysis.fit.least_squares import Guess, fit_sine\n"
        "from analysis.signals import SwingSignals\n"
        "t = np.arange(720) / 120\n"
        "led = 40 * np.sin(2 * np.pi * t / 0.8)\n"
        "sphere = 25 * np.sin(2 * np.pi * (t - 0.05) / 0.8)\n"
        "fit = fit_sine(SwingSignals(t, led, sphere), (0.01, 0.01), Guess(1.25, 0.0, 0.0, 0.054, 0.6))\n"
        "print(round(fit.latency_s, 6), [name for name in sys.modules if name.split('.')[0] in ('jax', 'jaxlib', 'jaxopt')])\n"
    )
    assert run_python(code).split() == ["0.05", "[]"]
