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

from predictors import scalar_quaternion as squat
from predictors.checks import finite_time, no_sample_yet, non_negative_parameter, positive_parameter, read_sample
from predictors.kinematic_covariance import KinematicCovariance, damped_reach, damped_step
from predictors.pose import Pose, PoseSample

# Prior spread of the motion at a cold start or after a drop-out (the first sample gives the pose).
INITIAL_SPEED_STD = 1.0  # m/s
INITIAL_ACCELERATION_STD = 10.0  # m/s^2
INITIAL_ANGULAR_SPEED_STD = 3.0  # rad/s


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
    """Position filter + orientation filter behind the predictor protocol."""

    name = "kalman"

    def __init__(
        self,
        position_model: type[ConstantVelocityPosition] | type[ConstantAccelerationPosition],
        position_noise: float,
        position_drive: float,
        orientation_noise: float,
        angular_acceleration_noise: float,
        angular_velocity_damping: float,
        max_gap: float,
        max_horizon: float,
    ) -> None:
        self.position_noise = positive_parameter(position_noise, self.name, "position_noise", "metres")
        self.orientation_noise = positive_parameter(orientation_noise, self.name, "orientation_noise", "radians")
        self.angular_acceleration_noise = positive_parameter(
            angular_acceleration_noise, self.name, "angular_acceleration_noise", "rad/s^1.5"
        )
        self.angular_velocity_damping = non_negative_parameter(
            angular_velocity_damping, self.name, "angular_velocity_damping", "1/s"
        )
        self.max_gap = positive_parameter(max_gap, self.name, "max_gap", "seconds")
        self.max_horizon = positive_parameter(max_horizon, self.name, "max_horizon", "seconds")
        self._position_model = position_model
        self._position_drive = position_drive
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
        last = self._t
        if last is None:
            raise no_sample_yet(self.name)
        t = finite_time(t, self.name)
        h = t - last
        limit = self.max_horizon
        h = limit if h > limit else -limit if h < -limit else h
        return Pose(t, self._position.at(h), self._orientation.at(h))  # type: ignore[union-attr]

    def reset(self) -> None:
        """Forget every sample."""
        self._position = None
        self._orientation = None
        self._t = None


class KalmanCV(_KalmanPredictor):
    """Kalman filter, constant velocity in position and orientation (`kalman-cv`).

    Parameters (defaults suit a head-mounted tracker at 60 to 1000 Hz):
        position_noise: m, standard deviation of the tracker's position noise per axis.
        acceleration_noise: m/s^1.5, square root of the spectral density of the white
            acceleration that drives the velocity (velocity wanders by this times sqrt(seconds)).
        orientation_noise: rad, standard deviation of the tracker's orientation noise per axis.
        angular_acceleration_noise: rad/s^1.5, square root of the spectral density of the white
            angular acceleration that drives the angular velocity.
        angular_velocity_damping: 1/s, >= 0, the rate at which the angular velocity reverts to
            rest between its random changes (see the module docstring); 0, the default, keeps it
            constant. `rig tune` fits it.
        max_gap: s, a longer gap between samples restarts the filter from the next sample.
        max_horizon: s, predictions further than this from the newest sample (either way) are
            made for this horizon: a drop-out holds the motion instead of flying away.
    """

    name = "kalman-cv"

    def __init__(
        self,
        position_noise: float = 0.0005,
        acceleration_noise: float = 1.0,
        orientation_noise: float = 0.002,
        angular_acceleration_noise: float = 5.0,
        angular_velocity_damping: float = 0.0,
        max_gap: float = 1.0,
        max_horizon: float = 0.5,
    ) -> None:
        self.acceleration_noise = positive_parameter(acceleration_noise, self.name, "acceleration_noise", "m/s^1.5")
        super().__init__(
            ConstantVelocityPosition,
            position_noise,
            self.acceleration_noise,
            orientation_noise,
            angular_acceleration_noise,
            angular_velocity_damping,
            max_gap,
            max_horizon,
        )


class KalmanCA(_KalmanPredictor):
    """Kalman filter, constant acceleration in position, constant angular velocity (`kalman-ca`).

    Parameters as `kalman-cv`, with `jerk_noise` (m/s^2.5, square root of the spectral density of
    the white jerk that drives the acceleration) instead of acceleration_noise. Orientation keeps
    the (optionally damped) constant-angular-velocity model: angular acceleration is too noisy to
    extrapolate.
    """

    name = "kalman-ca"

    def __init__(
        self,
        position_noise: float = 0.0005,
        jerk_noise: float = 20.0,
        orientation_noise: float = 0.002,
        angular_acceleration_noise: float = 5.0,
        angular_velocity_damping: float = 0.0,
        max_gap: float = 1.0,
        max_horizon: float = 0.5,
    ) -> None:
        self.jerk_noise = positive_parameter(jerk_noise, self.name, "jerk_noise", "m/s^2.5")
        super().__init__(
            ConstantAccelerationPosition,
            position_noise,
            self.jerk_noise,
            orientation_noise,
            angular_acceleration_noise,
            angular_velocity_damping,
            max_gap,
            max_horizon,
        )
