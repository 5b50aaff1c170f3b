"""The rig's service layer: what the command line, the demo, the benches and the notebooks call.

    from rig.service import simulate, analyse, demo, tune

Each is a plain function with a typed request or config and a typed result: `simulate` runs the
simulated rig (`SimulationConfig` -> `SimulationResult` with its `Truth`), `analyse` measures the
latency in a video (`AnalysisRequest` -> `Measurement`), `demo` does both and compares
(`DemoReport`), `tune` fits a predictor to recorded motion (`TuneReport`), `plan` recommends how
to film (`PlanRequest` -> `Plan`), `calibrate_camera` measures a camera's readout and exposure
from a film of a flashing light (`CalibrationRequest` -> `analysis.shutter.ShutterResult`). The
benchmarks are in `rig.bench`, registered by name.
"""

from rig.service.analyse import AnalysisRequest, Measurement, analyse
from rig.service.calibrate import CalibrationRequest, calibrate_camera
from rig.service.demo import DemoReport, compare_renderers, comparison_config, demo
from rig.service.plan import Plan, PlanRequest, plan
from rig.service.simulate import SimulationResult, simulate
from rig.service.tune import TuneReport, split_traces, tune
from rig.sim.config import SimulationConfig
from rig.sim.truth import Truth

__all__ = [
    "AnalysisRequest",
    "CalibrationRequest",
    "DemoReport",
    "Measurement",
    "Plan",
    "PlanRequest",
    "SimulationConfig",
    "SimulationResult",
    "Truth",
    "TuneReport",
    "analyse",
    "calibrate_camera",
    "compare_renderers",
    "comparison_config",
    "demo",
    "plan",
    "simulate",
    "split_traces",
    "tune",
]
