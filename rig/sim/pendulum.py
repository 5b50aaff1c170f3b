"""The simulated pendulum: the ground-truth motion of the LED and the tracker sensor.

World frame: x to the right, y up, z towards the camera. The pendulum swings in the x-y plane
about the z axis through `pivot`. The bob, which carries both the LED and the tracker sensor, is at

    pivot + L * (sin(theta), -cos(theta), 0),

so theta > 0 puts the bob to the right (+x). The sensor's orientation is the rotation about +z by
theta: it is the identity at rest and turns the body's -y axis onto the pivot-to-bob direction.

The angle obeys the nonlinear pendulum with linear viscous damping,

    theta'' = -(g / L) sin(theta) - (omega0 / Q) theta',    omega0 = sqrt(g / L),

so for small swings the amplitude decays as exp(-omega0 t / (2 Q)). Q = inf means no damping.
A pendulum may also be held at rest at +amplitude and let go at a set time, as a lab releases it
while filming. The equation is integrated once, accurately (DOP853, rtol 1e-11, atol 1e-12), from
the release to the end of the time window; every query afterwards is a vectorised evaluation of
the integrator's dense output.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from rig.errors import ConfigError
from rig.sim.pendulum_config import PendulumConfig

if TYPE_CHECKING:
    from scipy.integrate import OdeSolution

_RTOL = 1e-11
_ATOL = 1e-12


class Pendulum:
    """The pendulum's motion over [t_start, t_end], integrated once at construction.

    t_release is when it is let go from rest at +amplitude; before it (with release_s set) the
    pendulum is held there. lookback_s: times this long before t_start may be asked for too (the
    pendulum held there; a search that looks past the run's start), the swing unchanged.
    """

    def __init__(self, config: PendulumConfig, t_end: float, t_start: float = 0.0, lookback_s: float = 0.0) -> None:
        if not (math.isfinite(t_start) and math.isfinite(t_end) and t_end > t_start):
            raise ConfigError(
                f"Pendulum needs finite times with t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}"
            )
        self.config = config
        self.t_start = float(t_start)
        self.t_end = float(t_end)
        self._lookback_s = float(lookback_s)
        self.length_m = config.resolved_length_m
        self.omega0 = math.sqrt(config.g / self.length_m)
        self.pivot = np.asarray(config.pivot, dtype=np.float64)
        self.amplitude_rad = math.radians(config.amplitude_deg)
        if config.release_s is not None:
            self.t_release = float(config.release_s)
        else:
            self.t_release = self.t_start - config.phase_deg / 360.0 * self.period_s
        # released after the window: held throughout, nothing to integrate
        self._solution = self._integrate() if self.t_release < self.t_end else None

    @property
    def period_s(self) -> float:
        """The exact undamped period at the release amplitude A: 4 sqrt(L / g) K(sin^2(A / 2))."""
        m = math.sin(self.amplitude_rad / 2.0) ** 2
        from scipy.special import ellipk

        return 4.0 / self.omega0 * float(ellipk(m))

    def _integrate(self) -> OdeSolution:
        w0_squared = self.omega0**2
        damping = 0.0 if math.isinf(self.config.quality) else self.omega0 / self.config.quality

        def rate(_t: float, y: np.ndarray) -> list[float]:
            theta, omega = y
            return [omega, -w0_squared * math.sin(theta) - damping * omega]

        from scipy.integrate import solve_ivp  # here: importing the rig's services need not load the integrators

        result = solve_ivp(
            rate,
            (self.t_release, self.t_end),
            [self.amplitude_rad, 0.0],
            method="DOP853",
            rtol=_RTOL,
            atol=_ATOL,
            dense_output=True,
        )
        if not result.success:
            raise ConfigError(f"the pendulum could not be integrated: {result.message}")
        return result.sol

    def _state(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        times = np.asarray(t, dtype=np.float64)
        first = self.t_start - self._lookback_s
        if not (np.all(times >= first) and np.all(times <= self.t_end)):
            bad = float(times[~((times >= first) & (times <= self.t_end))].ravel()[0])
            raise ConfigError(
                f"time {bad!r} s is outside the simulated window [{first!r}, {self.t_end!r}] s; "
                "build the Pendulum with a window that covers every time you ask for"
            )
        angle = np.full(times.shape, self.amplitude_rad)
        velocity = np.zeros(times.shape)
        moving = times > self.t_release
        if self._solution is not None and moving.any():
            state = self._solution(times[moving])
            angle[moving], velocity[moving] = state[0], state[1]
        return angle, velocity

    def angle(self, t: ArrayLike) -> np.ndarray:
        """theta(t) in radians, the shape of t."""
        return self._state(t)[0]

    def angular_velocity(self, t: ArrayLike) -> np.ndarray:
        """theta'(t) in radians per second, the shape of t."""
        return self._state(t)[1]

    def led_position(self, t: ArrayLike) -> np.ndarray:
        """The bob's position in metres, shape t.shape + (3,)."""
        return self._bob_position(self.angle(t))

    def sensor_pose(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The sensor's positions, shape t.shape + (3,), and orientations (w, x, y, z), t.shape + (4,)."""
        theta = self.angle(t)
        half = theta / 2.0
        zeros = np.zeros_like(theta)
        orientation = np.stack([np.cos(half), zeros, zeros, np.sin(half)], axis=-1)
        return self._bob_position(theta), orientation

    def _bob_position(self, theta: np.ndarray) -> np.ndarray:
        offset = np.stack([np.sin(theta), -np.cos(theta), np.zeros_like(theta)], axis=-1)
        return self.pivot + self.length_m * offset
