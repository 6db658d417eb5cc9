"""Training solutions kept in the model: the guess for a task is its nearest one's solution.

An MLP's guess is an average of neighbouring solutions, and no solution of
any task: every category is off by a little (held out, single pallet: base
positions 18 % of their spread over the tasks, forces 55 %, IPOPT's
constraint multipliers 75 %), and each category alone, put into an exact
solution, costs IPOPT 4–10 iterations. The nearest training task's
solution, with its own multipliers, is a KKT point of a problem that
differs only in the start: on 20 held-out single-pallet tasks it took
median 11.5 iterations against 15 from the MLP, at the same or a lower
cost, but it ended more than 2 % above the best known cost on 24 % of 50
held-out tasks against 14 % from the MLP: the nearest task's solution may
lie in another basin than the best for this task. Among the ``candidates``
nearest tasks (10), the library therefore picks the solution nearest the
network's guess, whose basin is the better one more often (the network is
trained on each task's best-known solution): median 12 iterations (mean
12.5 against 16.8), 14 % above the best, as the MLP. The library holds
D_good's tasks, solution vectors and constraint multipliers (float32); the
task distance is over the task features divided by their spread in the
library, the solution distance over the network's output scale.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["SolutionLibrary", "farthest"]

_MIN_SPREAD = 1e-9


@dataclass(frozen=True)
class SolutionLibrary:
    """Solved tasks and their solutions, looked up by the nearest task.

    Attributes
    ----------
    tasks:
        (n, n_features) task features (start x, y, yaw; goal x, y, yaw).
    x:
        (n, n_variables) solution vectors.
    lam_g:
        (n, n_constraints) IPOPT's constraint multipliers at the solutions.
    scale:
        (n_features,) divisor of each feature in the distance: its spread
        over ``tasks`` (1 where a feature does not vary, e.g. a fixed goal).
    candidates:
        How many nearest tasks :meth:`pick` chooses among.

    """

    tasks: NDArray[np.float64]
    x: NDArray[np.float32]
    lam_g: NDArray[np.float32]
    scale: NDArray[np.float64]
    candidates: int = 10

    def __post_init__(self) -> None:
        n = self.tasks.shape[0]
        if n == 0 or self.x.shape[0] != n or self.lam_g.shape[0] != n:
            raise InvalidArgumentError(
                f"a solution library needs as many (≥ 1) tasks, solutions and multipliers, "
                f"got {n}, {self.x.shape[0]} and {self.lam_g.shape[0]}"
            )
        if self.scale.shape != (self.tasks.shape[1],):
            raise InvalidArgumentError(
                f"the library's scale has shape {self.scale.shape}, "
                f"its tasks {self.tasks.shape[1]} features"
            )
        if self.candidates < 1:
            raise InvalidArgumentError(f"candidates must be ≥ 1, got {self.candidates}")

    @classmethod
    def build(
        cls, tasks: ArrayLike, x: ArrayLike, lam_g: ArrayLike, candidates: int = 10
    ) -> SolutionLibrary:
        """A library of these solutions; the distance scale is the tasks' spread."""
        t = np.atleast_2d(np.asarray(tasks, dtype=float))
        spread = t.std(axis=0)
        return cls(
            t,
            np.asarray(x, dtype=np.float32),
            np.asarray(lam_g, dtype=np.float32),
            np.where(spread > _MIN_SPREAD, spread, 1.0),
            candidates,
        )

    def __len__(self) -> int:
        return int(self.tasks.shape[0])

    def nearest(self, tasks: ArrayLike, k: int = 1) -> NDArray[np.intp]:
        """Indices (n, k) of the ``k`` nearest library tasks to each of ``tasks``, nearest first."""
        t = np.atleast_2d(np.asarray(tasks, dtype=float))
        if t.shape[1] != self.tasks.shape[1]:
            raise InvalidArgumentError(
                f"the library's tasks have {self.tasks.shape[1]} features, got {t.shape[1]}"
            )
        d = (((t[:, None, :] - self.tasks[None, :, :]) / self.scale) ** 2).sum(axis=2)
        return np.argsort(d, axis=1, kind="stable")[:, : min(k, len(self))]

    def pick(self, tasks: ArrayLike, guesses: ArrayLike, out_scale: ArrayLike) -> NDArray[np.intp]:
        """Per task, among its ``candidates`` nearest, the solution nearest its guess.

        ``guesses`` (n, n_variables) are the network's, ``out_scale``
        (n_variables,) its output scale (the loss's per-category divisor).
        """
        near = self.nearest(tasks, self.candidates)
        g = np.atleast_2d(np.asarray(guesses, dtype=float))
        scale = np.asarray(out_scale, dtype=float)
        d = (((self.x[near].astype(float) - g[:, None, :]) / scale) ** 2).sum(axis=2)
        return near[np.arange(near.shape[0]), np.argmin(d, axis=1)]

    def arrays(self) -> dict[str, NDArray[np.float64] | NDArray[np.float32]]:
        """The arrays to store, by name."""
        return {
            "tasks": self.tasks,
            "x": self.x,
            "lam_g": self.lam_g,
            "scale": self.scale,
            "candidates": np.array(self.candidates),
        }

    @classmethod
    def from_arrays(cls, arrays: dict[str, NDArray[np.float64]]) -> SolutionLibrary:
        """The library stored by :meth:`arrays`."""
        try:
            return cls(
                np.asarray(arrays["tasks"], dtype=float),
                np.asarray(arrays["x"], dtype=np.float32),
                np.asarray(arrays["lam_g"], dtype=np.float32),
                np.asarray(arrays["scale"], dtype=float),
                int(arrays["candidates"]),
            )
        except KeyError as e:
            raise InvalidArgumentError(f"solution library arrays lack {e}") from None


def farthest(
    pool: ArrayLike, visited: Sequence[ArrayLike], scale: ArrayLike, *, same: float = 1e-3
) -> int | None:
    """The row of ``pool`` farthest from its nearest ``visited`` vector, or None.

    The distance is the RMS over the variables divided by ``scale`` (the
    network's output scale). Rows within ``same`` of a visited vector (a
    start already tried) are never chosen; None when every row is. A
    further start for a solve that ended in a poor minimum should lie in
    another basin: on held-out single-pallet tasks 58 and 72 the library
    candidates within 1.9 of the poor solution (in this distance) ended in
    that same minimum (six of six on tasks 58, 72 and 102, the picks
    aside), while farther ones reached the lower cost. Visited vectors with
    a NaN or infinite entry are left out.
    """
    rows = np.asarray(pool, dtype=float)
    if rows.size == 0:
        return None
    rows = np.atleast_2d(rows)
    s = np.asarray(scale, dtype=float)
    # A non-finite vector (a solve that ended on NaN) is no place in a basin,
    # and its NaN distances would hide every row.
    finite = [v for v in visited if np.isfinite(np.asarray(v, dtype=float)).all()]
    if not finite:
        return 0 if len(rows) else None
    seen = np.atleast_2d(np.asarray(finite, dtype=float))
    d = np.sqrt((((rows[:, None, :] - seen[None, :, :]) / s) ** 2).mean(axis=2)).min(axis=1)
    best = int(np.argmax(d))
    return best if d[best] > same else None
