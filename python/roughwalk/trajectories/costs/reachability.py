"""Kinematic reachability as a CHOMP term (Zucker 2011, §3.2 and §5.3).

When a supporting foot f cannot be reached, IK returns the closest reachable
foot f′ and e = f − f′. The paper moves the trunk by the "virtual force"
Δx = α·Σe_i, ω = β·Σ(f′_i − x) × e_i. That is exactly the descent direction of
½·Σ‖e_i‖²: f′ is the closest reachable point, so by the envelope theorem
∂(½‖e‖²)/∂x = −e and ∂(½‖e‖²)/∂ω = −(f − x) × e (= −(f′ − x) × e). CHOMP adds
the term like the obstacle cost, covariantly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["reachability_cost"]


def reachability_cost(
    errors: ArrayLike,
    feet: ArrayLike,
    base_pos: ArrayLike,
    rate_matrix: ArrayLike,
    active: ArrayLike,
    weight: float,
) -> tuple[float, NDArray[np.float64]]:
    """½·w·Σ‖e‖² over active legs and its gradient w.r.t. (x, rpy) (n, 6).

    Parameters
    ----------
    errors:
        e = f − FK(IK(f)) (n, 4, 3) [m], world frame.
    feet:
        Foot targets f (n, 4, 3) [m].
    base_pos:
        Trunk positions x (n, 3) [m].
    rate_matrix:
        E(rpy) (n, 3, 3), ω = E·d(rpy).
    active:
        (n, 4) which legs are supporting.
    weight:
        w.
    """
    e = np.where(np.asarray(active, dtype=bool)[..., None], np.asarray(errors, dtype=float), 0.0)
    f = np.asarray(feet, dtype=float)
    x = np.asarray(base_pos, dtype=float)
    value = 0.5 * weight * float(np.sum(e * e))
    g_x = -weight * e.sum(axis=1)
    g_w = -weight * np.cross(f - x[:, None, :], e).sum(axis=1)
    g_rpy = np.einsum("nij,ni->nj", np.asarray(rate_matrix, dtype=float), g_w)
    return value, np.concatenate([g_x, g_rpy], axis=1)
