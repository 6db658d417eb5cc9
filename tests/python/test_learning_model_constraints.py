"""A learned guess is solved with the constraint set its model was trained on."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import roughwalk
from roughwalk.learning import LearnedModel, ProblemSpec, build_problem
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_constraints import constraints_for_model, spec_for_learned
from roughwalk.learning.model_file import MODEL_FORMAT, problem_signature
from roughwalk.trajopt import HeuristicInitializer, Task
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS, TOWR_CONSTRAINTS
from roughwalk.trajopt.task import resolve

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
WITH_FORCES = (*MELON_REACH_CONSTRAINTS, "force_between_nodes")


def _model(constraints: tuple[str, ...] | None) -> LearnedModel:
    """A model whose every prediction is the heuristic's guess of one task (a sane start)."""
    problem = build_problem(SPEC)
    nlp = problem.formulation
    n_out = nlp.n_variables
    guess = HeuristicInitializer().guess(
        nlp, resolve(Task((0, 0, 0), (0.4, 0, 0)), problem.body, problem.terrain)
    )
    weights = (np.zeros((6, 5), np.float32), np.zeros((5, n_out), np.float32))
    biases = (np.zeros(5, np.float32), np.zeros(n_out, np.float32))
    mlp = MLP(weights, biases, "tanh", np.zeros(6), np.ones(6), guess, np.ones(n_out))
    header: dict[str, object] = {
        "format": MODEL_FORMAT,
        "version": 1,
        "problem": SPEC.to_dict(),
        "layout": problem_signature(nlp)["layout"],
    }
    if constraints is not None:
        header["constraints"] = list(constraints)
    return LearnedModel(mlp, header)


def test_the_model_s_recorded_set_replaces_the_default_but_not_a_chosen_one() -> None:
    model = _model(WITH_FORCES)
    assert constraints_for_model(model, MELON_REACH_CONSTRAINTS) == WITH_FORCES
    assert constraints_for_model(model, TOWR_CONSTRAINTS) == TOWR_CONSTRAINTS
    assert constraints_for_model(_model(None), MELON_REACH_CONSTRAINTS) == MELON_REACH_CONSTRAINTS


def test_optimize_with_a_learned_model_solves_the_nlp_it_was_trained_on(tmp_path: Path) -> None:
    trained = _model(WITH_FORCES).save(tmp_path / "with_forces.npz")
    plain = _model(None).save(tmp_path / "plain.npz")
    problem = {"gait": "walk", "steps": 4, "duration": 2.0, "max_iter": 0}
    task = ((0, 0, 0), (0.4, 0, 0))
    result = roughwalk.optimize_motion(
        "anymal_c", "flat", task, init=f"learned:{trained}", **problem
    )
    assert tuple(result.config["constraints"]) == WITH_FORCES
    default = roughwalk.optimize_motion(
        "anymal_c", "flat", task, init=f"learned:{plain}", **problem
    )
    assert tuple(default.config["constraints"]) == MELON_REACH_CONSTRAINTS
    assert result.n_constraints > default.n_constraints
    chosen = roughwalk.optimize_motion(
        "anymal_c", "flat", task, init=f"learned:{trained}", constraints=TOWR_CONSTRAINTS, **problem
    )
    assert tuple(chosen.config["constraints"]) == TOWR_CONSTRAINTS


def test_a_spec_without_a_fitting_shipped_model_keeps_its_set() -> None:
    assert spec_for_learned(SPEC) == SPEC
    named = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0, constraints=TOWR_CONSTRAINTS)
    assert spec_for_learned(named) is named


def test_the_shipped_double_pallet_model_brings_its_unilateral_rows() -> None:
    # Trained on solves that do not pull between force nodes (so that the
    # controller can track them): every double-pallet solve from it keeps them.
    double = spec_for_learned(ProblemSpec("anymal_c", "double_pallet", "walk", 16, 5.5))
    assert double.constraints == (*MELON_REACH_CONSTRAINTS, "unilateral_between_nodes")
    single = ProblemSpec("anymal_c", "single_pallet", "walk", 16, 5.5)
    assert spec_for_learned(single) == single
