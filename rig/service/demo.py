"""The demo: simulate a rig, measure its latency from the video alone, and compare with the truth.

`compare_renderers` runs one heavy scene through the direct and the warp renderer, each measured
the same way.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

from analysis.options import AnalysisOptions
from rig.demo_settings import AGREEMENT_MS, COMPARE_APP_FRAME_MS, COMPARE_RENDERERS, COMPARE_TRIANGLES
from rig.errors import RigError
from rig.service.analyse import AnalysisRequest, Measurement, analyse
from rig.service.bench_profile import with_profile
from rig.service.simulate import TRUTH_FILE, SimulationResult, simulate
from rig.service.sweep import simulated_bench
from rig.session.session import Progress
from rig.sim.config import SimulationConfig

ProgressFactory = Callable[[str], Progress]
"""Makes the progress callback of one stage ("simulating", "analysing")."""


@dataclass(frozen=True)
class DemoReport:
    """One simulated run, what the analyser measured in its video, and the plot of both tracks."""

    simulation: SimulationResult
    measurement: Measurement
    plot: Path

    @property
    def true_ms(self) -> float:
        return self.simulation.truth.latency_ms

    @property
    def measured_ms(self) -> float:
        return self.measurement.result.latency_ms

    @property
    def difference_ms(self) -> float:
        return self.measured_ms - self.true_ms

    @property
    def agrees(self) -> bool:
        """Whether the analyser found the true latency, within AGREEMENT_MS and unambiguously."""
        return abs(self.difference_ms) <= AGREEMENT_MS and not self.measurement.result.ambiguous

    def to_dict(self) -> dict[str, Any]:
        return {
            "latency_true_ms": self.true_ms,
            "latency_measured_ms": self.measured_ms,
            "difference_ms": self.difference_ms,
            "agrees": self.agrees,
            "analysis": self.measurement.to_dict(),
            "simulation": self.simulation.summary(),
            "plot": str(self.plot),
        }


def demo(config: SimulationConfig, out: Path, progress: ProgressFactory | None = None) -> DemoReport:
    """Simulate `config` into `out`, analyse its video, plot both tracks into out/demo.png.

    The analysis is told the simulated bench as a lab that knows its bench tells it (its camera's
    rate and exposure, the display's refresh, the LED's side: `simulated_bench`), each checked
    against the video, so that the demo measures as the filming advice says a lab should.
    A demo folder holds synthetic data only: rerunning the demo replaces a previous simulation
    (recognised by its truth.json) but never anything else.
    """
    out = Path(out)
    stage = progress or (lambda label: None)
    simulation = simulate(config, out, stage("simulating"), overwrite=(out / TRUTH_FILE).exists())
    told = with_profile(AnalysisOptions(), simulated_bench(config), out / TRUTH_FILE)
    measurement = analyse(AnalysisRequest(simulation.video_path, told), stage("analysing"))
    result = measurement.result
    plot = out / "demo.png"
    try:
        from analysis.plots import plot_tracks

        plot_tracks(result, plot, title=f"rig demo: measured {result.latency_ms:.2f} ms, true {simulation.truth.latency_ms:.2f} ms")
    except OSError as error:
        raise RigError(f"cannot write the plot {plot}: {error}") from error
    return DemoReport(simulation, measurement, plot)


def comparison_config(config: SimulationConfig) -> SimulationConfig:
    """The scene the renderers are compared on: a scene left at the defaults (no load, cheap frames)
    becomes a heavy one."""
    defaults = SimulationConfig()
    if config.scene_triangles == defaults.scene_triangles:
        config = replace(config, scene_triangles=COMPARE_TRIANGLES)
    if config.app_frame_ms == defaults.app_frame_ms:
        config = replace(config, app_frame_ms=COMPARE_APP_FRAME_MS)
    return config


def compare_renderers(config: SimulationConfig, out: Path, progress: ProgressFactory | None = None) -> dict[str, DemoReport]:
    """The demo of `config` with each of COMPARE_RENDERERS, into out/<renderer>."""
    return {name: demo(replace(config, renderer=name), Path(out) / name, progress) for name in COMPARE_RENDERERS}
