"""LearnedInit-1, -2, -3: re-solve from A_θ, re-filter, retrain (Melon 2020, Algorithm 1).

for each round: D_good ← FILTER(X, Y; g_max); θ ← SUPERVISEDLEARNING(D_good);
Y ← TOWR(A_θ(X); N_θ). Round 1 learns from the heuristic's solutions with
a two-layer network; later rounds learn from their predecessor's re-solves,
with N_θ = 25 < N_h since learned guesses converge faster, and a
three-layer network since more solutions pass the filter (§IV-B). g_max is
set once, from the heuristic's costs, so that every round is filtered by
the same standard: a per-task g_max when the heuristic run has enough
feasible solutions (:func:`~roughwalk.learning.filtering.fit_task_cost`),
else one global g_max.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk.learning.dataset import Dataset
from roughwalk.learning.executors import Executor
from roughwalk.learning.experience import generate, read_run
from roughwalk.learning.filtering import filter_good, fit_task_cost
from roughwalk.learning.model_file import LearnedModel
from roughwalk.learning.problem_spec import ProblemSpec
from roughwalk.learning.task_space import TaskSpace
from roughwalk.learning.training import TrainReport, train_model

__all__ = ["RoundReport", "learned_init_rounds", "N_LEARNED", "round_layers"]

N_LEARNED = 25  # Melon 2020, §IV-B: N_θ


def round_layers(k: int, width: int = 64) -> tuple[int, ...]:
    """Hidden layers of round ``k``: two layers first, three afterwards."""
    return (width, width) if k == 1 else (width, width, width)


@dataclass
class RoundReport:
    """One LearnedInit round: its model and, if re-solved, how its guesses fared."""

    round: int
    model_path: Path
    train: TrainReport
    resolved: Dataset | None = None

    def summary(self) -> str:
        """One paragraph for the terminal."""
        text = f"LearnedInit-{self.round}: {self.model_path}; {self.train.summary()}"
        if self.resolved is not None and len(self.resolved):
            its = np.asarray(self.resolved["iterations"])
            good = filter_good(self.resolved, self.train.g_max).n_good
            text += (
                f"\n  re-solved {len(self.resolved)} tasks from it (N_θ): median "
                f"{np.median(its):.0f} iterations, {good} within g_max"
            )
        return text


def learned_init_rounds(
    run: str | Path,
    out: str | Path,
    *,
    rounds: int = 3,
    n_tasks: int | None = None,
    max_iter: int = N_LEARNED,
    g_max: float | None = None,
    seed: int = 0,
    width: int = 64,
    executor: Executor | None = None,
    progress: Any = None,
    resolve_last: bool = False,
    solver: tuple[tuple[str, int | None], ...] | None = None,
) -> list[RoundReport]:
    """Train LearnedInit-1..``rounds`` from the heuristic run folder ``run``; write them in ``out``.

    Each round's model goes to ``out/learned_init_K.npz`` and its re-solves
    to ``out/round_K/`` (resumable like any run). ``n_tasks`` limits the
    re-solved tasks to the first N of the run (every round trains on the
    latest solution of every task then, re-solved or not); the last round's
    model is re-solved only with ``resolve_last``. ``solver``: the re-solves'
    restart settings that differ from the defaults (:attr:`ProblemSpec.solver`).
    """
    folder = Path(out)
    data = read_run(run)
    task_cost = fit_task_cost(data) if g_max is None else None
    threshold = None if task_cost is not None else filter_good(data, g_max).g_max
    spec = replace(ProblemSpec.from_dict(data.meta["problem"]), solver=solver)
    space = TaskSpace.from_dict(data.meta["task_space"])
    indices = [int(i) for i in data["index"] if n_tasks is None or i < n_tasks]
    reports: list[RoundReport] = []
    for k in range(1, rounds + 1):
        model, report = train_model(
            data,
            layers=round_layers(k, width),
            g_max=threshold,
            task_cost=task_cost,
            seed=seed,
            learned_round=k,
            note=f"LearnedInit-{k} from {Path(run).name}",
        )
        path = model.save(folder / f"learned_init_{k}.npz")
        reports.append(RoundReport(k, path, report))
        if k == rounds and not resolve_last:
            break
        resolved = generate(
            spec,
            space,
            0,
            folder / f"round_{k}",
            split=str(data.meta.get("split", "train")),
            seed=int(data.meta.get("seed", 0)),
            max_iter=max_iter,
            model=LearnedModel.load(path),
            init=f"learned:{path.name}",
            executor=executor,
            progress=progress,
            indices=indices,
        )
        reports[-1].resolved = resolved
        data = _latest(data, resolved)
    return reports


def _latest(data: Dataset, resolved: Dataset) -> Dataset:
    """``data`` with the rows of the re-solved tasks replaced by their re-solves."""
    kept = data.select(~np.isin(data["index"], resolved["index"]))
    if not len(kept):
        return resolved
    merged = Dataset(kept.columns, resolved.meta)
    return merged.append(resolved)
