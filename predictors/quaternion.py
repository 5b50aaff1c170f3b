"""Quaternion maths on float64 arrays of shape (..., 4): (w, x, y, z), Hamilton convention.

A unit quaternion q rotates a vector v (body into world) as q (0, v) q*. q and -q are the same
rotation. Functions that answer about rotations (`angle_between`, `to_rotation_vector`,
`to_axis_angle`, `to_matrix`, `rotate`, `slerp`) give the same answer for q and -q; functions that
answer about quaternions (`multiply`, `conjugate`, `log`) do not.

Two exponential maps, easy to confuse:

* `exp(v)` / `log(q)` are the quaternion exponential of the pure quaternion (0, v) and its inverse.
  |v| is *half* the rotation angle: `exp(v)` rotates by 2|v| about v/|v|, and `log` returns that
  half-angle vector, with |log(q)| in [0, pi].
* `from_rotation_vector(r)` / `to_rotation_vector(q)` use r = angle * axis, the full angle, with
  |r| in [0, pi] on the way out (the short way round): `from_rotation_vector(r) == exp(r / 2)`.

Every function that treats its input as a rotation normalises it first, so off-unit input (rounding
drift, a raw sensor value) is fine; a zero quaternion raises PredictorError. Small angles use
sinc / atan2 forms, so identical or nearly identical inputs never divide zero by zero.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from predictors.errors import PredictorError

_CONJUGATE_SIGNS = np.array([1.0, -1.0, -1.0, -1.0])
_IDENTITY_AXIS = np.array([1.0, 0.0, 0.0])
_PURE_PART = np.array([0.0, 1.0, 1.0, 1.0])


def _hamilton_table() -> np.ndarray:
    """(16, 4) matrix H with (p q)_i = sum_jk p_j q_k H[4 j + k, i]: the Hamilton product as one
    matmul of the outer product, which is as fast as any form on big batches and much faster
    than component-wise arithmetic on a single quaternion."""
    # (i, j, k, sign): component i of p q gains sign * p_j * q_k.
    terms = [
        (0, 0, 0, 1), (0, 1, 1, -1), (0, 2, 2, -1), (0, 3, 3, -1),
        (1, 0, 1, 1), (1, 1, 0, 1), (1, 2, 3, 1), (1, 3, 2, -1),
        (2, 0, 2, 1), (2, 1, 3, -1), (2, 2, 0, 1), (2, 3, 1, 1),
        (3, 0, 3, 1), (3, 1, 2, 1), (3, 2, 1, -1), (3, 3, 0, 1),
    ]
    table = np.zeros((16, 4))
    for i, j, k, sign in terms:
        table[4 * j + k, i] = sign
    return table


_HAMILTON = _hamilton_table()


def _last_axis(value: ArrayLike, size: int, what: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.ndim == 0 or array.shape[-1] != size:
        raise PredictorError(f"{what} must be an array of shape (..., {size}), got shape {array.shape}")
    return array


def _norm(array: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis, keeping it (shape (..., 1)) so it broadcasts back."""
    return np.sqrt(np.vecdot(array, array))[..., None]


def normalise(q: ArrayLike) -> np.ndarray:
    """q scaled to unit norm. Raises PredictorError if any quaternion has zero norm."""
    q = _last_axis(q, 4, "quaternion")
    n = _norm(q)
    if not n.all():
        raise PredictorError("a quaternion with zero norm is not a rotation; pass (1, 0, 0, 0) for none")
    return q / n


def conjugate(q: ArrayLike) -> np.ndarray:
    """(w, -x, -y, -z): the inverse rotation of a unit quaternion."""
    return _last_axis(q, 4, "quaternion") * _CONJUGATE_SIGNS


def multiply(p: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Hamilton product p q (rotate by q first, then by p); broadcasts over leading axes."""
    p = _last_axis(p, 4, "quaternion")
    q = _last_axis(q, 4, "quaternion")
    outer = p[..., :, None] * q[..., None, :]
    return outer.reshape(outer.shape[:-2] + (16,)) @ _HAMILTON


def canonical(q: ArrayLike) -> np.ndarray:
    """The one of q and -q whose first non-zero component is positive.

    That is w > 0 except for half turns (w == 0), where x, y, z break the tie, so
    canonical(q) == canonical(-q) exactly and a rotation has one canonical quaternion.
    """
    q = _last_axis(q, 4, "quaternion")
    first_nonzero = np.argmax(q != 0.0, axis=-1)[..., None]
    return np.where(np.take_along_axis(q, first_nonzero, axis=-1) < 0.0, -q, q)


def exp(v: ArrayLike) -> np.ndarray:
    """Quaternion exponential of the pure quaternion (0, v): (cos|v|, sin|v| v/|v|).

    A unit quaternion rotating by 2|v| about v/|v|; exp(0) is the identity.
    """
    v = _last_axis(v, 3, "vector")
    half_angle = _norm(v)
    sin_half = np.sin(half_angle)
    # sin|v| / |v| is accurate to rounding for any |v| > 0 (sin of a tiny x is x); only 0 is 0/0.
    sinc = np.divide(sin_half, half_angle, out=np.ones_like(half_angle), where=half_angle > 0.0)
    return np.concatenate([np.cos(half_angle), v * sinc], axis=-1)


def log(q: ArrayLike) -> np.ndarray:
    """Half-angle vector v of the (normalised) q, so exp(v) == q/|q|; |v| in [0, pi].

    Not sign-invariant: log(-q) != log(q). For q = -1 (a full turn) the axis is undefined and
    (pi, 0, 0) is returned.
    """
    q = normalise(q)
    w, vector = q[..., :1], q[..., 1:]
    # Near q = -1 the axis is multiplied by ~pi, so it must stay exact however small the vector
    # part is: scale by the largest component before squaring, so nothing underflows.
    largest = np.max(np.abs(vector), axis=-1, keepdims=True)
    direction = np.divide(vector, largest, out=np.zeros_like(vector), where=largest > 0.0)
    length = _norm(direction)
    axis = np.divide(direction, length, out=np.zeros_like(direction), where=length > 0.0)
    half_angle = np.arctan2(largest * length, w)
    full_turn = (largest == 0.0) & (w < 0.0)
    return np.where(full_turn, np.pi * _IDENTITY_AXIS, axis * half_angle)


def from_rotation_vector(r: ArrayLike) -> np.ndarray:
    """Unit quaternion rotating by |r| radians about r/|r|."""
    return exp(0.5 * _last_axis(r, 3, "rotation vector"))


def to_rotation_vector(q: ArrayLike) -> np.ndarray:
    """Rotation vector angle * axis of q, the short way round: angle in [0, pi]."""
    return 2.0 * log(canonical(q))


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> np.ndarray:
    """Unit quaternion rotating by `angle` radians (shape (...)) about `axis` (shape (..., 3)).

    The axis is normalised; a zero axis raises PredictorError.
    """
    axis = _last_axis(axis, 3, "axis")
    length = _norm(axis)
    if not length.all():
        raise PredictorError("a rotation axis must be non-zero; pass angle 0 about any axis for none")
    return from_rotation_vector(axis / length * np.asarray(angle, dtype=np.float64)[..., None])


def to_axis_angle(q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(unit axis (..., 3), angle (...) in [0, pi]) of q. The identity reports axis (1, 0, 0)."""
    r = to_rotation_vector(q)
    angle = _norm(r)
    axis = np.divide(r, angle, out=np.broadcast_to(_IDENTITY_AXIS, r.shape).copy(), where=angle > 0.0)
    return axis, angle[..., 0]


def to_matrix(q: ArrayLike) -> np.ndarray:
    """3x3 rotation matrix (..., 3, 3) of q: matrix @ v == rotate(q, v)."""
    q = normalise(q)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def from_matrix(m: ArrayLike) -> np.ndarray:
    """Canonical unit quaternion (see `canonical`) of a rotation matrix (..., 3, 3), by Shepperd's method.

    Of the four algebraically equal forms, each row uses the one whose pivot (4w^2, 4x^2, 4y^2 or
    4z^2) is largest, so no form loses precision near 180 degrees. `m` must be orthonormal.
    """
    m = np.asarray(m, dtype=np.float64)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise PredictorError(f"rotation matrix must have shape (..., 3, 3), got shape {m.shape}")
    m00, m01, m02 = m[..., 0, 0], m[..., 0, 1], m[..., 0, 2]
    m10, m11, m12 = m[..., 1, 0], m[..., 1, 1], m[..., 1, 2]
    m20, m21, m22 = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    # Candidate k is 4 * q_k * q; its k-th entry is the pivot 4 q_k^2.
    candidates = np.stack(
        [
            np.stack([1 + m00 + m11 + m22, m21 - m12, m02 - m20, m10 - m01], axis=-1),
            np.stack([m21 - m12, 1 + m00 - m11 - m22, m01 + m10, m02 + m20], axis=-1),
            np.stack([m02 - m20, m01 + m10, 1 - m00 + m11 - m22, m12 + m21], axis=-1),
            np.stack([m10 - m01, m02 + m20, m12 + m21, 1 - m00 - m11 + m22], axis=-1),
        ],
        axis=-2,
    )
    pivots = np.diagonal(candidates, axis1=-2, axis2=-1)
    best = np.argmax(pivots, axis=-1)[..., None, None]
    chosen = np.take_along_axis(candidates, best, axis=-2)[..., 0, :]
    return canonical(normalise(chosen))


def rotate(q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """v (..., 3) rotated by q (..., 4); broadcasts over leading axes."""
    q = normalise(q)
    v = _last_axis(v, 3, "vector")
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def angle_between(q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
    """Angle (...) in [0, pi] of the rotation taking q0 to q1; the same for either sign of each."""
    r = multiply(conjugate(normalise(q0)), normalise(q1))
    return 2.0 * np.arctan2(_norm(r[..., 1:])[..., 0], np.abs(r[..., 0]))


def great_circle(q0: ArrayLike, q1: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The great circle from q0 through q1, the short way: (half_angle (...), tangent (..., 4)).

    With half_angle = |log(q0* q1)| in [0, pi/2] (of q1 and -q1, the one nearer q0, so that
    q0 . q1 >= 0) and the unit tangent q0 (0, axis) orthogonal to q0, the circle is

        q(u) = cos(u half_angle) q0 + sin(u half_angle) tangent = q0 exp(u log(q0* q1)):

    q(0) = q0, q(1) = +-q1, unit-norm for every real u. Identical or antipodal inputs give
    half_angle 0 and a zero tangent (no motion). Computing the pair once lets a caller evaluate
    many u with one cos and one sin each.
    """
    q0 = normalise(q0)
    relative = multiply(conjugate(q0), normalise(q1))
    relative = np.where(relative[..., :1] < 0.0, -relative, relative)
    # relative = (cos h, sin h axis) with h in [0, pi/2]: its log is h axis, and the tangent is
    # q0 (0, axis) = q0 (0, sin h axis) / sin h.
    sin_half = _norm(relative[..., 1:])
    half_angle = np.arctan2(sin_half, relative[..., :1])
    scaled_tangent = multiply(q0, relative * _PURE_PART)
    tangent = np.divide(scaled_tangent, sin_half, out=np.zeros_like(scaled_tangent), where=sin_half > 0.0)
    return half_angle[..., 0], tangent


def slerp(q0: ArrayLike, q1: ArrayLike, u: ArrayLike) -> np.ndarray:
    """Spherical linear inter- and extrapolation from q0 (u = 0) to q1 (u = 1), for any real u.

    Equal to q0 exp(u log(q0* q1)) with the relative rotation q0* q1 taken the short way (q1
    flipped when q0 . q1 < 0): q and -q are the same endpoint, and however far u extrapolates the
    result stays unit-norm and is q0 followed by u times the rotation from q0 to q1, about a fixed
    axis (see `great_circle`).
    Broadcasts q0 (..., 4), q1 (..., 4) and u (...).
    """
    q0 = normalise(q0)
    half_angle, tangent = great_circle(q0, q1)
    phase = (np.asarray(u, dtype=np.float64) * half_angle)[..., None]
    return np.cos(phase) * q0 + np.sin(phase) * tangent
