"""A library pick that does not converge falls back to the network's own guess."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from _learned_models import SHIPPED_PALLET_MODEL, run_one_held_out_task, shipped_pallet_spec

from roughwalk.errors import ConfigError
from roughwalk.learning import ProblemSpec, build_problem, task_space
from roughwalk.learning.initializer import LearnedInitializer, load_model
from roughwalk.learning.model_constraints import constraints_for_model
from roughwalk.trajopt.parameters import SolverOptions

MODEL = SHIPPED_PALLET_MODEL
# Held-out task 104: the shipped model's library pick stops at 100 iterations
# unconverged; the network's guess converges in 12.
STUCK_TASK = 104


def test_a_stuck_library_pick_restarts_from_the_network_guess_and_converges() -> None:
    problem = build_problem(shipped_pallet_spec())
    after = problem.config.solver.guess_fallback_after
    assert after is not None
    initializer = LearnedInitializer(MODEL)
    assert initializer.has_fallback(problem.formulation)
    task = task_space("single_pallet").task(STUCK_TASK, split="test")
    result = problem.solve(task, initializer, max_iter=100)
    assert "restarted from the initialiser's fallback guess" in result.message
    assert result.status.solved, result.message
    # Both solves are paid for: the first's iterations, then the restart's.
    assert after < result.iterations <= 100
    assert result.history[-1]["iteration"] == result.iterations
    # The restart's starting point shares its number with the first solve's
    # last iteration; the entries say which solve they belong to, and time runs on.
    first = [h for h in result.history if h["solve"] == 0.0]
    second = [h for h in result.history if h["solve"] == 1.0]
    assert first and second and len(first) + len(second) == len(result.history)
    assert second[0]["iteration"] == first[-1]["iteration"]
    elapsed = [h["elapsed_s"] for h in result.history]
    assert all(b >= a for a, b in zip(elapsed, elapsed[1:], strict=False))


def test_experience_runs_from_a_model_fall_back_too(tmp_path: Path) -> None:
    data = run_one_held_out_task(tmp_path / "run", STUCK_TASK)
    assert data["status"][0] in ("exact", "approximate")
    assert data["iterations"][0] > _fallback_after(shipped_pallet_spec())


def _fallback_after(spec: ProblemSpec) -> int:
    after = build_problem(spec).config.solver.guess_fallback_after
    assert after is not None
    return after


def test_a_model_without_a_library_has_no_fallback() -> None:
    model = load_model(MODEL).network_only()
    assert model.library is None
    initializer = LearnedInitializer()
    initializer.model = model
    spec = ProblemSpec("anymal_c", "single_pallet", "walk", 16, 5.5)
    problem = build_problem(
        replace(spec, constraints=constraints_for_model(model, spec.config().constraints))
    )
    assert not initializer.has_fallback(problem.formulation)


def test_fallback_after_must_be_positive_or_none() -> None:
    assert SolverOptions(guess_fallback_after=None).guess_fallback_after is None
    with pytest.raises(ConfigError, match="guess_fallback_after"):
        SolverOptions(guess_fallback_after=0)
