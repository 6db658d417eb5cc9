"""Closed forms of Melon et al.'s integral cost on cubic Hermite polynomials (Melon 2020, Eq. 1).

On one polynomial of duration d, with x(s) = Σₖ aₖ sᵏ,

    ∫₀ᵈ ((x − x_ref)² + ω_d ẋ²) ds
        = Σⱼ,ₖ bⱼ bₖ d^(j+k+1)/(j+k+1) + ω_d Σⱼ,ₖ cⱼ cₖ d^(j+k+1)/(j+k+1),

where b are x's coefficients with x_ref taken off the constant and c those of
ẋ: a polynomial in the node values, rational in d. The cost may penalise the
spline's value (forces) or its derivative (base velocities); then x is the
spline's derivative and ẋ its second derivative.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import casadi as ca

from roughwalk.trajopt.variables.hermite import hermite_coefficients

__all__ = [
    "integral_of_square",
    "derivative_coefficients",
    "melon_integral",
    "melon_integral_function",
]


def integral_of_square(coefficients: Sequence[Any], d: Any) -> Any:
    """∫₀ᵈ (Σₖ aₖ sᵏ)² ds."""
    total: Any = 0.0
    n = len(coefficients)
    for j in range(n):
        for k in range(n):
            total = total + coefficients[j] * coefficients[k] * d ** (j + k + 1) / (j + k + 1)
    return total


def derivative_coefficients(coefficients: Sequence[Any]) -> list[Any]:
    """Coefficients of the derivative of Σₖ aₖ sᵏ."""
    return [k * coefficients[k] for k in range(1, len(coefficients))]


def melon_integral(
    coefficients: Sequence[Any], d: Any, reference: Any, derivative_weight: Any
) -> Any:
    """∫₀ᵈ ((x − ref)² + ω_d ẋ²) ds for x(s) = Σₖ aₖ sᵏ (scalar coefficients)."""
    shifted = [coefficients[0] - reference, *coefficients[1:]]
    value = integral_of_square(shifted, d)
    rate = integral_of_square(derivative_coefficients(coefficients), d)
    return value + derivative_weight * rate


@functools.cache
def melon_integral_function(order: int) -> ca.Function:
    """SX function (x0, v0, x1, v1, d, direction (3), ref, ω_d) → Eq. 1 on one polynomial.

    The penalised quantity is direction · x⁽ᵒʳᵈᵉʳ⁾(s) for the 3-D Hermite
    polynomial through (x0, v0) and (x1, v1): order 0 for a force (its
    magnitude along a direction), 1 for a velocity.
    """
    x0, v0, x1, v1 = (ca.SX.sym(n, 3) for n in ("x0", "v0", "x1", "v1"))
    d, ref, weight = ca.SX.sym("d"), ca.SX.sym("ref"), ca.SX.sym("w_d")
    direction = ca.SX.sym("direction", 3)
    a = hermite_coefficients(x0, v0, x1, v1, d)
    scalar = [ca.dot(direction, ak) for ak in a]
    for _ in range(order):
        scalar = derivative_coefficients(scalar)
    out = melon_integral(scalar, d, ref, weight)
    return ca.Function("melon_integral", [x0, v0, x1, v1, d, direction, ref, weight], [out])
