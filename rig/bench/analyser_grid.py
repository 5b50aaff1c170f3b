"""The analyser bench's videos (`rig bench analyser`): which rigs it simulates and what it does to
their films.

The mixed grid films cases whose latency the simulation knows: pendulum periods 0.6 to 1.9 s,
cameras 60 to 480 fps, displays 60 to 144 Hz, swings of 5 to 45 degrees, quality factors 20 to 500,
latencies from a predicting renderer's few ms to 450 ms (beyond half the period of a 0.6 s
pendulum, where -150 ms is as plausible), and impairments: sensor noise, defocus blur, a dim
sphere, the sphere missing from 5 % of frames. The values are spread over the cases by seeded
shuffles, so every value of every axis occurs and combinations vary; a few named cases add the
hard ones of cycle resolution (one, the unresolvable swing filmed from its release, which the
start of swing resolves).

The hard grid films what goes wrong in a lab: camera rates equal to, multiples of, divisors of and
near the display's (HARD_RATES), each at exposures of 5 to 100 % of its frame interval; a dim LED, a
dim sphere, the two swapped sides, a second bright object in view, a blob partly hidden by a bar,
and a 240 fps film with every 4th (a 120 fps one with every 2nd) frame kept, at every phase. The
issue's table cases are in it as filmed: 60 fps on 60 Hz and 144 on 144 with refreshes in phase
with the camera.

Every film's display runs at a seeded phase against the camera (a lab's display clock is not the
camera's), except where a case says otherwise. The longest period is 1.9 s, not 2: the
simulation's ground truth scans delays half a period either side of its guess and, for a 2 s
pendulum with a small latency, asks the pendulum for times past the end of its simulated window.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import cv2
import numpy as np

from analysis.video.sources import open_frames
from rig.records import VideoRecord
from rig.service import SimulationConfig, Truth
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig
from rig.sim.tracker import TrackerConfig

PERIODS_S = (0.6, 1.0, 1.4, 1.9)
CAMERA_FPS = (60.0, 120.0, 240.0, 480.0)
DISPLAY_HZ = (60.0, 90.0, 120.0, 144.0)
AMPLITUDES_DEG = (5.0, 20.0, 45.0)
QUALITIES = (20.0, 100.0, 500.0)
LATENCY_TARGETS_MS = (0.0, 40.0, 100.0, 200.0, 300.0, 450.0)
IMPAIRMENTS = ("none", "noise", "blur", "dim", "missing", "none")
DEFAULT_CASES = 48
# (camera fps, display Hz): equal, multiples, divisors and near the display's rate.
HARD_RATES = ((60.0, 60.0), (120.0, 60.0), (60.0, 120.0), (144.0, 144.0), (240.0, 144.0), (59.94, 60.0), (90.0, 60.0), (30.0, 60.0))
HARD_EXPOSURES = (0.05, 0.25, 0.5, 1.0)
# (impairment, camera fps, display Hz, exposure): what a lab's film may hold besides its rates.
HARD_IMPAIRMENTS = (
    ("dim-led", 240.0, 60.0, 1.0),
    ("dim-led", 120.0, 60.0, 0.5),
    ("dim-sphere", 60.0, 60.0, 1.0),
    ("dim-sphere", 240.0, 144.0, 0.5),
    ("swapped", 240.0, 60.0, 1.0),
    ("swapped", 60.0, 60.0, 1.0),
    ("bright-object", 120.0, 60.0, 1.0),
    ("bright-object", 90.0, 60.0, 0.5),
    ("occluded-sphere", 240.0, 60.0, 1.0),
    ("occluded-led", 144.0, 144.0, 1.0),
)
# (camera fps of the film, frames kept: every n-th).
DECIMATIONS = ((240.0, 4), (120.0, 2))
HARD_PERIOD_S = 1.0
HARD_TARGET_MS = 60.0
# The rig's latency with the hold predictor and no transport delay is about this (ms); a target
# latency is reached by adding the rest as tracker transport delay.
HOLD_BASE_MS = 38.0
NOISE_DN = 8.0
BLUR_SIGMA_PX = 2.5
DIM_WHITE_DN = 45.0
MISSING_FRACTION = 0.05
DIM_LED_FACTOR = 0.35
# A bar as wide as this fraction of a blob's swing, across its path a third of the way along.
OCCLUDER_FRACTION = 0.12
BRIGHT_OBJECT_PEAK = 900.0
BRIGHT_OBJECT_SIGMA_PX = 4.0


@dataclass(frozen=True)
class Case:
    """One video: its rig, the latency aimed at, what is done to the film afterwards, its group
    ("mixed", "named" or "hard"), and for a decimated film (n, k): every n-th frame from the k-th."""

    name: str
    config: SimulationConfig
    target_ms: float
    impairment: str
    group: str = "mixed"
    decimation: tuple[int, int] | None = None


def _config(
    period: float,
    fps: float,
    display: float,
    amplitude: float,
    quality: float,
    target_ms: float,
    impairment: str,
    seed: int,
    release_s: float | None = None,
    exposure: float = 1.0,
    phase: float | None = None,
) -> SimulationConfig:
    predictor = "slerp" if target_ms == 0.0 else "hold"
    transport = 0.004 if target_ms == 0.0 else max(0.0, target_ms - HOLD_BASE_MS) / 1e3
    dim = impairment in ("dim", "dim-sphere")
    camera = CameraConfig(
        fps=fps,
        exposure_s=exposure / fps,
        noise_dn=NOISE_DN if impairment == "noise" else CameraConfig().noise_dn,
        display_white_dn=DIM_WHITE_DN if dim else CameraConfig().display_white_dn,
    )
    display_phase = float(np.random.default_rng(seed).uniform()) if phase is None else phase
    return SimulationConfig(
        duration_s=max(6.0, 4.0 * period),
        seed=seed,
        pendulum=PendulumConfig(period_s=period, amplitude_deg=amplitude, quality=quality, release_s=release_s),
        tracker=TrackerConfig(transport_delay_s=transport),
        display=DisplayConfig(refresh_hz=display, phase=display_phase),
        camera=camera,
        predictor=predictor,
        warmup_s=0.5 + transport,
    )


def _case(
    index: int,
    period: float,
    fps: float,
    display: float,
    amplitude: float,
    quality: float,
    target: float,
    impairment: str,
    label: str = "",
    release_s: float | None = None,
) -> Case:
    name = label or f"case{index:02d}"
    released = f" released at {release_s:g}s" if release_s is not None else ""
    description = (
        f"{name}: T={period:g}s {fps:g}fps {display:g}Hz {amplitude:g}deg Q={quality:g} "
        f"target {target:g}ms {impairment}{released}"
    )
    config = _config(period, fps, display, amplitude, quality, target, impairment, index, release_s)
    return Case(description, config, target, impairment, "named" if label else "mixed")


def grid(count: int = DEFAULT_CASES, seed: int = 0) -> list[Case]:
    """``count`` mixed cases (every axis value shuffled over them), then the named hard cases."""
    rng = np.random.default_rng(seed)

    def spread(values: tuple[Any, ...]) -> list[Any]:
        repeated = [values[i % len(values)] for i in range(count)]
        return [repeated[i] for i in rng.permutation(count)]

    axes = [spread(axis) for axis in (PERIODS_S, CAMERA_FPS, DISPLAY_HZ, AMPLITUDES_DEG, QUALITIES, LATENCY_TARGETS_MS, IMPAIRMENTS)]
    cases = [_case(i, *values) for i, values in enumerate(zip(*axes, strict=True))]
    named = [
        (0.6, 240.0, 60.0, 20.0, 20.0, 450.0, "none", "beyond-half-damped"),
        (0.6, 120.0, 144.0, 45.0, 50.0, 450.0, "none", "beyond-half-wide"),
        (0.6, 240.0, 60.0, 5.0, 500.0, 450.0, "none", "beyond-half-unresolvable"),
        (1.0, 240.0, 60.0, 20.0, 200.0, 480.0, "none", "near-half-period"),
        (0.6, 240.0, 60.0, 5.0, 500.0, 450.0, "none", "beyond-half-filmed-release", 1.0),
    ]
    return cases + [_case(count + i, *values) for i, values in enumerate(named)]


def _hard_case(
    index: int, label: str, fps: float, display: float, exposure: float, impairment: str = "none", **extra: Any
) -> Case:
    seed = 1000 + index
    config = _config(HARD_PERIOD_S, fps, display, 20.0, 100.0, HARD_TARGET_MS, impairment, seed, exposure=exposure, **extra)
    description = f"{label}: {fps:g}fps {display:g}Hz exposure {exposure:.0%} phase {config.display.phase:.2f} {impairment}"
    return Case(description, config, HARD_TARGET_MS, impairment, "hard")


def hard_grid() -> list[Case]:
    """What goes wrong in a lab (see the module docstring), the issue's table cases first."""
    cases = [
        _hard_case(0, "table-60-on-60", 60.0, 60.0, 1.0, phase=0.0),
        _hard_case(1, "table-144-on-144", 144.0, 144.0, 1.0, phase=0.0),
    ]
    for fps, display in HARD_RATES:
        for exposure in HARD_EXPOSURES:
            cases.append(_hard_case(len(cases), f"rates-{fps:g}-on-{display:g}", fps, display, exposure))
    for impairment, fps, display, exposure in HARD_IMPAIRMENTS:
        cases.append(_hard_case(len(cases), impairment, fps, display, exposure, impairment))
    for fps, every in DECIMATIONS:
        film = _hard_case(len(cases), f"every-{every}th", fps, 60.0, 1.0)
        for start in range(every):
            cases.append(replace(film, name=f"{film.name} from frame {start}", impairment="decimated", decimation=(every, start)))
    return cases


def quick_grid() -> list[Case]:
    """Three short, cheap cases for a smoke test: two of the mixed grid, one of the hard."""
    cases = [
        _case(0, 0.6, 60.0, 60.0, 20.0, 50.0, 40.0, "none", "quick-a"),
        _case(1, 0.6, 60.0, 120.0, 30.0, 20.0, 100.0, "missing", "quick-b"),
        replace(_hard_case(2, "quick-dim-led", 120.0, 60.0, 1.0, "dim-led"), group="hard"),
    ]
    short = [replace(case.config, duration_s=3.0, pendulum=replace(case.config.pendulum, period_s=0.6)) for case in cases]
    return [replace(case, config=config) for case, config in zip(cases, short, strict=True)]


def _rewrite(video: Path, out: Path, change: Callable[[int, np.ndarray], np.ndarray | None], fps: float) -> Path:
    """Write ``video``'s frames, changed (None: left out), to ``out`` as the simulated camera does."""
    source = open_frames(video)
    writer = VideoRecord(out, fps, *source.frame_size)
    with writer:
        for index, (_, frame) in enumerate(source.frames()):
            changed = change(index, frame)
            if changed is not None:
                writer.write(changed)
    return out


def _background(video: Path, roi: list[int]) -> np.ndarray:
    """The region's per-pixel median over the film: what it shows where nothing moves."""
    x, y, w, h = roi
    frames = [frame[y : y + h, x : x + w] for _, frame in open_frames(video).frames()]
    return np.median(np.stack(frames[:: max(1, len(frames) // 31)]), axis=0).astype(np.uint8)


def _bar(video: Path, roi: list[int]) -> Callable[[int, np.ndarray], np.ndarray]:
    """A change that hides a vertical bar across a blob's path (the background shows there)."""
    x, y, w, h = roi
    background = _background(video, roi)
    left, width = w // 3, max(2, round(OCCLUDER_FRACTION * w))

    def hide(_: int, frame: np.ndarray) -> np.ndarray:
        frame = frame.copy()
        frame[y : y + h, x + left : x + left + width] = background[:, left : left + width]
        return frame

    return hide


def _bright_object(shape: tuple[int, ...]) -> np.ndarray:
    """A static bright spot between and above the two halves, saturated like a lamp."""
    height, width = shape
    rows, cols = np.mgrid[0:height, 0:width]
    spot = BRIGHT_OBJECT_PEAK * np.exp(-((cols - width / 2) ** 2 + (rows - height / 8) ** 2) / (2 * BRIGHT_OBJECT_SIGMA_PX**2))
    return spot.astype(np.float32)


def _change(video: Path, case: Case, truth: Truth, seed: int) -> Callable[[int, np.ndarray], np.ndarray | None] | None:
    """What the case's impairment does to each frame (None: nothing; the simulation made it)."""
    impairment = case.impairment
    if impairment == "blur":
        return lambda _, frame: cv2.GaussianBlur(frame, (0, 0), BLUR_SIGMA_PX)
    if impairment == "dim-led":
        return lambda _, frame: np.concatenate(
            [np.rint(frame[:, : frame.shape[1] // 2] * DIM_LED_FACTOR).astype(np.uint8), frame[:, frame.shape[1] // 2 :]], axis=1
        )
    if impairment == "swapped":
        return lambda _, frame: np.ascontiguousarray(frame[:, ::-1])
    if impairment == "bright-object":
        spot: list[np.ndarray] = []

        def lamp(_: int, frame: np.ndarray) -> np.ndarray:
            if not spot:
                spot.append(_bright_object(frame.shape))
            return np.clip(frame + spot[0], 0, 255).astype(np.uint8)

        return lamp
    if impairment in ("occluded-sphere", "occluded-led"):
        return _bar(video, truth.sphere_roi if impairment == "occluded-sphere" else truth.led_roi)
    if impairment == "decimated":
        assert case.decimation is not None
        every, start = case.decimation
        return lambda index, frame: frame if index % every == start else None
    if impairment == "missing":
        x, y, w, h = truth.sphere_roi
        background = _background(video, truth.sphere_roi)
        frames = truth.frames
        hidden = set(np.random.default_rng(seed).choice(frames, round(MISSING_FRACTION * frames), replace=False).tolist())

        def hide(index: int, frame: np.ndarray) -> np.ndarray:
            if index not in hidden:
                return frame
            frame = frame.copy()
            frame[y : y + h, x : x + w] = background
            return frame

        return hide
    return None


def impaired(video: Path, case: Case, truth: Truth, seed: int) -> Path:
    """The case's film after its impairment (the original for those the simulation makes itself)."""
    change = _change(video, case, truth, seed)
    if change is None:
        return video
    suffix = f"-{case.decimation[1]}" if case.decimation is not None else ""
    return _rewrite(video, video.with_name(f"{case.impairment}{suffix}.avi"), change, film_fps(case))


def film_fps(case: Case) -> float:
    """The frame rate of the film the analyser gets."""
    return case.config.camera.fps / (case.decimation[0] if case.decimation is not None else 1)
