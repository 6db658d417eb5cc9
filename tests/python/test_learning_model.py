"""Model files: plain arrays + JSON header that reload exactly; a mismatched problem is refused."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import roughwalk
from roughwalk.errors import ConfigError
from roughwalk.learning import LearnedModel, ProblemSpec, build_problem, filter_good
from roughwalk.learning.dataset import Dataset
from roughwalk.learning.filtering import cost_threshold
from roughwalk.learning.initializer import load_model
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_file import MODEL_FORMAT, problem_signature
from roughwalk.trajopt import Task

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
TASK = Task((0.1, -0.05, 0.2), (0.4, 0.0, 0.0))


def _model(n_out: int, layout: list[list[object]], rng: np.random.Generator) -> LearnedModel:
    weights = (
        rng.normal(size=(6, 5)).astype(np.float32),
        rng.normal(size=(5, n_out)).astype(np.float32),
    )
    biases = (rng.normal(size=5).astype(np.float32), rng.normal(size=n_out).astype(np.float32))
    mlp = MLP(
        weights, biases, "tanh", np.zeros(6), np.ones(6), rng.normal(size=n_out), np.ones(n_out)
    )
    header = {"format": MODEL_FORMAT, "version": 1, "problem": SPEC.to_dict(), "layout": layout}
    return LearnedModel(mlp, header)


def test_model_file_holds_arrays_only_and_predicts_the_same_after_reload(tmp_path: Path) -> None:
    nlp = build_problem(SPEC).formulation
    layout = problem_signature(nlp)["layout"]
    model = _model(nlp.n_variables, layout, np.random.default_rng(1))
    path = model.save(tmp_path / "m.npz")
    with zipfile.ZipFile(path) as z:  # plain arrays: loadable without pickle
        assert "header.npy" in z.namelist()
    back = LearnedModel.load(path)
    task = Task((0.1, -0.05, 0.2), (0.4, 0.0, 0.0))
    # The forward pass against a hand-written one.
    x = np.array([*task.start, *task.goal])
    w0, w1 = model.mlp.weights
    b0, b1 = model.mlp.biases
    expected = model.mlp.out_mean + (np.tanh(x @ w0 + b0) @ w1 + b1)
    np.testing.assert_allclose(back.predict(task), expected, rtol=1e-5)
    back.check(nlp)  # the problem it was made for is accepted


def test_fingerprint_follows_the_weights_not_the_name(tmp_path: Path) -> None:
    """A run resumed with a retrained model of the same name must be told apart."""
    nlp = build_problem(SPEC).formulation
    layout = problem_signature(nlp)["layout"]
    model = _model(nlp.n_variables, layout, np.random.default_rng(1))
    renamed = LearnedModel.load(model.save(tmp_path / "other_name.npz"))
    assert renamed.fingerprint == model.fingerprint
    retrained = _model(nlp.n_variables, layout, np.random.default_rng(2))
    retrained.save(tmp_path / "m.npz")
    assert LearnedModel.load(tmp_path / "m.npz").fingerprint != model.fingerprint
    nudged = LearnedModel.load(tmp_path / "m.npz")
    nudged.mlp.weights[0][0, 0] += np.float32(1e-3)
    assert nudged.fingerprint != retrained.fingerprint


def test_model_file_is_read_once_per_version(tmp_path: Path) -> None:
    nlp = build_problem(SPEC).formulation
    layout = problem_signature(nlp)["layout"]
    path = _model(nlp.n_variables, layout, np.random.default_rng(1)).save(tmp_path / "m.npz")
    first = load_model(str(path))
    assert load_model(str(path)) is first  # a solve per initialiser does not re-read it
    os.utime(path, ns=(1, path.stat().st_mtime_ns + 1))  # the file rewritten
    again = load_model(str(path))
    assert again is not first
    np.testing.assert_allclose(again.predict(TASK), first.predict(TASK))


@pytest.mark.parametrize(
    ("options", "named"),
    [
        ({"robot": "littledog"}, "robot is 'anymal_c' in the model but 'littledog' here"),
        ({"gait": "trot"}, "gait is 'walk' in the model but 'trot' here"),
        ({"steps": 8}, "steps is 4 in the model but 8 here"),
    ],
)
def test_model_applied_to_another_robot_gait_or_step_count_is_refused(
    tmp_path: Path, options: dict[str, Any], named: str
) -> None:
    nlp = build_problem(SPEC).formulation
    path = _model(nlp.n_variables, problem_signature(nlp)["layout"], np.random.default_rng(2)).save(
        tmp_path / "walk4.npz"
    )
    problem: dict[str, Any] = {"gait": "walk", "steps": 4, "duration": 2.0, **options}
    robot = problem.pop("robot", "anymal_c")
    with pytest.raises(ConfigError, match=f"learned model 'walk4' does not fit.*{named}"):
        roughwalk.optimize_motion(
            robot, "flat", ((0, 0, 0), (0.4, 0, 0)), init=f"learned:{path}", **problem
        )


def test_layout_change_alone_is_refused_naming_the_variable_sets() -> None:
    nlp = build_problem(SPEC).formulation
    layout = problem_signature(nlp)["layout"]
    changed = [[name, size + 1 if name == "base_lin" else size] for name, size in layout]
    model = _model(nlp.n_variables, changed, np.random.default_rng(3))
    with pytest.raises(ConfigError, match="variable layout differs in base_lin"):
        model.check(nlp)


def _cost_rows(cost: np.ndarray, starts: np.ndarray | None = None, **overrides: Any) -> Dataset:
    n = len(cost)
    columns = {
        "index": np.arange(n),
        "start": np.zeros((n, 3)) if starts is None else starts,
        "goal": np.zeros((n, 3)),
        "x0": np.zeros((n, 1)),
        "x": np.zeros((n, 1)),
        "cost": np.asarray(cost, dtype=float),
        "status": np.array(["exact"] * n),
        "iterations": np.zeros(n, int),
        "max_violation": np.zeros(n),
        "max_force_n": np.zeros(n),
        "solve_time_s": np.zeros(n),
        "first_iteration_s": np.zeros(n),
        "time_per_iteration_s": np.zeros(n),
    }
    columns.update(overrides)
    return Dataset(columns, {})


def test_g_max_is_found_at_the_start_of_the_tail() -> None:
    rng = np.random.default_rng(0)
    body = np.exp(rng.normal(0.0, 0.1, size=200))  # costs around 1
    tail = np.array([5.0, 20.0, 300.0, 1e4])  # poor local minima
    cost = np.concatenate([body, tail])
    g_max = cost_threshold(cost)
    assert body.max() < g_max < tail.min()
    one_infeasible = np.where(np.arange(len(cost)) == 0, 1.0, 0.0)
    result = filter_good(_cost_rows(cost, max_violation=one_infeasible))
    assert result.automatic and result.n_good == len(body) - 1
    given = filter_good(_cost_rows(cost, max_violation=one_infeasible), g_max=10.0)
    assert given.n_good == len(body) - 1 + 1


def test_g_max_is_not_dragged_past_a_heavy_tail() -> None:
    """A quarter of the solves in poor minima: the fence still ends the body, before the tail.

    Tukey's fence on all quartiles puts Q3 into the tail and ends beyond it
    (session 5's single pallet: 6.8, above 352 of 353 costs).
    """
    rng = np.random.default_rng(1)
    body = np.exp(rng.normal(0.0, 0.1, size=300))
    tail = np.exp(rng.uniform(np.log(1.5), np.log(4.5), size=100))  # 25 %, 1.5 to 4.5
    cost = np.concatenate([body, tail])
    logs = np.log(cost)
    q1, q3 = np.percentile(logs, [25.0, 75.0])
    assert np.mean(tail <= np.exp(q3 + 1.5 * (q3 - q1))) > 0.3  # the plain fence: too lax
    g_max = cost_threshold(cost)
    assert np.mean(body > g_max) <= 0.01
    assert np.mean(tail > g_max) >= 0.9


def test_training_filter_keeps_costly_tasks_and_drops_their_poor_minima() -> None:
    """With enough solves the filter is per task: costly tasks pass, poor minima anywhere do not."""
    from roughwalk.learning.filtering import MIN_TASK_FIT, fit_task_cost

    rng = np.random.default_rng(2)
    n = 2 * MIN_TASK_FIT
    starts = rng.uniform([-0.5, -0.75, -0.5], [0.5, 0.75, 0.5], size=(n, 3))
    cost = np.exp(0.5 - 1.2 * starts[:, 0]) * rng.lognormal(0, 0.03, n)
    poor = np.arange(n) % 20 == 0
    cost[poor] *= 2.0
    data = _cost_rows(cost, starts)
    task_cost = fit_task_cost(data)
    assert task_cost is not None
    good = filter_good(data, task_cost=task_cost).good
    assert not good[poor].any() and good[~poor].mean() >= 0.97
    # One global threshold keeps the poor minima of cheap (near) starts.
    assert filter_good(data).good[poor & (starts[:, 0] > 0.2)].any()
    assert fit_task_cost(_cost_rows(cost[: MIN_TASK_FIT - 1], starts[: MIN_TASK_FIT - 1])) is None


def test_multipliers_of_a_constraint_added_after_training_start_at_zero() -> None:
    """A model's lam_g stays the prefix of a problem that gained rows at the end; else untouched."""
    from types import SimpleNamespace

    from roughwalk.learning.initializer import _complete_rows

    layout = [(name, n) for name, n in (("a", 5), ("b", 3), ("c", 4))]
    nlp = SimpleNamespace(row_layout=layout, n_constraints=12)
    lam = np.arange(1.0, 9.0)  # the first two blocks: 8 rows
    completed = _complete_rows(nlp, lam)  # type: ignore[arg-type]
    np.testing.assert_array_equal(completed, np.concatenate([lam, np.zeros(4)]))
    # Not on a block boundary: left as it is, so the solver drops the mismatched multipliers.
    assert _complete_rows(nlp, lam[:7]).size == 7  # type: ignore[arg-type]
    assert _complete_rows(nlp, np.ones(12)).size == 12  # type: ignore[arg-type]


def test_task_cost_model_flags_minima_above_their_task_s_cost_not_costly_tasks() -> None:
    """Far starts cost more: the per-task fence passes them and catches a poor minimum."""
    from roughwalk.learning import TaskCostModel

    rng = np.random.default_rng(0)
    starts = rng.uniform([-0.5, -0.75, -0.5], [0.5, 0.75, 0.5], size=(300, 3))
    tasks = np.column_stack([starts, np.tile([1.6, 0.0, 0.0], (300, 1))])
    cost = np.exp(0.5 - 0.8 * starts[:, 0] + 0.3 * starts[:, 1] ** 2) * rng.lognormal(0, 0.03, 300)
    poor = np.arange(300) % 25 == 0
    cost[poor] *= 2.0  # poor local minima, anywhere in the task space
    model = TaskCostModel.fit(tasks, cost)
    beyond = cost > model.threshold(tasks)
    assert beyond[poor].all() and beyond[~poor].mean() <= 0.01
    # A global threshold misses the poor minima of cheap (near) starts.
    global_beyond = cost > cost_threshold(cost)
    assert global_beyond[poor].sum() < poor.sum() // 2
    back = TaskCostModel.from_dict(json.loads(json.dumps(model.to_dict())))
    assert np.allclose(back.threshold(tasks), model.threshold(tasks))
