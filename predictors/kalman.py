"""Kalman-filter predictors: constant velocity (`kalman-cv`) and constant acceleration (`kalman-ca`).

Position: per axis, a linear Kalman filter of the continuous white-noise kinematic model (white
acceleration for constant velocity, white jerk for constant acceleration), discretised with the
true time step of each sample; the three axes share one covariance (see
`predictors.kinematic_covariance`, which also says how it stays symmetric positive definite).

Orientation: a multiplicative (error-state) Kalman filter on the unit quaternion q with the world
angular velocity w (rad/s) in the state and white angular acceleration driving it, the angular
velocity optionally damped towards rest at `angular_velocity_damping` (beta, 1/s; 0 by default):

    time update    q <- exp(w c / 2) q,  w <- e^(-beta dt) w,  c = (1 - e^(-beta dt)) / beta
                   (c = dt without damping; the quaternion exponential is exact for the modelled
                   w and always unit norm)
    residual       r = rotation vector from q to the measured quaternion, the short way (|r| <= pi),
                   so a tracker that flips the quaternion's sign reads as no motion
    update         q <- exp(K_theta r / 2) q,  w <- w + K_w r.

Why damping: a head turns, then stops. Its angular velocity reverts to zero within a fraction of a
second, so extrapolating the current velocity unchanged over 20 to 100 ms overshoots at the end of
every turn. The Ornstein-Uhlenbeck angular velocity (Singer's manoeuvring-target model, see
`predictors.kinematic_covariance`) says so with one rate: a prediction h ahead carries the velocity
(1 - e^(-beta h)) / beta seconds instead of h. On the recorded head motion in `data/traces`, a
damping fitted on the first 60% (3 to 4.5 per second, by horizon) lowers the error on the rest at
20, 50 and 100 ms below two-sample slerp extrapolation's, which the noise ratio alone does not do
at 20 ms (tests/predictors/test_real_trace.py). With beta = 0 the model is the constant-velocity
one, bit for bit.

The error state is (world-frame attitude error, angular-velocity error) per axis. Its exact
transport over a step rotates the attitude error by exp(w dt); that rotation is dropped from the
covariance (not from the mean), which keeps the three axes independent with one shared 2 x 2
covariance, just as for position. The neglected term is of order |w dt| times the anisotropy of the
covariance, and the covariance is isotropic whenever the noises are: at 300 deg/s and 60 Hz the
ellipsoid it would turn is a sphere turned by 5 degrees. The JAX twin (`predictors.jax_filters`)
implements the same model.

Samples are taken in sensor-time order: a sample older than the newest one is dropped (it says
nothing about where the pose is going that the newer one has not said); a sample at the newest
one's time is a second measurement of the same state (measurement update, no time update); a gap
longer than `max_gap` restarts the filter from the new sample, since the motion before a drop-out
says little about the motion after it.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from declared import Range
from predictors import scalar_quaternion as squat
from predictors.checks import horizon, read_sample
from predictors.kinematic_covariance import KinematicCovariance, damped_reach, damped_step
from predictors.params import LOG, MAX_GAP, MAX_HORIZON, Param, ParamSet, declare_params
from predictors.pose import Pose, PoseSample

# Prior spread of the motion at a cold start or after a drop-out (the first sample gives the pose).
INITIAL_SPEED_STD = 1.0  # m/s
INITIAL_ACCELERATION_STD = 10.0  # m/s^2
INITIAL_ANGULAR_SPEED_STD = 3.0  # rad/s

# The parameters of the Kalman predictors, which `auto` shares. Only the process noises and the
# damping are fitted: the predicted means depend on the noises only through their ratio, so the
# measurement noises stay as the tracker's datasheet (or the default) gives them.
POSITION_NOISE = Param(
    "position_noise", 0.0005, "metres",
    "Standard deviation of the tracker's position noise per axis: from a nanometre (an interferometer) to a metre.",
    Range(1e-9, 1.0, True, True), LOG, acts_on="position",
)
ACCELERATION_NOISE = Param(
    "acceleration_noise", 1.0, "m/s^1.5",
    "Square root of the spectral density of the white acceleration that drives the velocity "
    "(velocity wanders by this times sqrt(seconds)).",
    Range(1e-6, 1e4, True, True), LOG, trainable=True, acts_on="position",
)
JERK_NOISE = Param(
    "jerk_noise", 20.0, "m/s^2.5",
    "Square root of the spectral density of the white jerk that drives the acceleration.",
    Range(1e-6, 1e6, True, True), LOG, trainable=True, acts_on="position",
)
ORIENTATION_NOISE = Param(
    "orientation_noise", 0.002, "radians",
    "Standard deviation of the tracker's orientation noise per axis: from a nanoradian to half a turn.",
    Range(1e-9, math.pi, True, True), LOG, acts_on="orientation",
)
ANGULAR_ACCELERATION_NOISE = Param(
    "angular_acceleration_noise", 5.0, "rad/s^1.5",
    "Square root of the spectral density of the white angular acceleration that drives the angular velocity.",
    Range(1e-6, 1e5, True, True), LOG, trainable=True, acts_on="orientation",
)
ANGULAR_VELOCITY_DAMPING = Param(
    "angular_velocity_damping", 0.0, "1/s",
    "The rate at which the angular velocity reverts to rest between its random changes (see "
    "`predictors.kalman`); 0 keeps it constant. From 0, tuning starts at a rate slow against the "
    "horizons tuned for, which predicts almost as the undamped model while giving the loss a slope in it.",
    Range(0.0, 1e4, True, True), LOG, trainable=True, acts_on="orientation", tune_from=1.0,
)


class ConstantVelocityPosition:
    """Position and velocity per axis; `step` returns the squared one-step prediction error (m^2)."""

    __slots__ = ("covariance", "x", "y", "z", "vx", "vy", "vz")

    def __init__(self, noise: float, acceleration_noise: float, position: tuple[float, float, float]) -> None:
        self.covariance = KinematicCovariance(
            2, acceleration_noise**2, noise**2, (noise**2, INITIAL_SPEED_STD**2)
        )
        self.x, self.y, self.z = position
        self.vx = self.vy = self.vz = 0.0

    def step(self, dt: float, measured: tuple[float, float, float]) -> float:
        """Time update over dt >= 0 s, then measurement update with `measured` (m)."""
        if dt > 0.0:
            self.covariance.predict(dt)
            self.x += dt * self.vx
            self.y += dt * self.vy
            self.z += dt * self.vz
        ex, ey, ez = measured[0] - self.x, measured[1] - self.y, measured[2] - self.z
        k0, k1 = self.covariance.update()
        self.x += k0 * ex
        self.y += k0 * ey
        self.z += k0 * ez
        self.vx += k1 * ex
        self.vy += k1 * ey
        self.vz += k1 * ez
        return ex * ex + ey * ey + ez * ez

    def at(self, h: float) -> tuple[float, float, float]:
        """The position h seconds after the newest sample."""
        return (self.x + h * self.vx, self.y + h * self.vy, self.z + h * self.vz)


class ConstantAccelerationPosition:
    """Position, velocity and acceleration per axis; `step` returns the squared one-step error (m^2)."""

    __slots__ = ("covariance", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az")

    def __init__(self, noise: float, jerk_noise: float, position: tuple[float, float, float]) -> None:
        self.covariance = KinematicCovariance(
            3, jerk_noise**2, noise**2, (noise**2, INITIAL_SPEED_STD**2, INITIAL_ACCELERATION_STD**2)
        )
        self.x, self.y, self.z = position
        self.vx = self.vy = self.vz = 0.0
        self.ax = self.ay = self.az = 0.0

    def step(self, dt: float, measured: tuple[float, float, float]) -> float:
        """Time update over dt >= 0 s, then measurement update with `measured` (m)."""
        if dt > 0.0:
            self.covariance.predict(dt)
            h = 0.5 * dt * dt
            self.x += dt * self.vx + h * self.ax
            self.y += dt * self.vy + h * self.ay
            self.z += dt * self.vz + h * self.az
            self.vx += dt * self.ax
            self.vy += dt * self.ay
            self.vz += dt * self.az
        ex, ey, ez = measured[0] - self.x, measured[1] - self.y, measured[2] - self.z
        k0, k1, k2 = self.covariance.update()
        self.x += k0 * ex
        self.y += k0 * ey
        self.z += k0 * ez
        self.vx += k1 * ex
        self.vy += k1 * ey
        self.vz += k1 * ez
        self.ax += k2 * ex
        self.ay += k2 * ey
        self.az += k2 * ez
        return ex * ex + ey * ey + ez * ez

    def at(self, h: float) -> tuple[float, float, float]:
        """The position h seconds after the newest sample."""
        g = 0.5 * h * h
        return (
            self.x + h * self.vx + g * self.ax,
            self.y + h * self.vy + g * self.ay,
            self.z + h * self.vz + g * self.az,
        )


class OrientationFilter:
    """The multiplicative orientation filter, its angular velocity damped at `damping` (1/s, >= 0);
    `step` returns the squared one-step error (rad^2)."""

    __slots__ = ("covariance", "damping", "q", "wx", "wy", "wz")

    def __init__(
        self, noise: float, angular_acceleration_noise: float, orientation: squat.Quaternion, damping: float = 0.0
    ) -> None:
        self.covariance = KinematicCovariance(
            2, angular_acceleration_noise**2, noise**2, (noise**2, INITIAL_ANGULAR_SPEED_STD**2)
        )
        self.damping = damping
        self.q = orientation
        self.wx = self.wy = self.wz = 0.0

    def step(self, dt: float, measured: squat.Quaternion) -> float:
        """Time update over dt >= 0 s, then measurement update with the unit quaternion `measured`."""
        if dt > 0.0:
            if self.damping == 0.0:
                self.covariance.predict(dt)
                self.q = squat.rotated_by(dt * self.wx, dt * self.wy, dt * self.wz, self.q)
            else:
                motion = damped_step(dt, self.damping)
                self.covariance.predict_damped(motion)
                reach, decay = motion[0], motion[1]
                self.q = squat.rotated_by(reach * self.wx, reach * self.wy, reach * self.wz, self.q)
                self.wx *= decay
                self.wy *= decay
                self.wz *= decay
        rx, ry, rz = squat.rotation_vector_between(self.q, measured)
        k0, k1 = self.covariance.update()
        self.q = squat.rotated_by(k0 * rx, k0 * ry, k0 * rz, self.q)
        self.wx += k1 * rx
        self.wy += k1 * ry
        self.wz += k1 * rz
        return rx * rx + ry * ry + rz * rz

    def at(self, h: float) -> squat.Quaternion:
        """The orientation h seconds after the newest sample."""
        reach = damped_reach(h, self.damping)
        return squat.rotated_by(reach * self.wx, reach * self.wy, reach * self.wz, self.q)


class _KalmanPredictor:
    """Position filter + orientation filter behind the predictor protocol; a subclass names its
    position model and the parameter that drives it."""

    name = "kalman"
    params: ClassVar[ParamSet]
    _position_model: type[ConstantVelocityPosition] | type[ConstantAccelerationPosition]
    _position_drive_param: Param

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self._position_drive = getattr(self, self._position_drive_param.name)
        self._position: ConstantVelocityPosition | ConstantAccelerationPosition | None = None
        self._orientation: OrientationFilter | None = None
        self._t: float | None = None

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample (see the module docstring for the order rules)."""
        t, position, orientation = read_sample(sample, self.name)
        last = self._t
        if last is None or t - last > self.max_gap:
            self._position = self._position_model(self.position_noise, self._position_drive, position)
            self._orientation = OrientationFilter(
                self.orientation_noise, self.angular_acceleration_noise, orientation, self.angular_velocity_damping
            )
            self._t = t
            return
        dt = t - last
        if dt < 0.0:
            return
        self._position.step(dt, position)  # type: ignore[union-attr]
        self._orientation.step(dt, orientation)  # type: ignore[union-attr]
        self._t = t

    def predict(self, t: float) -> Pose:
        """The pose at t (s): the model run forward (or back) from the newest sample, at most
        max_horizon seconds."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        return Pose(t, self._position.at(h), self._orientation.at(h))  # type: ignore[union-attr]

    def reset(self) -> None:
        """Forget every sample."""
        self._position = None
        self._orientation = None
        self._t = None


@declare_params(
    POSITION_NOISE, ACCELERATION_NOISE, ORIENTATION_NOISE, ANGULAR_ACCELERATION_NOISE, ANGULAR_VELOCITY_DAMPING,
    MAX_GAP, MAX_HORIZON,
)
class KalmanCV(_KalmanPredictor):
    """Kalman filter, constant velocity in position and orientation (`kalman-cv`).

    The defaults suit a head-mounted tracker at 60 to 1000 Hz; `rig tune` fits the process noises
    and the damping to a recording.
    """

    name = "kalman-cv"
    _position_model = ConstantVelocityPosition
    _position_drive_param = ACCELERATION_NOISE


@declare_params(
    POSITION_NOISE, JERK_NOISE, ORIENTATION_NOISE, ANGULAR_ACCELERATION_NOISE, ANGULAR_VELOCITY_DAMPING,
    MAX_GAP, MAX_HORIZON,
)
class KalmanCA(_KalmanPredictor):
    """Kalman filter, constant acceleration in position, constant angular velocity (`kalman-ca`).

    As `kalman-cv`, with white jerk driving the acceleration instead of white acceleration driving
    the velocity. Orientation keeps the (optionally damped) constant-angular-velocity model:
    angular acceleration is too noisy to extrapolate.
    """

    name = "kalman-ca"
    _position_model = ConstantAccelerationPosition
    _position_drive_param = JERK_NOISE
