"""Experience grown from solved neighbours: each task starts at the nearest solved task's solution.

Where the NLP rarely converges from a guess (the double pallet: the
heuristic 0 of 10 held-out tasks, a model trained on 27 solves 4 of 10),
the converged solution of a nearby task, with its own multipliers, is the
cheapest start found so far: session 7 converged one feasible solve per
7 s of CPU warm-started from the tasks' earlier solutions, against one per
21–25 s from a model's guess. :func:`neighbour_solves` solves the tasks of a
run in the order that keeps that true: next the task nearest to any solved
one, from that solve's solution and multipliers; every feasible solve joins
the pool at once, so the solved set grows outwards from its seeds (the
feasible solves of earlier run folders of the same problem, and the run's
own). The distance is over the task features divided by the task space's
box width (1 where the box is flat, e.g. a fixed goal).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.learning.executors import Executor
from roughwalk.learning.filtering import VIOLATION_TOL, feasible_mask
from roughwalk.learning.problem_spec import NLP_SETTINGS, ProblemSpec
from roughwalk.learning.task_space import TaskSpace
from roughwalk.trajopt import Task

__all__ = ["NEAREST_INIT", "SolvedPool", "neighbour_solves", "parse_nearest"]

NEAREST_INIT = "nearest"
"""``--init nearest:RUN[,RUN...]``: start each task at its nearest solved neighbour's solution."""


def parse_nearest(init: str) -> list[Path] | None:
    """The seed run folders of ``nearest:RUN[,RUN...]``, or None for another ``init``."""
    name, _, argument = init.partition(":")
    if name != NEAREST_INIT:
        return None
    folders = [Path(item) for item in argument.split(",") if item.strip()]
    if not folders:
        raise ConfigError(
            "--init nearest needs the run folders whose feasible solves seed it: "
            "nearest:RUN[,RUN...]"
        )
    return folders


@dataclass
class SolvedPool:
    """Feasible solves (task features, solution, multipliers), looked up by the nearest task.

    Attributes
    ----------
    scale:
        (6,) divisor of each task feature in the distance.

    """

    scale: NDArray[np.float64]
    tasks: list[NDArray[np.float64]] = field(default_factory=list)
    starts: list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=list
    )

    @classmethod
    def for_space(cls, space: TaskSpace) -> SolvedPool:
        """An empty pool whose distance divides by ``space``'s start box (goal: by 1)."""
        width = np.asarray(space.start_high, dtype=float) - np.asarray(space.start_low, dtype=float)
        start_scale = np.where(width > 0.0, width, 1.0)
        return cls(np.concatenate([start_scale, np.ones(3)]))

    def __len__(self) -> int:
        return len(self.tasks)

    def add(self, row: dict[str, Any]) -> bool:
        """Add a stored solve if it is feasible and recorded its multipliers; say whether."""
        lam_x = np.asarray(row["lam_x"], dtype=float)
        lam_g = np.asarray(row["lam_g"], dtype=float)
        cost = float(row["cost"])
        violation = float(row["max_violation"])
        usable = (
            np.isfinite(cost)
            and np.isfinite(violation)
            and violation <= VIOLATION_TOL
            and lam_x.size > 0
            and lam_g.size > 0
            and bool(np.isfinite(lam_x).all() and np.isfinite(lam_g).all())
        )
        if usable:
            features = np.concatenate([np.asarray(row["start"]), np.asarray(row["goal"])])
            self.tasks.append(features.astype(float))
            self.starts.append((np.asarray(row["x"], dtype=float), lam_x, lam_g))
        return usable

    def distances(self, tasks: Sequence[Task]) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        """Per task its scaled distance to the nearest solve and that solve's position."""
        t = np.array([[*task.start, *task.goal] for task in tasks], dtype=float).reshape(-1, 6)
        pool = np.asarray(self.tasks, dtype=float).reshape(-1, 6)
        d = np.sqrt((((t[:, None, :] - pool[None, :, :]) / self.scale) ** 2).sum(axis=2))
        nearest = np.argmin(d, axis=1)
        return d[np.arange(len(t)), nearest], nearest


def seed_pool(spec: ProblemSpec, space: TaskSpace, folders: Sequence[Path]) -> SolvedPool:
    """The feasible solves of ``folders`` (runs of ``spec``'s problem) as a pool."""
    from roughwalk.learning.experience import read_run

    pool = SolvedPool.for_space(space)
    wanted = _rows_and_variables(spec.to_dict())
    for folder in folders:
        data = read_run(folder)
        problem = data.meta.get("problem")
        if not isinstance(problem, dict) or _rows_and_variables(problem) != wanted:
            raise ConfigError(
                f"{folder} holds solves of another problem ({problem!r}); nearest starts "
                f"need solves of {spec.to_dict()!r} (it may differ in "
                f"{', '.join(NLP_SETTINGS)})"
            )
        for k in np.flatnonzero(feasible_mask(data)):
            pool.add({name: data[name][k] for name in data.columns})
    return pool


def _rows_and_variables(problem: dict[str, Any]) -> dict[str, Any]:
    """``problem`` without :data:`NLP_SETTINGS`: what fixes the solution's and rows' shape.

    A seed run's solves only start the solves: one made at another
    ``swing_base_clearance`` (the same rows, other bounds) is as good a
    start; the run records its own problem, so its solves are never mixed
    with the seeds' in training.
    """
    return {k: v for k, v in problem.items() if k not in NLP_SETTINGS}


def neighbour_solves(
    spec: ProblemSpec,
    indices: Sequence[int],
    tasks: Sequence[Task],
    pool: SolvedPool,
    max_iter: int,
    executor: Executor,
    batch: int = 1,
    time_limit_s: float | None = None,
) -> Iterator[dict[str, Any]]:
    """Solve ``tasks`` nearest-to-the-pool first, each from its nearest solve; yield the rows.

    ``batch`` tasks are handed to ``executor`` at a time (its worker
    count); each yielded feasible row joins ``pool`` before the next batch
    is chosen. ``time_limit_s`` is each solve's wall-time limit (None: the
    problem's).
    """
    from roughwalk.learning.experience import SolveJob, solve_job

    if len(pool) == 0 and len(tasks):
        raise ConfigError(
            "no feasible solve with multipliers in the seed runs: nothing to start from"
        )
    left = list(range(len(tasks)))
    while left:
        distance, nearest = pool.distances([tasks[k] for k in left])
        order = np.argsort(distance, kind="stable")[: max(batch, 1)]
        jobs = []
        for j in order:
            k = left[int(j)]
            x0, lam_x0, lam_g0 = pool.starts[int(nearest[j])]
            jobs.append(
                SolveJob(
                    spec,
                    indices[k],
                    tasks[k],
                    max_iter,
                    x0,
                    lam_x0,
                    lam_g0,
                    time_limit_s=time_limit_s,
                )
            )
        chosen = {left[int(j)] for j in order}
        left = [k for k in left if k not in chosen]
        for row in executor.run(solve_job, jobs):
            pool.add(row)
            yield row
