"""A learned guess is solved with the constraint set its model was trained on."""

from __future__ import annotations

from pathlib import Path

from _learned_models import SPEC, heuristic_guess_model

import roughwalk
from roughwalk.learning import LearnedModel, ProblemSpec
from roughwalk.learning.model_constraints import constraints_for_model, spec_for_learned
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS, TOWR_CONSTRAINTS

WITH_FORCES = (*MELON_REACH_CONSTRAINTS, "force_between_nodes")


def _model(constraints: tuple[str, ...] | None) -> LearnedModel:
    return heuristic_guess_model(constraints=None if constraints is None else list(constraints))


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
    assert "guess from learned model 'with_forces'" in result.message  # which model
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
