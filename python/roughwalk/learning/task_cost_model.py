"""A g_max per task: the cost a task's solution should reach, predicted from the task.

One global g_max (:func:`~roughwalk.learning.filtering.cost_threshold`)
treats every task alike, but costs differ by task: on the single pallet a
start 1.5 m before the edge walks further and climbs later than one 0.5 m
before it, and its optimum costs more than the global g_max although no
initialiser finds a lower one. A poor local minimum is a cost well above
what *this* task costs. :class:`TaskCostModel` predicts log g(y*) from the
task by least squares on quadratic features of (start, goal), fitted on
feasible solutions (refitted once without the rows beyond the first fit's
fence, so that poor minima do not lift the prediction), and sets the fence,
like the global one, at Tukey's Q3 + 1.5·IQR, of the residuals log g − ĝ.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["TaskCostModel"]


def _features(tasks: ArrayLike) -> NDArray[np.float64]:
    """[1, z, z zᵀ (upper triangle)] of the (n, 6) start/goal rows z."""
    z = np.atleast_2d(np.asarray(tasks, dtype=float))
    i, j = np.triu_indices(z.shape[1])
    return np.column_stack([np.ones(len(z)), z, z[:, i] * z[:, j]])


def _fence(residuals: NDArray[np.float64]) -> float:
    q1, q3 = np.percentile(residuals, [25.0, 75.0])
    return float(q3 + 1.5 * (q3 - q1))


@dataclass(frozen=True)
class TaskCostModel:
    """log g(task) ≈ φ(task)ᵀ w, and the fence above it where poor minima begin.

    Attributes
    ----------
    coefficients:
        w, over the quadratic features of the 6 task numbers (start x, y,
        yaw, goal x, y, yaw) [m, m, rad].
    log_fence:
        Residual log g − ĝ beyond which a cost is a poor minimum (a factor
        exp(log_fence) above the prediction).
    n_fit:
        Solutions the fit used.

    """

    coefficients: tuple[float, ...]
    log_fence: float
    n_fit: int

    @classmethod
    def fit(cls, tasks: ArrayLike, costs: ArrayLike) -> TaskCostModel:
        """Fit on (n, 6) tasks and their feasible solutions' costs (> 0)."""
        x = _features(tasks)
        log_cost = np.log(np.asarray(costs, dtype=float))
        if len(log_cost) < x.shape[1] or not np.all(np.isfinite(log_cost)):
            raise InvalidArgumentError(
                f"a task cost model needs at least {x.shape[1]} positive finite costs, "
                f"got {len(log_cost)}"
            )
        keep = np.ones(len(log_cost), dtype=bool)
        for _ in range(2):
            w = np.linalg.lstsq(x[keep], log_cost[keep], rcond=None)[0]
            residual = log_cost - x @ w
            fence = _fence(residual[keep])
            keep = residual <= fence
        return cls(tuple(float(v) for v in w), fence, int(keep.sum()))

    def predict(self, tasks: ArrayLike) -> NDArray[np.float64]:
        """Predicted cost ĝ per task."""
        return np.asarray(np.exp(_features(tasks) @ np.asarray(self.coefficients)))

    def threshold(self, tasks: ArrayLike) -> NDArray[np.float64]:
        """g_max per task: the prediction times exp(log_fence)."""
        return self.predict(tasks) * float(np.exp(self.log_fence))

    def to_dict(self) -> dict[str, Any]:
        """Plain data for a model header."""
        return {
            "features": "quadratic in (start x, y, yaw, goal x, y, yaw), log cost",
            "coefficients": list(self.coefficients),
            "log_fence": self.log_fence,
            "n_fit": self.n_fit,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TaskCostModel:
        """The model written by :meth:`to_dict`."""
        return cls(
            tuple(float(v) for v in data["coefficients"]),
            float(data["log_fence"]),
            int(data["n_fit"]),
        )
