"""Quaternion maths in JAX for the predictors' twins (`predictors.jax_filters`): (w, x, y, z),
Hamilton, the same operations as the real-time `predictors.scalar_quaternion`, written to be safe
to differentiate at zero rotation (series forms below a tiny angle)."""

from __future__ import annotations

import jax
import jax.numpy as jnp

Array = jax.Array

_SMALL = 1e-8  # below this angle (rad) the series forms of sin(x)/x and x/sin(x) are exact in float64


def _multiply(a: Array, b: Array) -> Array:
    aw, ax, ay, az = a[0], a[1], a[2], a[3]
    bw, bx, by, bz = b[0], b[1], b[2], b[3]
    return jnp.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def rotated_by(r: Array, q: Array) -> Array:
    """exp(r / 2) q, renormalised: q followed by the world rotation vector r."""
    squared = jnp.dot(r, r)
    small = squared < _SMALL**2
    half = 0.5 * jnp.sqrt(jnp.where(small, 1.0, squared))
    sinc = jnp.where(small, 0.5 - squared / 48.0, 0.5 * jnp.sin(half) / half)
    cos = jnp.where(small, 1.0 - squared / 8.0, jnp.cos(half))
    turned = _multiply(jnp.concatenate([cos[None], sinc * r]), q)
    return turned / jnp.linalg.norm(turned)


def rotation_vector_between(a: Array, b: Array) -> Array:
    """World rotation vector r, |r| <= pi, with b = +-exp(r / 2) a."""
    d = _multiply(b, a * jnp.array([1.0, -1.0, -1.0, -1.0]))
    d = jnp.where(d[0] < 0.0, -d, d)
    squared = jnp.dot(d[1:], d[1:])
    small = squared < _SMALL**2
    sin_half = jnp.sqrt(jnp.where(small, 1.0, squared))
    scale = jnp.where(small, 2.0 / d[0], 2.0 * jnp.arctan2(sin_half, d[0]) / sin_half)
    return scale * d[1:]


def slerp(q0: Array, q1: Array, u: Array) -> Array:
    """q0 exp(u log(q0* q1)), the short way, renormalised: the real-time `slerp`."""
    relative = _multiply(q0 * jnp.array([1.0, -1.0, -1.0, -1.0]), q1)
    relative = jnp.where(relative[0] < 0.0, -relative, relative)
    squared = jnp.dot(relative[1:], relative[1:])
    still = (squared == 0.0) | jnp.all(q0 == q1)
    sin_half = jnp.sqrt(jnp.where(still, 1.0, squared))
    half_angle = jnp.arctan2(sin_half, relative[0])
    axis = relative[1:] / sin_half
    tangent = _multiply(q0, jnp.concatenate([jnp.zeros(1), axis]))
    phase = u * half_angle
    moved = jnp.cos(phase) * q0 + jnp.sin(phase) * tangent
    moved = moved / jnp.linalg.norm(moved)
    # No rotation between them: q0 itself, as the real-time slerp returns.
    return jnp.where(still, q0, moved)
