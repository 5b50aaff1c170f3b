"""Plan how to film: the camera setting, film length and layout that measure latency to a wanted
accuracy (`rig plan`).

Each camera rate and exposure on offer is filmed by the simulated rig (the display's refresh, the
pendulum's period, the rig's default layout in a 640 x 480 image) for a short film at two display
phases, one in step with the camera and one not, and analysed as the lab will analyse it, the
camera's settings given (`rig analyse --display-hz --exposure-ms`). Two parts of the 95 %
half-width come out: the statistical part, which shrinks as one over the square root of the film's
length (more conservatively than that, since the interval's critical value falls too), and the
part the camera's sampling of the display and the model checks add, which does not. The worse
phase counts. A setting reaches the accuracy with the shortest film whose half-width, so
extrapolated, is within it; the recommendation is the one that needs the shortest film (then the
lowest frame rate), and it is checked by filming it at that length as `rig simulate` would with the
recommended options, and analysing it: the plan promises only what that check met, lengthening
the film up to CHECK_ATTEMPTS times.

Besides, every setting's sampling bias bound is worked out analytically
(``analysis.sampling.model.bias_range_s``): what a camera phase-locked to the display could be off
by if the video could not place the refreshes.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Callable

import analysis
from declared import check, like
from analysis.sampling.model import bias_range_s, commensurate
from analysis.timing import RATE_AGREEMENT
from rig.errors import ConfigError
from rig.plan_settings import PlanAccuracy
from rig.service.bench_profile import CameraProfile
from rig.service.simulate import SimulationResult, simulate
from rig.sim.camera import CameraConfig
from rig.sim.config import SimulationConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig

# Films simulated for each setting: this many periods, at least TRIAL_MIN_S.
TRIAL_PERIODS = 4
TRIAL_MIN_S = 3.0
# A display phase against the camera that is in step with no common rate pair.
OFF_STEP_PHASE = 0.37
# The shortest film recommended: this many periods, at least MIN_FILM_S; the longest MAX_FILM_S.
MIN_FILM_PERIODS = 6
MIN_FILM_S = 4.0
MAX_FILM_S = 120.0
FILM_STEP_S = 0.5
CHECK_ATTEMPTS = 3
CHECK_GROWTH = 1.6
CAMERA_FPS_RANGE = (20.0, 2000.0)

Log = Callable[[str], None]


@dataclass(frozen=True)
class PlanRequest:
    """The display's refresh (Hz), the camera rates (fps) and exposures (fractions of the frame
    interval) on offer, the pendulum's period (s) and swing (degrees), and the accuracy wanted:
    the 95 % half-width of the latency (ms)."""

    display_hz: float
    camera_fps: tuple[float, ...]
    exposures: tuple[float, ...] = (1.0,)
    period_s: float = 1.0
    amplitude_deg: float = PendulumConfig().amplitude_deg
    accuracy_ms: float = like(PlanAccuracy, "accuracy_ms")

    def __post_init__(self) -> None:
        check(self, ConfigError)
        low, high = CAMERA_FPS_RANGE
        if not self.camera_fps or not all(low <= fps <= high for fps in self.camera_fps):
            raise ConfigError(f"camera frame rates must be {low:g}-{high:g} fps, got {list(self.camera_fps)}")
        if not self.exposures or not all(0.0 < e <= 1.0 for e in self.exposures):
            raise ConfigError(f"exposures are fractions of the frame interval in (0, 1], got {list(self.exposures)}")
        DisplayConfig(refresh_hz=self.display_hz)
        PendulumConfig(period_s=self.period_s, amplitude_deg=self.amplitude_deg)


@dataclass(frozen=True)
class Setting:
    """One camera setting, as simulated: its rate and exposure; phases, how many phases of each
    refresh its frames visit (None: they walk through all); bias_bound_ms, what a phase-locked
    film could be off by; statistical_ms and added_ms, the worse phase's statistical half-width
    over trial_s of film and what sampling and checks added; error_ms the larger error the trials
    made; film_s the film that reaches the accuracy (None: none does) and half_width_ms its
    expected 95 % half-width."""

    camera_fps: float
    exposure: float
    phases: int | None
    bias_bound_ms: float
    trial_s: float
    statistical_ms: float
    added_ms: float
    error_ms: float
    film_s: float | None
    half_width_ms: float | None

    @property
    def exposure_ms(self) -> float:
        return 1e3 * self.exposure / self.camera_fps

    def half_width_at(self, film_s: float) -> float:
        return self.statistical_ms * math.sqrt(self.trial_s / film_s) + self.added_ms

    def to_dict(self) -> dict[str, Any]:
        return {
            "camera_fps": self.camera_fps,
            "exposure": self.exposure,
            "exposure_ms": self.exposure_ms,
            "phases_per_refresh": self.phases,
            "bias_bound_ms": self.bias_bound_ms,
            "trial_s": self.trial_s,
            "statistical_half_width_ms": self.statistical_ms,
            "added_half_width_ms": self.added_ms,
            "trial_error_ms": self.error_ms,
            "film_s": self.film_s,
            "expected_half_width_ms": self.half_width_ms,
        }


@dataclass(frozen=True)
class Plan:
    """Every setting, the recommended one (None: none reaches the accuracy) with the film length it
    needs and what the check by simulation measured, and the layout the simulations assumed."""

    request: PlanRequest
    settings: tuple[Setting, ...]
    recommended: Setting | None
    checked: dict[str, float] | None
    layout: dict[str, Any]

    def commands(self) -> list[str]:
        """The `rig simulate` and `rig analyse` lines that film and measure the recommendation."""
        if self.recommended is None:
            return []
        best, request = self.recommended, self.request
        return [
            f"rig simulate --out plan --display-hz {request.display_hz:g} --camera-fps {best.camera_fps:g} "
            f"--exposure {best.exposure:g} --duration {best.film_s:g} --period-s {request.period_s:g} "
            f"--amplitude-deg {request.amplitude_deg:g}",
            f"rig analyse plan/video.avi --display-hz {request.display_hz:g} --exposure-ms {best.exposure_ms:.6g}",
        ]

    def bench_changes(self, camera: CameraProfile, when: str) -> dict[str, dict[str, Any]]:
        """What `rig plan --bench` writes into the bench profile (`rig.service.bench_profile`), whose
        camera is now `camera`: the display's refresh and, where there is one, the recommended camera
        setting (frame rate and exposure), each from this plan (`when`, a date). A readout the profile
        holds for another frame rate (or one longer than the new frame interval) is removed: it may
        not hold at this one, and the camera is to be calibrated again."""
        source = f"rig plan {when}"
        changes: dict[str, dict[str, Any]] = {"display": {"refresh_hz": self.request.display_hz, "refresh_source": source}}
        best = self.recommended
        if best is None:
            return changes
        why = f"{source}: recommended for a 95% half-width of {self.request.accuracy_ms:g} ms"
        interval_ms = 1e3 / best.camera_fps
        changes["camera"] = {
            "fps": best.camera_fps, "fps_source": why,
            "exposure_ms": float(f"{best.exposure_ms:.6g}"), "exposure_ci95_ms": None, "exposure_source": why,
        }  # fmt: skip
        other_rate = camera.fps is not None and abs(camera.fps - best.camera_fps) > RATE_AGREEMENT * best.camera_fps
        if camera.readout_ms is not None and (other_rate or camera.readout_ms > interval_ms):
            changes["camera"] |= dict.fromkeys(("readout_ms", "readout_ci95_ms", "readout_direction", "readout_source"))
        return changes

    def to_dict(self) -> dict[str, Any]:
        return {
            "request": asdict(self.request),
            "settings": [setting.to_dict() for setting in self.settings],
            "recommended": None if self.recommended is None else self.recommended.to_dict(),
            "checked": self.checked,
            "layout": self.layout,
            "commands": self.commands(),
        }


def _config(request: PlanRequest, fps: float, exposure: float, duration_s: float, phase: float) -> SimulationConfig:
    """The simulated rig `rig simulate` makes of the plan's options (its defaults elsewhere)."""
    return SimulationConfig(
        duration_s=duration_s,
        pendulum=PendulumConfig(period_s=request.period_s, amplitude_deg=request.amplitude_deg),
        display=DisplayConfig(refresh_hz=request.display_hz, phase=phase),
        camera=CameraConfig(fps=fps, exposure_s=exposure / fps),
    )


def _measure(request: PlanRequest, config: SimulationConfig, folder: Path) -> tuple[SimulationResult, analysis.LatencyResult]:
    run = simulate(config, folder, overwrite=True)
    result = analysis.analyse(
        run.video_path, analysis.AnalysisOptions(display_hz=request.display_hz, exposure_ms=config.camera.exposure * 1e3)
    )
    return run, result


def _half_widths(result: analysis.LatencyResult) -> tuple[float, float]:
    """(statistical half-width, what sampling and checks added) of the default method, in ms."""
    method = result.methods[result.method]
    statistical = method.details["statistical_ci95_ms"]
    own = (statistical[1] - statistical[0]) / 2
    final = (result.ci95_ms[1] - result.ci95_ms[0]) / 2
    return own, max(final - own, 0.0)


def film_needed(setting: Setting, request: PlanRequest) -> float | None:
    """The shortest film (s, in FILM_STEP_S steps) whose expected half-width reaches the accuracy."""
    shortest = max(MIN_FILM_S, MIN_FILM_PERIODS * request.period_s)
    room = request.accuracy_ms - setting.added_ms
    if room <= 0:
        return None
    needed = max(shortest, setting.trial_s * (setting.statistical_ms / room) ** 2)
    film = math.ceil(needed / FILM_STEP_S) * FILM_STEP_S
    return film if film <= MAX_FILM_S else None


def _trial(request: PlanRequest, fps: float, exposure: float, folder: Path, log: Log) -> Setting:
    trial_s = max(TRIAL_MIN_S, TRIAL_PERIODS * request.period_s)
    statistical, added, error = 0.0, 0.0, 0.0
    for phase in (0.0, OFF_STEP_PHASE):
        run, result = _measure(request, _config(request, fps, exposure, trial_s, phase), folder)
        own, extra = _half_widths(result)
        statistical, added = max(statistical, own), max(added, extra)
        error = max(error, abs(result.latency_ms - run.truth.latency_ms))
    ratio = commensurate(fps / request.display_hz)
    setting = Setting(
        camera_fps=fps,
        exposure=exposure,
        phases=ratio[0] if ratio is not None else None,
        bias_bound_ms=bias_range_s(request.display_hz, fps, exposure / fps) * 1e3,
        trial_s=trial_s,
        statistical_ms=statistical,
        added_ms=added,
        error_ms=error,
        film_s=None,
        half_width_ms=None,
    )
    film = film_needed(setting, request)
    setting = replace(setting, film_s=film, half_width_ms=None if film is None else setting.half_width_at(film))
    log(
        f"{fps:g} fps, exposure {exposure:.0%}: half-width {statistical + added:.3f} ms over {trial_s:g} s "
        f"({added:.3f} from sampling and checks), error {error:.3f} ms; "
        + (f"{film:g} s of film reach {request.accuracy_ms:g} ms" if film is not None else "never reaches it")
    )
    return setting


def _layout(config: SimulationConfig, run: SimulationResult) -> dict[str, Any]:
    camera = config.camera
    return {
        "image_px": [camera.width, camera.height],
        "led_roi": run.truth.led_roi,
        "sphere_roi": run.truth.sphere_roi,
        "advice": (
            "the LED left of the display and at the same height (a rolling shutter reads rows at different "
            "times); each swing filling most of its half of the image, as in these regions of a "
            f"{camera.width}x{camera.height} image (a smaller swing in pixels measures proportionally worse); "
            "the sphere drawn larger than the LED looks and below the camera's saturation; nothing else moving "
            "in view; the sphere's path in one band of display rows (its scan-out delay is part of the latency)"
        ),
    }


def plan(request: PlanRequest, log: Log, folder: Path | None = None) -> Plan:
    """Simulate every setting on offer, and recommend and check one (see the module docstring);
    ``folder`` keeps the simulated films (else a temporary folder)."""
    with tempfile.TemporaryDirectory(prefix="rig-plan-") as scratch:
        work = Path(folder) if folder is not None else Path(scratch)
        settings = [
            _trial(request, fps, exposure, work / "trial", log)
            for fps in request.camera_fps
            for exposure in request.exposures
        ]
        reaching = sorted((s for s in settings if s.film_s is not None), key=lambda s: (s.film_s, s.camera_fps, -s.exposure))
        recommended, checked, layout = None, None, {}
        for candidate in reaching[:2]:
            recommended, checked, layout = _checked(request, candidate, work / "check", log)
            if recommended is not None:
                break
    ordered = sorted(settings, key=lambda s: (s.film_s is None, s.film_s or 0.0, s.camera_fps, -s.exposure))
    return Plan(request, tuple(ordered), recommended, checked, layout)


def _checked(
    request: PlanRequest, setting: Setting, folder: Path, log: Log
) -> tuple[Setting | None, dict[str, float] | None, dict[str, Any]]:
    """The setting with a film length that a simulation as `rig simulate` makes it confirms
    (lengthened up to CHECK_ATTEMPTS times), what that simulation measured, and its layout; None
    when no length within MAX_FILM_S does."""
    film = setting.film_s
    assert film is not None
    for _ in range(CHECK_ATTEMPTS):
        config = _config(request, setting.camera_fps, setting.exposure, film, DisplayConfig().phase)
        run, result = _measure(request, config, folder)
        half_width = (result.ci95_ms[1] - result.ci95_ms[0]) / 2
        covered = result.ci95_ms[0] <= run.truth.latency_ms <= result.ci95_ms[1]
        log(f"check: {setting.camera_fps:g} fps, exposure {setting.exposure:.0%}, {film:g} s: half-width {half_width:.3f} ms")
        if half_width <= request.accuracy_ms and covered and not result.ambiguous:
            measured = {
                "film_s": film,
                "half_width_ms": half_width,
                "error_ms": result.latency_ms - run.truth.latency_ms,
                "true_latency_ms": run.truth.latency_ms,
            }
            return replace(setting, film_s=film, half_width_ms=half_width), measured, _layout(config, run)
        film = math.ceil(film * CHECK_GROWTH / FILM_STEP_S) * FILM_STEP_S
        if film > MAX_FILM_S:
            break
    return None, None, {}
