"""Experience generation: solve sampled tasks and keep every outcome (Melon 2020, Alg. 1).

Y ← TOWR(A_h(X); N_h): each task of a task space is solved from an initial
guess (the heuristic, or a learned model's) with an iteration limit, and the
task, the guess, the solution vector, its cost, status, iterations and
times are kept. A run writes each finished solve as its own small file
(written to a temporary name, synced, then renamed), so a run killed at any
moment loses no finished solve; running it again solves only what is
missing, then consolidates everything into one :class:`Dataset`.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.learning.dataset import COLUMNS, Dataset
from roughwalk.learning.executors import Executor, LocalExecutor
from roughwalk.learning.model_costs import cost_changes
from roughwalk.learning.neighbour_starts import NEAREST_INIT, neighbour_solves, seed_pool
from roughwalk.learning.problem_spec import (
    UNRECORDED_SOLVE_SETTINGS,
    ProblemSpec,
    build_problem,
    solve_settings,
    task_refusal,
    variable_layout,
)
from roughwalk.learning.task_space import TaskSpace
from roughwalk.trajopt import (
    ContactSchedule,
    Formulation,
    HeuristicInitializer,
    Task,
    TrajoptResult,
)
from roughwalk.trajopt.task import ResolvedTask, resolve

if TYPE_CHECKING:
    from roughwalk.learning.model_file import LearnedModel, Start

__all__ = [
    "SolveJob",
    "FixedGuess",
    "solve_job",
    "ExperienceRun",
    "generate",
    "jittered",
    "result_row",
    "read_run",
]

N_HEURISTIC = 100  # Melon 2020, §IV-B: N_h


@dataclass(frozen=True)
class SolveJob:
    """One solve: task ``index`` of a split, from ``x0`` (None: the heuristic guess).

    With multipliers ``lam_x0`` and ``lam_g0`` as well, IPOPT is warm-started.
    """

    spec: ProblemSpec
    index: int
    task: Task
    max_iter: int
    x0: NDArray[np.float64] | None = None
    lam_x0: NDArray[np.float64] | None = None
    lam_g0: NDArray[np.float64] | None = None
    fallback: (
        tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None] | None
    ) = None
    """A second start (guess, lam_x, lam_g): a library model's network guess."""
    cost_limit: float | None = None
    """The cost above which a converged solve is started again from ``restarts``."""
    restarts: tuple[Start, ...] = ()
    """Further starts for a converged solve dearer than ``cost_limit`` (library candidates)."""
    restart_scale: NDArray[np.float64] | None = None
    """The distance scale :func:`~roughwalk.learning.solution_library.farthest` chooses them in."""
    time_limit_s: float | None = None
    """IPOPT's wall-time limit [s]; None: the problem's ``solver.time_limit_s``."""


class FixedGuess:
    """An initialiser that hands over a given guess (and multipliers), and a fallback if given.

    The fallback (a library model's network guess and multipliers) is the
    start of a restart when the solve from ``x0`` has not converged after
    ``solver.guess_fallback_after`` iterations, as under ``--init learned``.
    """

    name = "fixed"

    def __init__(
        self,
        x0: NDArray[np.float64],
        lam_x0: NDArray[np.float64] | None = None,
        lam_g0: NDArray[np.float64] | None = None,
        fallback: (
            tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]
            | None
        ) = None,
        cost_limit: float | None = None,
        restarts: tuple[Start, ...] = (),
        restart_scale: NDArray[np.float64] | None = None,
    ) -> None:
        self.x0, self.lam_x0, self.lam_g0 = x0, lam_x0, lam_g0
        self._fallback = fallback
        self._cost_limit = cost_limit
        self._restarts = restarts
        self._restart_scale = restart_scale

    def has_fallback(self, nlp: Formulation) -> bool:
        """Whether a fallback start was given."""
        return self._fallback is not None

    def fallback(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """The fallback start, within the bounds, lam_g padded for appended rows."""
        from roughwalk.learning.initializer import _complete_rows

        assert self._fallback is not None
        x1, lam_x1, lam_g1 = self._fallback
        lam_g = None if lam_g1 is None else _complete_rows(nlp, np.asarray(lam_g1))
        return np.clip(np.asarray(x1, dtype=float), nlp.lbx, nlp.ubx), lam_x1, lam_g

    def cost_limit(self, nlp: Formulation, task: ResolvedTask) -> float | None:
        """The given cost limit (None: never start again)."""
        return self._cost_limit

    def other_start(
        self, nlp: Formulation, task: ResolvedTask, visited: Sequence[NDArray[np.float64]]
    ) -> Start | None:
        """The given further start farthest from every start and solution so far, or None."""
        from roughwalk.learning.initializer import choose_start

        if self._restart_scale is None:
            return None
        return choose_start(nlp, self._restarts, visited, self._restart_scale)

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """The gait's schedule."""
        return gait

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """The task as given."""
        return task

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The given vector."""
        return self.x0

    def multipliers(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """The given multipliers (None: IPOPT starts its own), lam_g padded for appended rows."""
        from roughwalk.learning.initializer import _complete_rows

        lam_g = None if self.lam_g0 is None else _complete_rows(nlp, np.asarray(self.lam_g0))
        return self.lam_x0, lam_g


def result_row(index: int, result: TrajoptResult, x0: NDArray[np.float64]) -> dict[str, Any]:
    """A dataset row (:data:`~roughwalk.learning.dataset.COLUMNS`) from a solve."""
    assert result.task is not None and result.x is not None
    history = result.history or []
    solve_time = result.solve_time_s - result.build_time_s
    first = float(history[1]["elapsed_s"]) if len(history) > 1 else solve_time
    later = len(history) - 2
    per_iteration = (float(history[-1]["elapsed_s"]) - first) / later if later > 0 else float("nan")
    return {
        "index": index,
        "start": np.asarray(result.task.start, dtype=float),
        "goal": np.asarray(result.task.goal, dtype=float),
        "x0": np.asarray(x0, dtype=float),
        "x": np.asarray(result.x, dtype=float),
        "lam_x": np.asarray(result.lam_x, dtype=float),
        "lam_g": np.asarray(result.lam_g, dtype=float),
        "cost": float(result.objective),
        "status": result.status.value,
        "iterations": int(result.iterations),
        "max_violation": float(result.max_violation),
        "max_force_n": float(result.max_force_n),
        "solve_time_s": float(solve_time),
        "first_iteration_s": first,
        "time_per_iteration_s": per_iteration,
    }


def _network_starts(
    model: LearnedModel, tasks: list[Task]
) -> list[
    tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None] | None
]:
    """Per task the network's own guess and multipliers: a library model's fallback."""
    if model.library is None:
        return [None] * len(tasks)
    network = model.network_only()
    x = network.predict_tasks(tasks)
    lam_x, lam_g = network.predict_multipliers(tasks)
    return [
        (x[k], None if lam_x is None else lam_x[k], None if lam_g is None else lam_g[k])
        for k in range(len(tasks))
    ]


def solve_job(job: SolveJob) -> dict[str, Any]:
    """Solve one job in this process (the NLP is built once per process)."""
    problem = build_problem(job.spec)
    if job.x0 is None:
        resolved = resolve(job.task, problem.body, problem.terrain)
        x0 = HeuristicInitializer().guess(problem.formulation, resolved)
    else:
        x0 = np.asarray(job.x0, dtype=float)
    guess = FixedGuess(
        x0, job.lam_x0, job.lam_g0, job.fallback, job.cost_limit, job.restarts, job.restart_scale
    )
    result = problem.solve(job.task, guess, max_iter=job.max_iter, time_limit_s=job.time_limit_s)
    return result_row(job.index, result, x0)


class ExperienceRun:
    """A run's folder: ``run.json`` (what is solved), ``solves/`` (one file per task), dataset.

    Parameters
    ----------
    folder:
        The run's folder (created).
    meta:
        What the run solves: "problem", "task_space", "split", "seed",
        "init", "max_iter" (and "layout", added on the first solve). A folder
        made for other settings is refused, naming the first that differs.
    unrecorded:
        What a folder that does not record a key of ``meta`` was made with
        (a record added later: "solver"); a key missing here too refuses it.

    """

    def __init__(
        self,
        folder: str | Path,
        meta: dict[str, Any],
        unrecorded: dict[str, Any] | None = None,
    ) -> None:
        self.folder = Path(folder)
        self.solves = self.folder / "solves"
        self.solves.mkdir(parents=True, exist_ok=True)
        meta_path = self.folder / "run.json"
        meta = json.loads(json.dumps(meta))  # tuples as JSON lists, as read back
        if meta_path.is_file():
            old = json.loads(meta_path.read_text())
            unrecorded = json.loads(json.dumps(unrecorded or {}))
            for key, value in meta.items():
                if key not in old and key in unrecorded:
                    _check_settings(self.folder, key, unrecorded[key], value, recorded=False)
                    continue
                if key in unrecorded and isinstance(old[key], dict):
                    _check_settings(self.folder, key, old[key], value, recorded=True)
                    continue
                if key not in old:
                    # An older run that did not record this cannot prove it matches
                    # (e.g. solved before the constraint set was recorded).
                    raise ConfigError(
                        f"{self.folder} holds a run that does not record '{key}' "
                        f"(asked {value!r}); use another folder"
                    )
                if old[key] != value:
                    raise ConfigError(
                        f"{self.folder} holds a run with another '{key}' "
                        f"({old[key]!r}, asked {value!r}); use another folder"
                    )
            meta = {**old, **meta}
        self.meta = meta
        self._write_meta()

    def _write_meta(self) -> None:
        tmp = self.folder / "run.json.part"
        tmp.write_text(json.dumps(self.meta, indent=1) + "\n")
        os.replace(tmp, self.folder / "run.json")

    def _path(self, index: int) -> Path:
        return self.solves / f"{index:06d}.npz"

    def done(self) -> set[int]:
        """Indices of the finished solves."""
        return {int(p.stem) for p in self.solves.glob("*.npz") if p.stem.isdigit()}

    def record(self, row: dict[str, Any]) -> None:
        """Store one finished solve durably (temporary file, fsync, rename)."""
        path = self._path(int(row["index"]))
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "wb") as f:
            arrays: dict[str, Any] = {k: np.asarray(row[k]) for k in COLUMNS if k in row}
            np.savez(f, **arrays)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)

    def rows(self, indices: Sequence[int] | None = None) -> list[dict[str, Any]]:
        """The stored rows (of ``indices``, default all), by index."""
        wanted = sorted(self.done() if indices is None else indices)
        out = []
        for i in wanted:
            with np.load(self._path(i), allow_pickle=False) as data:
                out.append(_row(data))
        return out

    def dataset(self, indices: Sequence[int] | None = None) -> Dataset:
        """The stored rows as a dataset, also written to ``dataset.npz`` (+ .json)."""
        data = Dataset.from_rows(self.rows(indices), self.meta)
        data.save(self.folder / "dataset.npz")
        return data


def _check_settings(
    folder: Path, key: str, old: dict[str, Any], new: dict[str, Any], *, recorded: bool
) -> None:
    """Refuse a folder whose settings ``key`` (a dict) differ from ``new``, naming the first."""
    for name in {**old, **new}:
        if name in old and old.get(name) == new.get(name):
            continue
        was = _setting(old.get(name))
        made = "made with" if recorded else "made before run folders recorded it, so with"
        raise ConfigError(
            f"{folder} holds solves {made} {key}.{name}={was}; this run has "
            f"{key}.{name}={_setting(new.get(name))}, and resuming would mix solves of both "
            f"settings in one dataset: use a fresh folder, or --set {key}.{name}={was} "
            "to finish the run as it was made"
        )


def _setting(value: Any) -> str:
    """A setting's value as ``--set`` spells it."""
    return "none" if value is None else str(value)


def _progress(done: int, total: int, new: int, started: float, out: TextIO) -> None:
    elapsed = time.perf_counter() - started
    width = 30
    filled = int(width * done / max(total, 1))
    rate = elapsed / new if new else float("nan")
    eta = rate * (total - done)
    line = (
        f"[{'#' * filled}{'.' * (width - filled)}] {done}/{total} "
        f"{rate:.1f} s/task, {eta / 60:.1f} min left"
    )
    if out.isatty():
        out.write("\r" + line + ("\n" if done == total else ""))
    elif done == total or done % max(total // 20, 1) == 0:
        out.write(line + "\n")
    out.flush()


def generate(
    spec: ProblemSpec,
    space: TaskSpace,
    n_tasks: int,
    folder: str | Path,
    *,
    split: str = "train",
    seed: int = 0,
    max_iter: int = N_HEURISTIC,
    model: LearnedModel | None = None,
    init: str = "heuristic",
    executor: Executor | None = None,
    progress: TextIO | None = sys.stderr,
    on_solved: Callable[[dict[str, Any]], None] | None = None,
    indices: Sequence[int] | None = None,
    jitter: Sequence[float] | None = None,
    jitter_seed: int = 0,
    seeds: Sequence[str | Path] | None = None,
    batch: int = 1,
    time_limit_s: float | None = None,
) -> Dataset:
    """Solve tasks 0..n_tasks−1 of ``space``'s ``split`` into ``folder``; resume what is there.

    Parameters
    ----------
    spec, space:
        The problem and its task space.
    n_tasks:
        How many tasks (the first ``n_tasks`` of the split's stream).
    folder:
        The run's folder; finished solves found there are kept, not redone.
    split, seed:
        Which random stream of tasks.
    max_iter:
        IPOPT's iteration limit (N_h = 100 with the heuristic, N_θ = 25 learned).
    model:
        A learned model whose guesses (and multipliers) start the solves;
        None uses the heuristic.
    init:
        The guesses' name, recorded in the run.
    executor:
        Where to solve (default: in this process).
    progress:
        Where to draw the progress bar (None: nowhere).
    on_solved:
        Called with each stored row (tests interrupt a run with it).
    indices:
        Solve these task indices instead of 0..n_tasks−1.
    jitter, jitter_seed:
        With a model: ask it for the guess of a task whose start is moved
        by these standard deviations (x [m], y [m], yaw [rad]); see
        :func:`jittered`. Recorded in the run.
    seeds, batch:
        Instead of a model: start each task at the solution (and
        multipliers) of the nearest feasible solve of these run folders and
        of this run, nearest tasks first, ``batch`` (the executor's workers)
        at a time (:mod:`~roughwalk.learning.neighbour_starts`); ``init``
        names them (``nearest:RUN,...``).
    time_limit_s:
        IPOPT's wall-time limit of each solve [s]; None: the problem's
        ``solver.time_limit_s``. It changes no iterate, only where a slow
        solve stops (its row's status is then "timeout"), so it is not part
        of what a resumed folder must match; the run records the last one
        used as "time_limit_s" (null: the problem's). A solve that stopped on
        time is kept as done: re-solve it in a fresh folder.

    Returns
    -------
    Dataset
        Every stored solve of the wanted tasks, sorted by task index.

    """
    if spec.terrain != space.terrain:
        raise ConfigError(
            f"the problem is on terrain '{spec.terrain}' but the task space "
            f"'{space.name}' is on '{space.terrain}'"
        )
    if time_limit_s is not None and not time_limit_s > 0:
        raise ConfigError(f"time_limit_s must be > 0 seconds, got {time_limit_s}")
    if model is not None:
        # Its guesses must be of this NLP (a fixed-duration model's are shorter
        # than an optimised-duration problem's): refused before the folder is made.
        model.check_signature(spec.to_dict())
    if seeds is not None and model is not None:
        raise ConfigError("a run starts from a model's guesses or from seed runs' solves, not both")
    if seeds is not None:
        init = f"{NEAREST_INIT}:{','.join(str(f) for f in seeds)}"
    run = ExperienceRun(
        folder,
        {
            # A run resumed under another constraint set would mix two problems'
            # solves; checked first, so that the refusal names it.
            "constraints": list(spec.config().constraints),
            # Only when some weight is not the default: older runs resume as before.
            **({"costs": costs} if (costs := cost_changes(spec.config().costs)) else {}),
            "problem": spec.to_dict(),
            "task_space": space.to_dict(),
            "split": split,
            "seed": seed,
            "init": init,
            # The guesses' source by content: a retrained model keeps its name.
            "model": None if model is None else model.fingerprint,
            "max_iter": max_iter,
            # Only when given: runs made before jitter existed resume as before.
            **({} if jitter is None else {"jitter": [*map(float, jitter), int(jitter_seed)]}),
            # How a learned solve restarts (a heuristic solve uses none of it).
            **({} if model is None else {"solver": solve_settings(spec)}),
        },
        unrecorded={"solver": UNRECORDED_SOLVE_SETTINGS},
    )
    # What the solves stop at on this machine (None: the problem's limit), not
    # what the folder solves; a solve that stopped on time stays done.
    limit = None if time_limit_s is None else float(time_limit_s)
    if run.meta.get("time_limit_s", None) != limit:
        run.meta["time_limit_s"] = limit
        run._write_meta()
    wanted = list(range(n_tasks)) if indices is None else sorted(set(indices))
    # Tasks the problem refuses (a start no solve can leave) are not solved:
    # the run records why, and the dataset leaves them out.
    refused = {
        i: reason
        for i in wanted
        if (reason := task_refusal(spec, space.task(i, seed=seed, split=split))) is not None
    }
    # The record is today's for the wanted tasks (a check that changed since
    # must not leave a task out of read_run), earlier runs' for the others.
    checked = set(wanted)
    record = {k: r for k, r in run.meta.get("refused", {}).items() if int(k) not in checked}
    record.update({str(i): r for i, r in refused.items()})
    if record != run.meta.get("refused", {}):
        run.meta.pop("refused", None)
        run.meta.update({"refused": record} if record else {})
        run._write_meta()
    wanted = [i for i in wanted if i not in refused]
    done = run.done()
    todo = [i for i in wanted if i not in done]
    tasks = [space.task(i, seed=seed, split=split) for i in todo]
    jobs = [
        SolveJob(spec, i, t, max_iter, time_limit_s=time_limit_s)
        for i, t in zip(todo, tasks, strict=True)
    ]
    if model is not None and tasks:
        asked = tasks if jitter is None else jittered(tasks, todo, jitter, jitter_seed)
        x0s = model.predict_tasks(asked)
        lam_x, lam_g = model.predict_multipliers(asked)
        fallbacks = _network_starts(model, asked)
        # Further starts for a solve that converges dear (solver.dear_guess_restarts).
        n_restarts = spec.config().solver.dear_guess_restarts
        limits = model.cost_limits(tasks) if n_restarts > 0 else None
        jobs = [
            SolveJob(
                spec,
                job.index,
                job.task,
                max_iter,
                x0s[k],
                None if lam_x is None else lam_x[k],
                None if lam_g is None else lam_g[k],
                fallbacks[k],
                None if limits is None else float(limits[k]),
                tuple(model.other_starts(asked[k])) if limits is not None else (),
                model.mlp.out_scale,
                time_limit_s,
            )
            for k, job in enumerate(jobs)
        ]
    if "layout" not in run.meta and jobs:
        run.meta["layout"] = variable_layout(build_problem(spec).formulation)
        run._write_meta()
    started = time.perf_counter()
    finished = len(wanted) - len(todo)
    executor = executor or LocalExecutor(1)
    if seeds is None:
        results: Iterator[dict[str, Any]] = executor.run(solve_job, jobs)
    else:
        pool = seed_pool(spec, space, [Path(f) for f in seeds])
        for row in run.rows():
            pool.add(row)
        results = neighbour_solves(spec, todo, tasks, pool, max_iter, executor, batch, time_limit_s)
    for row in results:
        run.record(row)
        finished += 1
        if progress is not None:
            _progress(finished, len(wanted), finished - len(wanted) + len(todo), started, progress)
        if on_solved is not None:
            on_solved(row)
    if "layout" not in run.meta:
        run.meta["layout"] = variable_layout(build_problem(spec).formulation)
        run._write_meta()
    run.meta["layout"] = [list(item) for item in run.meta["layout"]]
    return run.dataset(wanted)


def jittered(
    tasks: Sequence[Task], indices: Sequence[int], jitter: Sequence[float], seed: int
) -> list[Task]:
    """``tasks`` with each start moved by N(0, diag(jitter)²), drawn from (seed, index).

    A learned guess asked for a nearby task lands in another basin of the
    NLP: re-solving the same task from jittered guesses is a multi-start
    that finds the lower minima a model trained on single solves misses
    (far starts on the single pallet). The draw depends only on the seed
    and the task's index, so a resumed or distributed run asks the same.
    """
    sigma = np.asarray(jitter, dtype=float)
    if sigma.shape != (3,) or np.any(sigma < 0):
        raise ConfigError(f"jitter is three standard deviations (x, y, yaw) >= 0, got {jitter!r}")
    out = []
    for task, index in zip(tasks, indices, strict=True):
        shift = np.random.default_rng([seed, int(index)]).normal(0.0, 1.0, 3) * sigma
        start = tuple(float(v) for v in np.asarray(task.start, dtype=float) + shift)
        out.append(Task(start, task.goal))  # type: ignore[arg-type]
    return out


def read_run(folder: str | Path) -> Dataset:
    """The finished solves of a run folder (even one still running), without writing anything.

    Tasks the run records as refused are left out, as :func:`generate`'s
    dataset leaves them: a folder solved before the refusal existed holds
    their (infeasible) solves.
    """
    path = Path(folder)
    meta_path = path / "run.json"
    if not meta_path.is_file():
        raise ConfigError(f"{path} is not an experience run (no run.json)")
    meta = json.loads(meta_path.read_text())
    refused = {int(i) for i in meta.get("refused", {})}
    rows = []
    for item in sorted((path / "solves").glob("*.npz")):
        if not item.stem.isdigit() or int(item.stem) in refused:
            continue
        with np.load(item, allow_pickle=False) as data:
            rows.append(_row(data))
    return Dataset.from_rows(rows, meta)


def _row(data: Any) -> dict[str, Any]:
    """A stored row (rows from before multipliers were recorded lack them)."""
    return {k: data[k][()] if data[k].ndim == 0 else data[k] for k in COLUMNS if k in data.files}
