"""Joint speeds near their limits as a CHOMP term.

The paper only checks the velocity limits after CHOMP and lengthens the step
if they are broken (Zucker 2011, §5.3). A swing leg that must lift higher in
the same time is then pushed to the limit exactly where it descends onto its
target; this term lets the optimiser trade such a late dash for an earlier
lift instead. With D_t = q_{t+1} − q_t over the sample period dt,

    f = ½·w·h·Σ_t Σ_j max(0, |D_tj|/dt − ρ·v_j)²,

zero while every joint stays below the fraction ρ of its limit v_j.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["joint_speed_cost"]


def joint_speed_cost(
    q: ArrayLike, dt: float, limit: ArrayLike, fraction: float, weight: float
) -> tuple[float, NDArray[np.float64]]:
    """Value and gradient (T − 2, J) w.r.t. the interior samples of joint angles q (T, J) [rad].

    ``limit`` (J,) [rad/s]; ``weight`` is w·h; the first and last samples are fixed.
    """
    x = np.asarray(q, dtype=float)
    v = np.asarray(limit, dtype=float)
    d = np.diff(x, axis=0)
    excess = np.maximum(np.abs(d) / dt - fraction * v, 0.0)
    value = 0.5 * weight * float(np.sum(excess**2))
    g_d = weight * excess * np.sign(d) / dt  # ∂f/∂D_t
    grad = g_d[:-1] - g_d[1:]  # q_t enters D_{t−1} with +1 and D_t with −1
    return value, grad
