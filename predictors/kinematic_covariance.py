"""The covariance of a kinematic Kalman filter, one axis at a time, kept in factored form.

The model, per axis, with state x = (position, velocity) for order 2 (constant velocity) or
(position, velocity, acceleration) for order 3 (constant acceleration), driven by continuous white
noise of spectral density `density` on the highest derivative, observed in position with noise
variance `measurement_variance`; over a step of dt seconds

    x' = F x + w,   F = exp(A dt) (1, dt, dt^2/2 ...),   w ~ N(0, Q),  Q = density * integral of
         exp(A s) b b^T exp(A s)^T ds over [0, dt]      (Bar-Shalom's continuous white-noise model)
    z  = x[0] + v,  v ~ N(0, measurement_variance).

Why one covariance for three axes: when the noise is isotropic and all three coordinates are
measured together, the x, y and z filters see the same F, Q, H and R, and the covariance update
does not depend on the measured values, so all three share one covariance exactly. Propagating one
n x n matrix instead of a 3n x 3n one is what makes the filter as cheap as double exponential
smoothing (LaViola's Kalman filter cost 135 times more).

Why factored: the covariance is never stored. It is kept as P = L D L^T, L unit lower triangular,
D diagonal and positive (Bierman and Thornton's U-D filter, in lower form):

* symmetry is structural, whatever rounding does;
* the time update is Thornton's modified weighted Gram-Schmidt: each new D entry is a weighted sum
  of squares with positive weights, never a difference, so D stays positive (P positive definite)
  for any dt, including 1 microsecond and hours, over any number of steps;
* the measurement update of the first state is exact and trivial in this form: only d0 changes,
  d0' = d0 r / (d0 + r) (the Schur complement of d0 is unchanged by observing x[0]), and the gain
  is (d0 / (d0 + r)) times the first column of L.

Joseph's form would also keep P symmetric positive definite, at about four times the cost of the
update here; re-symmetrising a stored P fixes symmetry but not definiteness.

Q's factors are closed forms: Q = density * dt * S C S with S = diag(dt^(n-1), ..., dt, 1) and C a
constant matrix whose L D L^T factors are tabulated below.

Damped velocity (order 2 only, `predict_damped`): the velocity decays towards zero at `damping`
(1/s, beta) between its random kicks, dv = -beta v dt + dW, an Ornstein-Uhlenbeck velocity
(Singer's manoeuvring-target model). With x = beta dt, one step is

    F = [[1, reach], [0, decay]],  reach = (1 - e^-x) / beta,  decay = e^-x,
    Q = density * [[dt^3 g(x), dt^2 h(x)^2 / 2], [dt^2 h(x)^2 / 2, dt h(x) (1 + e^-x) / 2]]

with h(x) = (1 - e^-x) / x and g(x) = (x - 3/2 + 2 e^-x - e^-2x / 2) / x^3, both 1 and 1/3 at x = 0,
where the model is the constant-velocity one exactly. `damped_step` evaluates them; g cancels to
x^3 / 3 from terms of size x, so below `SERIES_BELOW` it is summed as its power series instead.
Its factors are no longer constants: the 2 x 2 L D L^T of Q is taken per step, which is safe, since
det Q / Q11 is a quarter of Q22 or more (no cancellation beyond two bits).
"""

from __future__ import annotations

from math import exp, expm1

import numpy as np

# C[i][j] = 1 / ((2n - 1 - i - j) (n - 1 - i)! (n - 1 - j)!) and its factors, written out below:
# order 2: C = [[1/3, 1/2], [1/2, 1]],  L = [[1], [3/2, 1]],  D = (1/3, 1/4);
# order 3: C = [[1/20, 1/8, 1/6], [1/8, 1/3, 1/2], [1/6, 1/2, 1]],
#          L = [[1], [5/2, 1], [10/3, 4, 1]],  D = (1/20, 1/48, 1/9).
# With S, L_Q = S L S^-1 (entry i, j divided by dt^(i - j)) and D_Q = density * dt * D * S^2.
_ORDERS = (2, 3)

# Below this x = beta dt, g(x) is summed as its series 1/3 - x/4 + 7x^2/60 - x^3/24 + 31x^4/2520 -
# x^5/320, whose first dropped term is below 1e-13 relative there; above it the closed form loses at
# most 3e-16 / x^2 < 1e-12 relative to cancellation.
SERIES_BELOW = 0.02


# One step of the damped-velocity model: (reach, decay, Q00, Q01, Q11), F = [[1, reach], [0, decay]]
# and Q / density. A plain tuple: a NamedTuple would cost a third of a microsecond per sample.
DampedStep = tuple[float, float, float, float, float]


def damped_reach(h: float, damping: float) -> float:
    """How far (in s of the current velocity) a damped velocity carries in h seconds (h may be
    negative): (1 - e^(-damping h)) / damping, and h itself without damping. Written as h times
    (1 - e^-x) / x, x = damping h, as in `damped_step`: dividing by a subnormal damping instead
    would round to a reach beyond h."""
    x = damping * h
    return h if x == 0.0 else h * (-expm1(-x) / x)


def damped_step(dt: float, damping: float) -> DampedStep:
    """F and Q / density of the damped-velocity model (see the module docstring) over dt > 0 s."""
    x = damping * dt
    a = -expm1(-x)  # 1 - e^-x, to full relative precision for small x
    decay = exp(-x)
    h = a / x if x > 0.0 else 1.0
    if x < SERIES_BELOW:
        g = 1.0 / 3.0 + x * (-0.25 + x * (7.0 / 60.0 + x * (-1.0 / 24.0 + x * (31.0 / 2520.0 - x / 320.0))))
    else:
        g = (x - a - 0.5 * a * a) / (x * x * x)
    return (dt * h, decay, dt * dt * dt * g, 0.5 * dt * dt * h * h, 0.5 * dt * h * (1.0 + decay))


class KinematicCovariance:
    """The shared per-axis covariance of an order-2 or order-3 kinematic filter, as P = L D L^T.

    `predict(dt)` is the time update and `update()` the measurement update; both mutate in place.
    Units are those of the state: with positions in metres, `density` is in m^2/s^3 (order 2) or
    m^2/s^5 (order 3) and the variances are in m^2, (m/s)^2, (m/s^2)^2.
    """

    __slots__ = ("order", "density", "measurement_variance", "_l", "_d")

    def __init__(self, order: int, density: float, measurement_variance: float, initial: tuple[float, ...]) -> None:
        if order not in _ORDERS:
            raise ValueError(f"order must be 2 or 3, got {order!r}")
        if len(initial) != order:
            raise ValueError(f"initial needs {order} variances, got {len(initial)}")
        self.order = order
        self.density = density
        self.measurement_variance = measurement_variance
        # Independent initial errors: L = I, D = the initial variances.
        self._l = [[0.0] * order for _ in range(order)]
        self._d = list(initial)

    def predict(self, dt: float) -> None:
        """Time update over dt > 0 seconds: P <- F P F^T + Q, by weighted Gram-Schmidt."""
        if self.order == 2:
            self._predict_order_2(dt)
        else:
            self._predict_order_3(dt)

    def _predict_order_2(self, dt: float) -> None:
        l10 = self._l[1][0]
        d0, d1 = self._d
        q = self.density * dt
        # Columns of A = [F L | Lq] with weights (d0, d1, q0, q1); rows a0, a1 of A.
        q0, q1 = q * dt * dt / 3.0, q / 4.0
        lq = 1.5 / dt
        a00, a01 = 1.0 + dt * l10, dt
        a10 = l10
        new_d0 = d0 * a00 * a00 + d1 * a01 * a01 + q0
        new_l10 = (d0 * a10 * a00 + d1 * a01 + q0 * lq) / new_d0
        b0, b1, b2 = a10 - new_l10 * a00, 1.0 - new_l10 * a01, lq - new_l10
        new_d1 = d0 * b0 * b0 + d1 * b1 * b1 + q0 * b2 * b2 + q1
        self._l[1][0] = new_l10
        self._d[0], self._d[1] = new_d0, new_d1

    def _predict_order_3(self, dt: float) -> None:
        _, (l10, _, _), (l20, l21, _) = self._l
        d0, d1, d2 = self._d
        h = 0.5 * dt * dt
        q = self.density * dt
        # A = [F L | L_Q], weights (d0, d1, d2, e0, e1, e2); rows a0, a1, a2 written out.
        e0, e1, e2 = q * dt**4 / 20.0, q * dt * dt / 48.0, q / 9.0
        q10, q20, q21 = 2.5 / dt, (10.0 / 3.0) / (dt * dt), 4.0 / dt
        a00, a01, a02 = 1.0 + dt * l10 + h * l20, dt + h * l21, h
        a10, a11, a12 = l10 + dt * l20, 1.0 + dt * l21, dt
        a20, a21 = l20, l21
        # Step 0: b0 = a0.
        n0 = d0 * a00 * a00 + d1 * a01 * a01 + d2 * a02 * a02 + e0
        m10 = (d0 * a10 * a00 + d1 * a11 * a01 + d2 * a12 * a02 + e0 * q10) / n0
        m20 = (d0 * a20 * a00 + d1 * a21 * a01 + d2 * a02 + e0 * q20) / n0
        b10, b11, b12, b13 = a10 - m10 * a00, a11 - m10 * a01, a12 - m10 * a02, q10 - m10
        c20, c21, c22, c23 = a20 - m20 * a00, a21 - m20 * a01, 1.0 - m20 * a02, q20 - m20
        # Step 1: b1 = a1 - m10 b0 (last two columns 1, 0).
        n1 = d0 * b10 * b10 + d1 * b11 * b11 + d2 * b12 * b12 + e0 * b13 * b13 + e1
        m21 = (d0 * c20 * b10 + d1 * c21 * b11 + d2 * c22 * b12 + e0 * c23 * b13 + e1 * q21) / n1
        # Step 2: b2 = a2 - m20 b0 - m21 b1 (last column 1).
        b20, b21, b22, b23, b24 = c20 - m21 * b10, c21 - m21 * b11, c22 - m21 * b12, c23 - m21 * b13, q21 - m21
        n2 = d0 * b20 * b20 + d1 * b21 * b21 + d2 * b22 * b22 + e0 * b23 * b23 + e1 * b24 * b24 + e2
        lower = self._l
        lower[1][0], lower[2][0], lower[2][1] = m10, m20, m21
        self._d[0], self._d[1], self._d[2] = n0, n1, n2

    def predict_damped(self, step: DampedStep) -> None:
        """Time update of an order-2 covariance over one step of the damped-velocity model
        (`damped_step`): P <- F P F^T + density Q, by weighted Gram-Schmidt as `predict`."""
        l10 = self._l[1][0]
        d0, d1 = self._d
        reach, decay, s00, s01, s11 = step
        # Q = Lq Dq Lq^T per step; then the columns of A = [F L | Lq], weights (d0, d1, q0, q1).
        lq = s01 / s00
        q0 = self.density * s00
        q1 = self.density * (s11 - s01 * lq)
        a00, a01 = 1.0 + reach * l10, reach
        a10, a11 = decay * l10, decay
        new_d0 = d0 * a00 * a00 + d1 * a01 * a01 + q0
        new_l10 = (d0 * a10 * a00 + d1 * a11 * a01 + q0 * lq) / new_d0
        b0, b1, b2 = a10 - new_l10 * a00, a11 - new_l10 * a01, lq - new_l10
        new_d1 = d0 * b0 * b0 + d1 * b1 * b1 + q0 * b2 * b2 + q1
        self._l[1][0] = new_l10
        self._d[0], self._d[1] = new_d0, new_d1

    def update(self) -> tuple[float, ...]:
        """Measurement update for an observation of state 0; returns the Kalman gain (n,)."""
        d0 = self._d[0]
        k0 = d0 / (d0 + self.measurement_variance)
        self._d[0] = d0 * self.measurement_variance / (d0 + self.measurement_variance)
        lower = self._l
        if self.order == 2:
            return (k0, k0 * lower[1][0])
        return (k0, k0 * lower[1][0], k0 * lower[2][0])

    def matrix(self) -> np.ndarray:
        """P = L D L^T as an (n, n) array (for tests and diagnostics, not for the real-time path).

        Its lower triangle is computed and mirrored, so rounding in the product cannot make the
        array asymmetric: P is symmetric by construction.
        """
        lower = np.eye(self.order) + np.tril(np.array(self._l), -1)
        product = np.tril(lower @ np.diag(self._d) @ lower.T)
        return product + np.tril(product, -1).T

    def diagonal_factor(self) -> tuple[float, ...]:
        """D of P = L D L^T: all entries positive is P positive definite."""
        return tuple(self._d)
