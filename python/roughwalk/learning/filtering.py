"""D_good = {(x, y) : g(y) < g_max}: keep the solutions worth imitating (Melon 2020, eq. 4).

Solving from the heuristic guess ends in a long tail of poor local minima
(Melon 2020, Fig. 6); Melon et al. set g_max at the start of that tail by
eye. Here it is Tukey's upper fence of the feasible solutions' log-costs,
Q3 + 1.5·IQR, the usual definition of where outliers begin, computed on the
logarithm because costs are positive and skewed; it can be overridden.
Solutions that violate the constraints count as beyond any threshold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.learning.dataset import Dataset

__all__ = ["FilterResult", "cost_threshold", "feasible_mask", "filter_good", "VIOLATION_TOL"]

VIOLATION_TOL = 1e-3
"""Largest constraint violation (constraints' units) of a solution kept as feasible."""


@dataclass(frozen=True)
class FilterResult:
    """Which rows passed the filter and why.

    Attributes
    ----------
    g_max:
        The cost threshold.
    automatic:
        Whether g_max was found from the costs (else given).
    good:
        (n,) mask of D_good.
    feasible:
        (n,) mask of the feasible solutions.

    """

    g_max: float
    automatic: bool
    good: NDArray[np.bool_]
    feasible: NDArray[np.bool_]

    @property
    def n_good(self) -> int:
        """Size of D_good."""
        return int(self.good.sum())


def feasible_mask(data: Dataset, tol: float = VIOLATION_TOL) -> NDArray[np.bool_]:
    """Rows whose solution has a finite cost and violates no constraint by more than ``tol``."""
    cost = np.asarray(data["cost"], dtype=float)
    viol = np.asarray(data["max_violation"], dtype=float)
    return np.isfinite(cost) & np.isfinite(viol) & (viol <= tol)


def cost_threshold(costs: NDArray[np.float64]) -> float:
    """g_max at the start of the costs' upper tail: exp(Q3 + 1.5·IQR) of log(cost).

    Costs ≤ 0 (no cost terms) give the largest cost: nothing is an outlier.
    """
    values = np.asarray(costs, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        raise InvalidArgumentError("no finite cost to set g_max from (no feasible solution)")
    if np.any(values <= 0):
        return float(values.max())
    logs = np.log(values)
    q1, q3 = np.percentile(logs, [25.0, 75.0])
    return float(np.exp(q3 + 1.5 * (q3 - q1)))


def filter_good(data: Dataset, g_max: float | None = None) -> FilterResult:
    """D_good of ``data``: feasible rows with cost below ``g_max`` (default: found)."""
    feasible = feasible_mask(data)
    automatic = g_max is None
    threshold = cost_threshold(data["cost"][feasible]) if g_max is None else float(g_max)
    good = feasible & (np.asarray(data["cost"], dtype=float) <= threshold)
    return FilterResult(threshold, automatic, good, feasible)
