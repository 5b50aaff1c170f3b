"""Synthetic pendulum videos with a known latency, for testing the analyser (given to tests as fixtures).

The LED hangs on a damped pendulum and is drawn as a saturating Gaussian blob (with an optional
wide halo: bloom). With ``chirp`` the swing's frequency rises as its amplitude decays, as a real
pendulum's does (by amplitude^2 / 16). The sphere is a
dimmer, shaded blob that a display shows at the LED's position ``latency_s`` earlier: each display
refresh holds one pose for 1/display_hz, sampled so that the middle of the hold is ``latency_s``
after the sampled pose; that makes ``latency_s`` the mean delay of the sphere's swing, which is
what the phase method measures. The camera integrates light over an exposure centred on its frame
time ``n / fps`` (box filter; the sphere's held poses are weighted by their exact overlap with it),
then adds static bright clutter, Gaussian noise and optional defocus blur, and clips to 8 bits.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pytest

LED_SUBSAMPLES = 12
# Noise frames drawn once and picked at random per frame: independent enough, and fast.
NOISE_BANK = 61


@dataclass(frozen=True)
class PendulumScene:
    """Times in s, positions and sizes in px, intensities in 8-bit levels before clipping.

    exposure is a fraction of the frame interval; decay is the fraction of the swing's amplitude
    lost over the clip; the sphere swings like the LED, scaled by sphere_scale about its centre.
    With release_s the pendulum is held at its full swing until then and released from rest (the
    swing then starts there, not at phase_rad); with stop_s it is stopped dead then.
    """

    latency_s: float = 0.05
    period_s: float = 1.0
    duration_s: float = 6.3
    fps: float = 240.0
    display_hz: float = 60.0
    display_offset_s: float = 0.0037
    exposure: float = 1.0
    width: int = 160
    height: int = 120
    swing_rad: float = 0.35
    phase_rad: float = 0.4
    decay: float = 0.2
    arm_px: float = 80.0
    led_centre: tuple[float, float] = (40.0, 55.0)
    sphere_centre: tuple[float, float] = (115.0, 60.0)
    sphere_scale: float = 0.9
    led_sigma: float = 1.8
    led_gain: float = 700.0
    sphere_sigma: float = 3.0
    sphere_gain: float = 150.0
    background: float = 12.0
    panel: float = 20.0
    noise: float = 2.0
    led_moves: bool = True
    chirp: bool = False
    bloom_gain: float = 0.0
    bloom_sigma: float = 4.5
    clutter: tuple[tuple[float, float, float], ...] = ()
    defocus_px: float = 0.0
    release_s: float | None = None
    stop_s: float | None = None
    seed: int = 0

    @property
    def frame_count(self) -> int:
        return round(self.duration_s * self.fps)


def pendulum_angle(scene: PendulumScene, t: np.ndarray) -> np.ndarray:
    if not scene.led_moves:
        return np.zeros_like(t)
    if scene.stop_s is not None:
        t = np.minimum(t, scene.stop_s)
    damping = -math.log(1 - scene.decay) / scene.duration_s
    omega = 2 * np.pi / scene.period_s
    if scene.release_s is not None:
        since = np.maximum(t - scene.release_s, 0.0)
        return scene.swing_rad * np.exp(-damping * since) * np.cos(omega * since)
    phase = omega * t
    if scene.chirp:
        # omega(t) = omega (1 - A(t)^2 / 16), A(t) = swing exp(-damping t), integrated from t = 0.
        decay = (1 - np.exp(-2 * damping * t)) / (2 * damping) if damping > 0 else t
        phase = phase - omega * scene.swing_rad**2 / 16 * decay
    return scene.swing_rad * np.exp(-damping * t) * np.sin(phase + scene.phase_rad)


def _arc(
    scene: PendulumScene, t: np.ndarray, centre: tuple[float, float], scale: float
) -> tuple[np.ndarray, np.ndarray]:
    angle = pendulum_angle(scene, t)
    arm = scale * scene.arm_px
    return centre[0] + arm * np.sin(angle), centre[1] - arm * (1 - np.cos(angle))


def led_positions(scene: PendulumScene, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return _arc(scene, t, scene.led_centre, 1.0)


def _blobs(
    scene: PendulumScene, x: np.ndarray, y: np.ndarray, weight: np.ndarray, sigma: float, shading: float
) -> np.ndarray:
    """Sum over axis 1 of weighted separable blobs; x, y, weight have shape (frames, terms)."""
    cols = np.arange(scene.width, dtype=np.float32)
    rows = np.arange(scene.height, dtype=np.float32)
    dx = (cols[None, None, :] - x[..., None].astype(np.float32)) / sigma
    dy = (rows[None, None, :] - y[..., None].astype(np.float32)) / sigma
    gx = np.exp(-0.5 * dx**2) * np.clip(1 - shading * dx, 0, None) * weight[..., None].astype(np.float32)
    gy = np.exp(-0.5 * dy**2) * np.clip(1 - shading * dy, 0, None)
    return np.einsum("nmh,nmw->nhw", gy, gx, optimize=True)


def sphere_samples(scene: PendulumScene, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For camera frames at times t: the LED times the display shows during each exposure, and the
    fraction of the exposure each is shown for; both (frames, terms)."""
    exposure = scene.exposure / scene.fps
    hold = 1 / scene.display_hz
    start, end = t - exposure / 2, t + exposure / 2
    first_hold = np.floor((start - scene.display_offset_s) / hold)
    holds = first_hold[:, None] + np.arange(math.ceil(exposure / hold) + 1)[None, :]
    hold_start = scene.display_offset_s + holds * hold
    overlap = np.minimum(end[:, None], hold_start + hold) - np.maximum(start[:, None], hold_start)
    return hold_start + hold / 2 - scene.latency_s, np.clip(overlap, 0, None) / exposure


@functools.lru_cache(maxsize=8)
def render(scene: PendulumScene) -> np.ndarray:
    """The video as (N, H, W) uint8 frames (read-only: copy before changing them)."""
    count = scene.frame_count
    t = np.arange(count) / scene.fps
    exposure = scene.exposure / scene.fps
    offsets = ((np.arange(LED_SUBSAMPLES) + 0.5) / LED_SUBSAMPLES - 0.5) * exposure
    led_x, led_y = led_positions(scene, t[:, None] + offsets[None, :])
    share = np.full(led_x.shape, 1 / LED_SUBSAMPLES)
    image = scene.led_gain * _blobs(scene, led_x, led_y, share, scene.led_sigma, 0.0)
    if scene.bloom_gain:
        image += scene.bloom_gain * _blobs(scene, led_x, led_y, share, scene.bloom_sigma, 0.0)

    sampled, weights = sphere_samples(scene, t)
    sphere_x, sphere_y = _arc(scene, sampled, scene.sphere_centre, scene.sphere_scale)
    image += scene.sphere_gain * _blobs(scene, sphere_x, sphere_y, weights, scene.sphere_sigma, 0.25)

    static = np.full((scene.height, scene.width), scene.background, dtype=np.float32)
    static[:, scene.width // 2 :] = scene.panel + np.linspace(0, 4, scene.height, dtype=np.float32)[:, None]
    cols, rows = np.meshgrid(np.arange(scene.width), np.arange(scene.height))
    for x, y, gain in scene.clutter:
        static += (gain * np.exp(-((cols - x) ** 2 + (rows - y) ** 2) / (2 * 2.5**2))).astype(np.float32)
    rng = np.random.default_rng(scene.seed)
    bank = scene.noise * rng.standard_normal((NOISE_BANK, scene.height, scene.width), dtype=np.float32)
    image += static + 0.5
    image += bank[rng.integers(NOISE_BANK, size=count)]
    if scene.defocus_px:
        for index in range(count):
            image[index] = cv2.GaussianBlur(image[index], (0, 0), scene.defocus_px)
    np.clip(image, 0, 255, out=image)
    frames = image.astype(np.uint8)
    frames.flags.writeable = False
    return frames


def write_mjpg(path: Path, frames: np.ndarray, fps: float) -> Path:
    """Write grey frames as 3-channel BGR into an MJPG .avi, as the rig's camera does."""
    height, width = frames.shape[1:3]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), fps, (width, height))
    for frame in frames:
        writer.write(cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR))
    writer.release()
    return path


def swing_signals(scene: PendulumScene) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal positions of the LED and the sphere as the camera would see them, without images."""
    t = np.arange(scene.frame_count) / scene.fps
    offsets = ((np.arange(LED_SUBSAMPLES) + 0.5) / LED_SUBSAMPLES - 0.5) * scene.exposure / scene.fps
    led_x, _ = led_positions(scene, t[:, None] + offsets[None, :])
    sampled, weights = sphere_samples(scene, t)
    sphere_x, _ = _arc(scene, sampled, scene.sphere_centre, scene.sphere_scale)
    return led_x.mean(axis=1), (weights * sphere_x).sum(axis=1)


def true_positions(scene: PendulumScene) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Centres (x, y) of the LED and of the displayed sphere at each frame time (no blur)."""
    t = np.arange(scene.frame_count) / scene.fps
    led_x, led_y = led_positions(scene, t)
    shown = (
        scene.display_offset_s
        + (np.floor((t - scene.display_offset_s) * scene.display_hz) + 0.5) / scene.display_hz
    )
    sphere_x, sphere_y = _arc(scene, shown - scene.latency_s, scene.sphere_centre, scene.sphere_scale)
    return led_x, led_y, sphere_x, sphere_y


@pytest.fixture
def scene() -> type[PendulumScene]:
    """The scene class; call it with the fields to change from the defaults."""
    return PendulumScene


@pytest.fixture
def render_video():
    return render


@pytest.fixture
def camera_signals():
    return swing_signals


@pytest.fixture
def mjpg_file():
    return write_mjpg


@pytest.fixture
def scene_truth():
    return true_positions
