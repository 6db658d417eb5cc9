"""D_good = {(x, y) : g(y) < g_max}: keep the solutions worth imitating (Melon 2020, eq. 4).

Solving from the heuristic guess ends in a long tail of poor local minima
(Melon 2020, Fig. 6); Melon et al. set g_max at the start of that tail by
eye. Here it is Tukey's upper fence, Q3 + 1.5·IQR, of the feasible
solutions' log-costs (costs are positive and skewed), with the quartiles
taken from the lower half only: Q3 is mirrored from Q1 about the median.
Poor minima only ever lie above the good solutions, so a tail holding a
quarter of the solves drags Q3 and the IQR up and the plain fence ends
beyond the tail it should mark (single pallet, session 5: at 6.8, above
all but one of 353 costs); the lower half is clean, and on a symmetric
body both fences agree. It can be overridden.

With enough solutions (:data:`MIN_TASK_FIT`) training filters with a
per-task g_max instead (:class:`~roughwalk.learning.task_cost_model.TaskCostModel`):
costs differ by task (far starts cost more), and one threshold for all
tasks either keeps the poor minima of cheap tasks or drops the costly tasks.
Solutions that violate the constraints count as beyond any threshold.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.learning.dataset import Dataset
from roughwalk.learning.task_cost_model import TaskCostModel

__all__ = [
    "FilterResult",
    "best_per_task",
    "cost_threshold",
    "feasible_mask",
    "filter_good",
    "fit_task_cost",
    "MIN_TASK_FIT",
    "VIOLATION_TOL",
]

VIOLATION_TOL = 1e-3
"""Largest constraint violation (constraints' units) of a solution kept as feasible."""

MIN_TASK_FIT = 100
"""Feasible solutions needed before training filters with a per-task g_max.

The cost model has 28 quadratic features; with fewer than a few times as
many solutions its fence measures its own overfit, not the tasks' spread.
"""


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

    Q3 and the IQR are those of the lower half mirrored about the median
    (Q3 = 2·median − Q1): a heavy upper tail cannot move them.
    Costs ≤ 0 (no cost terms) give the largest cost: nothing is an outlier.
    """
    values = np.asarray(costs, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        raise InvalidArgumentError("no finite cost to set g_max from (no feasible solution)")
    if np.any(values <= 0):
        return float(values.max())
    logs = np.log(values)
    q1, median = np.percentile(logs, [25.0, 50.0])
    q3 = 2.0 * median - q1
    return float(np.exp(q3 + 1.5 * (q3 - q1)))


def fit_task_cost(data: Dataset) -> TaskCostModel | None:
    """A per-task g_max from ``data``'s feasible solutions; None below :data:`MIN_TASK_FIT`."""
    feasible = feasible_mask(data)
    if int(feasible.sum()) < MIN_TASK_FIT:
        return None
    tasks = np.column_stack([data["start"], data["goal"]])
    return TaskCostModel.fit(tasks[feasible], np.asarray(data["cost"], dtype=float)[feasible])


def filter_good(
    data: Dataset, g_max: float | None = None, *, task_cost: TaskCostModel | None = None
) -> FilterResult:
    """D_good of ``data``: feasible rows with cost below ``g_max`` (default: found).

    With ``task_cost`` and no ``g_max``, a row is kept below its own task's
    g_max instead (the result's ``g_max`` is still the global one, for the
    record).
    """
    feasible = feasible_mask(data)
    automatic = g_max is None
    cost = np.asarray(data["cost"], dtype=float)
    threshold = cost_threshold(cost[feasible]) if g_max is None else float(g_max)
    limit: NDArray[np.float64] | float = threshold
    if automatic and task_cost is not None:
        limit = task_cost.threshold(np.column_stack([data["start"], data["goal"]]))
    good = feasible & (cost <= limit)
    return FilterResult(threshold, automatic, good, feasible)


def best_per_task(datasets: Sequence[Dataset]) -> Dataset:
    """One row per task index: its best solve over ``datasets`` (Algorithm 1's re-solves).

    Re-solving a task from a later round's guess gives a second solution of
    the same task; the best one is kept: a feasible solution before an
    infeasible one, then the lower cost; on a tie the earlier dataset's.
    """
    if not datasets:
        raise InvalidArgumentError("no dataset given")
    best: dict[int, tuple[tuple[bool, float], int]] = {}
    for k, data in enumerate(datasets):
        feasible = feasible_mask(data)
        cost = np.asarray(data["cost"], dtype=float)
        for row, index in enumerate(np.asarray(data["index"]).tolist()):
            key = (not bool(feasible[row]), float(cost[row]) if np.isfinite(cost[row]) else np.inf)
            if index not in best or key < best[index][0]:
                best[int(index)] = (key, k)
    out: Dataset | None = None
    for k, data in enumerate(datasets):
        chosen = [i for i, (_, source) in best.items() if source == k]
        part = data.select(np.isin(data["index"], chosen))
        if len(part):
            out = part if out is None else out.append(part)
    assert out is not None  # every task has a best row in some dataset
    return out
