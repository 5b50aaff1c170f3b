"""Quaternion maths on plain Python floats, for the real-time path of the predictors.

A predictor runs `update` and `predict` once per tracker sample and display frame, inside the same
process that renders, with a budget of a few microseconds. numpy pays about a microsecond of call
overhead per operation whatever the array size, so on one quaternion the vectorised functions of
`predictors.quaternion` cost more than the arithmetic itself; here the same maths is written out on
floats, where an operation costs tens of nanoseconds. `predictors.quaternion` stays the reference:
the tests check these functions against it.

Quaternions are tuples (w, x, y, z), Hamilton convention, as in `predictors.quaternion`. Rotation
vectors are full-angle (angle * axis, radians), like `quaternion.from_rotation_vector`.
"""

from __future__ import annotations

from math import atan2, cos, sin, sqrt

Quaternion = tuple[float, float, float, float]

IDENTITY: Quaternion = (1.0, 0.0, 0.0, 0.0)


def multiply(a: Quaternion, b: Quaternion) -> Quaternion:
    """Hamilton product a b (rotate by b first, then by a)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def normalised(q: Quaternion) -> Quaternion:
    """q scaled to unit norm; q must be non-zero."""
    w, x, y, z = q
    scale = 1.0 / sqrt(w * w + x * x + y * y + z * z)
    return (w * scale, x * scale, y * scale, z * scale)


def rotated_by(rx: float, ry: float, rz: float, q: Quaternion) -> Quaternion:
    """exp(r / 2) q: q followed by the world-frame rotation vector r (radians), renormalised.

    The half-angle sine over the angle uses sin(h) / h, exact to rounding for any h > 0, and the
    series limit at h == 0, so zero rotation returns q bit for bit.
    """
    half_angle = 0.5 * sqrt(rx * rx + ry * ry + rz * rz)
    if half_angle == 0.0:
        return q
    c = cos(half_angle)
    s = 0.5 * sin(half_angle) / half_angle
    ew, ex, ey, ez = c, s * rx, s * ry, s * rz
    w, x, y, z = q
    w, x, y, z = (
        ew * w - ex * x - ey * y - ez * z,
        ew * x + ex * w + ey * z - ez * y,
        ew * y - ex * z + ey * w + ez * x,
        ew * z + ex * y - ey * x + ez * w,
    )
    scale = 1.0 / sqrt(w * w + x * x + y * y + z * z)
    return (w * scale, x * scale, y * scale, z * scale)


def rotation_vector_between(a: Quaternion, b: Quaternion) -> tuple[float, float, float]:
    """The world-frame rotation vector r, |r| in [0, pi], with b == +-exp(r / 2) a: the short way.

    a and b must be unit quaternions. q and -q give the same answer, so a tracker that flips the
    sign of its quaternion between samples reads as the small motion it is.
    """
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    # d = b a*, the rotation taking a to b in the world frame.
    dw = bw * aw + bx * ax + by * ay + bz * az
    dx = -bw * ax + bx * aw - by * az + bz * ay
    dy = -bw * ay + bx * az + by * aw - bz * ax
    dz = -bw * az - bx * ay + by * ax + bz * aw
    if dw < 0.0:
        dw, dx, dy, dz = -dw, -dx, -dy, -dz
    sin_half = sqrt(dx * dx + dy * dy + dz * dz)
    if sin_half == 0.0:
        return (0.0, 0.0, 0.0)
    scale = 2.0 * atan2(sin_half, dw) / sin_half
    return (dx * scale, dy * scale, dz * scale)


def great_circle(q0: Quaternion, q1: Quaternion) -> tuple[float, Quaternion]:
    """(half_angle, tangent) of the great circle from q0 through q1, the short way.

    The same pair as `predictors.quaternion.great_circle`: q(u) = cos(u h) q0 + sin(u h) tangent
    passes through q0 at u = 0 and +-q1 at u = 1, h in [0, pi/2]. Identical or antipodal inputs give
    h = 0 and a zero tangent.
    """
    aw, ax, ay, az = q0
    bw, bx, by, bz = q1
    # r = q0* q1, the rotation from q0 to q1 in q0's frame, taken with r_w >= 0.
    rw = aw * bw + ax * bx + ay * by + az * bz
    rx = aw * bx - ax * bw - ay * bz + az * by
    ry = aw * by + ax * bz - ay * bw - az * bx
    rz = aw * bz - ax * by + ay * bx - az * bw
    if rw < 0.0:
        rw, rx, ry, rz = -rw, -rx, -ry, -rz
    sin_half = sqrt(rx * rx + ry * ry + rz * rz)
    if sin_half == 0.0:
        return 0.0, (0.0, 0.0, 0.0, 0.0)
    half_angle = atan2(sin_half, rw)
    rx, ry, rz = rx / sin_half, ry / sin_half, rz / sin_half
    # tangent = q0 (0, axis)
    return half_angle, (
        -ax * rx - ay * ry - az * rz,
        aw * rx + ay * rz - az * ry,
        aw * ry - ax * rz + az * rx,
        aw * rz + ax * ry - ay * rx,
    )


def slerp(q0: Quaternion, q1: Quaternion, u: float) -> Quaternion:
    """Spherical linear inter- and extrapolation, q0 at u = 0, +-q1 at u = 1, the short way.

    Equal inputs (or no rotation between them) give q0 itself, bit for bit.
    """
    if q0 == q1:
        return q0
    half_angle, (tw, tx, ty, tz) = great_circle(q0, q1)
    if half_angle == 0.0:
        return q0
    phase = u * half_angle
    c, s = cos(phase), sin(phase)
    w, x, y, z = q0
    return normalised((c * w + s * tw, c * x + s * tx, c * y + s * ty, c * z + s * tz))
