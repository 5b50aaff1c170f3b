"""The candidate motion estimates of `adaptive`: two-sample velocity and Kalman smoothers of several
bandwidths, all kept relative to the newest sample.

Every candidate says where the pose is now and how fast it moves, as an *estimate*: two six-tuples

    ((offset of the orientation (3), angular velocity (3)), (offset of the position (3), velocity (3)))

where the offsets are world-frame rotation vector (rad) and displacement (m) from the newest
sample to the candidate's smoothed pose, and the velocities are world-frame (rad/s, m/s). A
candidate predicts h seconds after the newest sample q_n, p_n as

    q = exp((offset + h angular_velocity) / 2) q_n,   p = p_n + offset + h velocity

(a learned gain may scale the velocity term: `predictors.horizon_scores`). Keeping the offsets
relative to the newest sample lets one rotation vector per sample, the step r from the previous
newest sample to the new one (taken the short way, so a sign flip is no motion), serve every
candidate, with no quaternion arithmetic per candidate.

* `two-sample`: offset 0 and the velocity through the two newest samples: slerp extrapolation,
  constant velocity from the last two samples, exactly.
* `kalman-F`: a constant-velocity Kalman filter, per axis, whose noise ratio gives it a bandwidth
  of F Hz whatever the sample rate: with the measurement noise 1 per sample and white acceleration
  of density (2 pi F)^4 dt_mean, the continuous equivalent has natural frequency 2 pi F. Position
  and orientation share its covariance (`predictors.kinematic_covariance`), so one 2 x 2 factored
  covariance per bandwidth serves six axes. Over a step, the time update moves the offset by
  dt times the velocity, the new sample moves the origin by r, and the measurement update pulls
  the offset towards zero (the measurement is the new sample, at offset zero):

      a <- dt w + a + (dt w) x a / 2             (rotation vectors compose as log(exp x exp y) =
      a <- a - r - a x r / 2                      x + y + x X y / 2 to second order; exact when
                                                  the axes agree)
      a <- (1 - k0) a,   w <- w - k1 a_before    (k: the Kalman gain).

  The dropped third-order terms, |x|^2 |y| / 12, are below 1e-5 rad for a step of 0.05 rad and an
  offset of 0.05 rad; over 3 s of turning at 3 rad/s the smoothers follow the exact
  multiplicative filter of `predictors.kalman` to 1e-4 rad (tests/predictors/test_smoothers.py).

A low bandwidth smooths a noisy tracker and lags a sudden turn; a high one follows the motion and
passes the noise on. `adaptive` runs them all and, at each horizon, trusts the one whose errors
have turned out smallest.
"""

from __future__ import annotations

from math import pi

from predictors.kinematic_covariance import KinematicCovariance

BANDWIDTHS_HZ = (25.0, 10.0, 4.0)
"""The Kalman smoothers' bandwidths: a decade of smoothing, from following a clean 30 Hz tracker
closely to averaging a noisy 1000 Hz one."""

NAMES = ("two-sample", *(f"kalman-{f:g}Hz" for f in BANDWIDTHS_HZ))

# Weight of each new interval in the running mean interval that scales the smoothers' noise.
INTERVAL_RATE = 0.05
# Prior velocity variance at a (re)start, in units of (measurement noise / interval)^2: diffuse, so
# the first two samples set the velocity.
_DIFFUSE = 1e4

Motion = tuple[float, float, float, float, float, float]
Estimate = tuple[Motion, Motion]
Vector = tuple[float, float, float]

STILL: Estimate = ((0.0,) * 6, (0.0,) * 6)  # type: ignore[assignment]


class Smoothers:
    """The candidates of `NAMES`, advanced sample by sample; `estimates` is their current estimates,
    in the order of `NAMES`, and `interval` the running mean sample interval (s; 0 before two samples)."""

    __slots__ = ("estimates", "interval", "_filters", "_covariances", "_densities", "_moved")

    def __init__(self) -> None:
        self.estimates: tuple[Estimate, ...] = (STILL,) * len(NAMES)
        self.interval = 0.0
        # Per filter: [(orientation offset, angular velocity), (position offset, velocity)].
        self._filters: list[list[Motion]] = [[STILL[0], STILL[1]] for _ in BANDWIDTHS_HZ]
        self._covariances: list[KinematicCovariance] = []
        self._densities = tuple((2.0 * pi * f) ** 4 for f in BANDWIDTHS_HZ)
        # Whether any step has moved the position: until one has, every position estimate is
        # exactly zero (and the update would keep it so), so it is not computed.
        self._moved = False

    def advance(self, dt: float, r: Vector, rp: Vector, two_sample: Estimate) -> None:
        """A new newest sample dt >= 0 s after the last: it turned by r (rad) and moved by rp (m) from
        it; `two_sample` is the two-sample estimate through it. dt = 0 is a duplicate that replaces
        the newest sample: a second measurement, no time update."""
        if not self._covariances:
            if dt == 0.0:
                self.estimates = (two_sample, *self.estimates[1:])
                return
            self.interval = dt
            self._covariances = [KinematicCovariance(2, 1.0, 1.0, (1.0, _DIFFUSE / (dt * dt))) for _ in BANDWIDTHS_HZ]
        elif dt > 0.0:
            self.interval += INTERVAL_RATE * (dt - self.interval)
        interval = self.interval
        r0, r1, r2 = r
        s0, s1, s2 = rp
        moved = self._moved = self._moved or bool(s0 or s1 or s2)
        estimates: list[Estimate] = [two_sample]
        for covariance, density, state in zip(self._covariances, self._densities, self._filters):
            if dt > 0.0:
                covariance.density = density * interval
                covariance.predict(dt)
            k0, k1 = covariance.update()
            g = 1.0 - k0
            (a0, a1, a2, w0, w1, w2), moving = state
            # Time update, then the origin moved to the new sample (rotation vectors composed to
            # second order), then the measurement update at offset zero.
            u0, u1, u2 = dt * w0, dt * w1, dt * w2
            a0, a1, a2 = (
                a0 + u0 + 0.5 * (u1 * a2 - u2 * a1),
                a1 + u1 + 0.5 * (u2 * a0 - u0 * a2),
                a2 + u2 + 0.5 * (u0 * a1 - u1 * a0),
            )
            a0, a1, a2 = (
                a0 - r0 - 0.5 * (a1 * r2 - a2 * r1),
                a1 - r1 - 0.5 * (a2 * r0 - a0 * r2),
                a2 - r2 - 0.5 * (a0 * r1 - a1 * r0),
            )
            state[0] = turning = (g * a0, g * a1, g * a2, w0 - k1 * a0, w1 - k1 * a1, w2 - k1 * a2)
            if moved:
                b0, b1, b2, v0, v1, v2 = moving
                b0, b1, b2 = b0 + dt * v0 - s0, b1 + dt * v1 - s1, b2 + dt * v2 - s2
                state[1] = moving = (g * b0, g * b1, g * b2, v0 - k1 * b0, v1 - k1 * b1, v2 - k1 * b2)
            estimates.append((turning, moving))
        self.estimates = tuple(estimates)


def two_sample(dt: float, r: Vector, rp: Vector) -> Estimate:
    """The two-sample estimate: no offset, the velocity of turning by r and moving by rp in dt > 0 s."""
    return (0.0, 0.0, 0.0, r[0] / dt, r[1] / dt, r[2] / dt), (0.0, 0.0, 0.0, rp[0] / dt, rp[1] / dt, rp[2] / dt)
