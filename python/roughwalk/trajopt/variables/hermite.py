"""Cubic Hermite polynomials: the pieces every spline of the NLP is made of.

A polynomial of duration d is fixed by its start and end values x₀, x₁ and
derivatives v₀, v₁ (Melon 2020, §III-A; Winkler 2018, §V). The formulas use
only +, −, ·, /, so they work on floats, numpy arrays and CasADi symbols alike.
"""

from __future__ import annotations

from typing import Any

__all__ = ["hermite_coefficients", "hermite_point", "polynomial_value"]


def hermite_coefficients(x0: Any, v0: Any, x1: Any, v1: Any, d: Any) -> tuple[Any, Any, Any, Any]:
    """Coefficients (a₀, a₁, a₂, a₃) of x(s) = a₀ + a₁s + a₂s² + a₃s³, s ∈ [0, d] [s]."""
    a2 = (3.0 * (x1 - x0) - d * (2.0 * v0 + v1)) / (d * d)
    a3 = (2.0 * (x0 - x1) + d * (v0 + v1)) / (d * d * d)
    return x0, v0, a2, a3


def polynomial_value(coefficients: tuple[Any, ...], s: Any) -> Any:
    """Σ aₖ sᵏ by Horner's rule."""
    out = coefficients[-1]
    for a in reversed(coefficients[:-1]):
        out = out * s + a
    return out


def hermite_point(x0: Any, v0: Any, x1: Any, v1: Any, d: Any, s: Any) -> tuple[Any, Any, Any]:
    """Position, velocity and acceleration at local time s [s] of a polynomial of duration d [s]."""
    a0, a1, a2, a3 = hermite_coefficients(x0, v0, x1, v1, d)
    pos = a0 + s * (a1 + s * (a2 + s * a3))
    vel = a1 + s * (2.0 * a2 + s * 3.0 * a3)
    acc = 2.0 * a2 + 6.0 * a3 * s
    return pos, vel, acc
