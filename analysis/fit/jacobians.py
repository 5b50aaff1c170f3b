"""The Jacobians of the fit's weighted residuals, analytic, from the model's basis and its slopes
(``model.basis_slopes``): that of the projected residual, which Levenberg-Marquardt steps on, and
that in all 5 + 16 parameters, whose Gauss-Newton information gives the fit's covariance.

With A the weighted design, c = (A'A)^-1 A'y the linear solution and r = y - A c, a non-linear
parameter p moves the residual by dr/dp = -(A_p c + A c_p), where A_p is the design's derivative
and A'A c_p = A_p' r - A' A_p c (Golub and Pereyra 1973; the full derivative, not Kaufman's
approximation). In all parameters the columns are -A_p c for the non-linear ones and -A for the
linear ones. Both are exact up to rounding, so they agree with JAX's automatic derivative of the
same residuals to about 1e-12 relative (tests/analysis/fit/test_jacobians.py).
"""

from __future__ import annotations

import numpy as np

from analysis.fit import model


def projected_residual_and_jacobian(
    params: np.ndarray, structure: model.Structure, data: model.FitData
) -> tuple[np.ndarray, np.ndarray]:
    """(the projected residual (2N,), its Jacobian (2N, 5) in the scaled non-linear parameters)."""
    weighted, target, normal, rhs = model.normal_equations(model.basis(params, structure, data), structure, data, data.w)
    coefficients = np.linalg.solve(normal, rhs)
    per_signal = np.einsum("kbi,i->kb", model.PLACEMENT, coefficients)
    residual = target - np.einsum("knb,kb->kn", weighted, per_signal)
    slopes = model.basis_slopes(params, structure, data) * data.w.reshape(1, 2, -1, 1)
    moved = np.einsum("pknb,kb->pkn", slopes, per_signal)
    pulled = np.einsum("pknb,kn->pkb", slopes, residual) - np.einsum("knb,pkn->pkb", weighted, moved)
    coefficient_slopes = np.linalg.solve(normal, np.einsum("kbi,pkb->ip", model.PLACEMENT, pulled))
    refit = np.einsum("knb,kbp->pkn", weighted, np.einsum("kbi,ip->kbp", model.PLACEMENT, coefficient_slopes))
    return residual.reshape(-1), -(moved + refit).reshape(5, -1).T


def full_jacobian(
    params: np.ndarray, coefficients: np.ndarray, structure: model.Structure, data: model.FitData
) -> np.ndarray:
    """(2N, 21) the Jacobian of ``model.full_residual`` in all parameters, non-linear first."""
    functions = model.basis(params, structure, data)
    weights = data.w.reshape(1, 2, -1, 1)
    per_signal = np.einsum("kbi,i->kb", model.PLACEMENT, coefficients)
    moved = np.einsum("pknb,kb->pkn", model.basis_slopes(params, structure, data) * weights, per_signal)
    columns = np.einsum("knb,kbi->kni", functions * weights[0], model.PLACEMENT)
    return -np.concatenate([moved.reshape(5, -1).T, columns.reshape(-1, 16)], axis=1)
