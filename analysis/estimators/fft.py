"""``fft``: Steed's phase method, the phase lag of the sphere's swing behind the LED's (``analysis.phase``)."""

from __future__ import annotations

import time

from analysis.estimators.contract import EstimationContext
from analysis.phase import fft_phase_latency
from analysis.result import MethodResult


class FftPhaseEstimator:
    """The phase difference of both signals at the swing frequency, over the angular frequency."""

    name = "fft"
    gives_interval = False

    def estimate(self, context: EstimationContext) -> MethodResult:
        started = time.perf_counter()
        swing = context.swing
        _, led, sphere = swing.uniform
        phase = fft_phase_latency(led, sphere, swing.fps, swing.frequency_hz)
        return MethodResult(
            self.name,
            context.unwrapped(phase.latency_s) * 1e3,
            None,
            "sine",
            time.perf_counter() - started,
            {"frequency_hz": phase.frequency_hz, "cycles": phase.cycles},
        )
