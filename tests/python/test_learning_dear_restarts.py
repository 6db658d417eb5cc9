"""A learned solve that converges above its task's g_max starts again from another candidate."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _learned_models import SHIPPED_PALLET_MODEL, run_one_held_out_task, shipped_pallet_spec

from roughwalk.errors import ConfigError
from roughwalk.learning import build_problem, task_space
from roughwalk.learning.initializer import LearnedInitializer, load_model
from roughwalk.learning.solution_library import farthest
from roughwalk.trajopt.optimize import _cheaper
from roughwalk.trajopt.parameters import SolverOptions
from roughwalk.trajopt.solver import SolveOutcome, TrajoptStatus

MODEL = SHIPPED_PALLET_MODEL
# Held-out task 58: the library's pick (and the network's own guess) converge
# to 3.414, above the task's g_max 3.345; the heuristic reaches 2.559.
DEAR_TASK = 58


def test_a_dear_minimum_starts_again_and_keeps_the_cheaper() -> None:
    problem = build_problem(shipped_pallet_spec())
    initializer = LearnedInitializer(MODEL)
    task = task_space("single_pallet").task(DEAR_TASK, split="test")
    limit = load_model(MODEL).cost_limits([task])
    assert limit is not None
    result = problem.solve(task, initializer, max_iter=100)
    assert result.status.solved, result.message
    assert "more start(s) after a converged cost above" in result.message
    assert result.objective < limit[0] < 3.414
    # Every start is paid for, within the one iteration limit.
    assert 20 < result.iterations <= 100
    assert result.history[-1]["iteration"] == result.iterations


def test_experience_runs_from_a_model_start_again_too(tmp_path: Path) -> None:
    model = load_model(MODEL)
    data = run_one_held_out_task(tmp_path / "run", DEAR_TASK)
    limit = model.cost_limits([task_space("single_pallet").task(DEAR_TASK, split="test")])
    assert limit is not None
    assert data["status"][0] in ("exact", "approximate")
    assert data["cost"][0] < limit[0]


def test_farthest_picks_the_row_farthest_from_what_was_tried() -> None:
    pool = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [0.0, 2.0]])
    scale = np.array([1.0, 2.0])  # the second coordinate counts half
    assert farthest(pool, [pool[0]], scale) == 2  # RMS distances 0, 0.71, 2.12, 0.71
    assert farthest(pool, [pool[2]], scale) == 3  # 2.12, 1.41, 0, 2.24
    assert farthest(pool, [pool[0], pool[2]], scale) == 1  # a tie at 0.71: the first
    assert farthest(pool, list(pool), scale) is None  # every row tried
    assert farthest(pool, [], scale) == 0
    # A solve that ended on NaN (IPOPT's invalid number) hides no row.
    diverged = np.array([np.nan, 0.0])
    assert farthest(pool, [pool[0], diverged], scale) == 2
    assert farthest(pool, [diverged], scale) == 0
    # An empty pool has no row to give.
    assert farthest(np.zeros((0, 2)), [pool[0]], scale) is None
    assert farthest([], [], scale) is None


def test_dear_guess_restarts_must_not_be_negative() -> None:
    assert SolverOptions(dear_guess_restarts=0).dear_guess_restarts == 0
    with pytest.raises(ConfigError, match="dear_guess_restarts"):
        SolverOptions(dear_guess_restarts=-1)


def _outcome(objective: float, iterations: int, time_s: float, history: list) -> SolveOutcome:
    empty = np.zeros(0)
    return SolveOutcome(
        TrajoptStatus.EXACT, "Solve_Succeeded", iterations, time_s,
        empty, empty, empty, objective, empty, empty, history,
    )  # fmt: skip


def test_a_further_starts_history_runs_on_after_the_kept_ones() -> None:
    # As after a fallback restart: the further start's entries are numbered and
    # timed after the solves before it, and say which solve they are of.
    kept = _outcome(
        3.4,
        50,
        1.0,
        [
            {"iteration": 0.0, "elapsed_s": 0.0, "solve": 0.0},
            {"iteration": 40.0, "elapsed_s": 0.7, "solve": 0.0},
            {"iteration": 40.0, "elapsed_s": 0.7, "solve": 1.0},
            {"iteration": 50.0, "elapsed_s": 1.0, "solve": 1.0},
        ],
    )
    other = _outcome(
        2.5, 8, 0.2, [{"iteration": 0.0, "elapsed_s": 0.0}, {"iteration": 8.0, "elapsed_s": 0.2}]
    )
    joined = _cheaper(kept, other)
    assert joined.objective == 2.5 and joined.iterations == 58
    assert [h["solve"] for h in joined.history] == [0.0, 0.0, 1.0, 1.0, 2.0, 2.0]
    assert [h["iteration"] for h in joined.history][-2:] == [50.0, 58.0]
    elapsed = [h["elapsed_s"] for h in joined.history]
    assert all(b >= a for a, b in zip(elapsed, elapsed[1:], strict=False))
    assert elapsed[-1] == pytest.approx(1.2)
    # An untagged first solve (no fallback before) counts as solve 0.
    plain = _cheaper(_outcome(3.4, 30, 0.5, [{"iteration": 30.0, "elapsed_s": 0.5}]), other)
    assert [h["solve"] for h in plain.history] == [0.0, 1.0, 1.0]
