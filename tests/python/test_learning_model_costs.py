"""A learned guess is solved with the cost weights its model was trained with."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from _learned_models import SPEC, heuristic_guess_model

import roughwalk
from roughwalk.config import override
from roughwalk.learning import LearnedModel, ProblemSpec, task_space
from roughwalk.learning.experience import generate
from roughwalk.learning.model_costs import cost_changes, costs_for_model, recorded_costs
from roughwalk.trajopt.parameters import melon_config

PENALTY = {"force_between_nodes_penalty": 10.0}


def _model(costs: dict[str, float] | None) -> LearnedModel:
    return heuristic_guess_model(costs=None if costs is None else costs)


def test_recorded_weights_survive_a_save_and_load(tmp_path: Path) -> None:
    loaded = LearnedModel.load(_model(PENALTY).save(tmp_path / "penalty.npz"))
    assert recorded_costs(loaded) == PENALTY
    old = LearnedModel.load(_model(None).save(tmp_path / "old.npz"))
    assert recorded_costs(old) is None
    assert costs_for_model(old, melon_config().costs) == melon_config().costs


def test_recorded_weights_replace_defaults_but_not_chosen_ones() -> None:
    model = _model({"force_between_nodes_penalty": 10.0, "force.weight": 0.2})
    default = melon_config().costs
    applied = costs_for_model(model, default)
    assert applied.force_between_nodes_penalty == 10.0
    assert applied.force.weight == 0.2
    assert cost_changes(applied) == {"force_between_nodes_penalty": 10.0, "force.weight": 0.2}
    chosen = costs_for_model(model, override(melon_config().costs, {"force.weight": 0.07}))
    assert chosen.force.weight == 0.07
    assert chosen.force_between_nodes_penalty == 10.0


def test_a_solve_from_the_model_uses_the_recorded_weight_unless_overridden(
    tmp_path: Path,
) -> None:
    path = _model(PENALTY).save(tmp_path / "penalty.npz")
    problem = {"gait": "walk", "steps": 4, "duration": 2.0, "max_iter": 0}
    task = ((0, 0, 0), (0.4, 0, 0))
    result = roughwalk.optimize_motion("anymal_c", "flat", task, init=f"learned:{path}", **problem)
    assert result.config["costs"]["force_between_nodes_penalty"] == 10.0
    assert "force_between_nodes_penalty" in result.costs
    mine = roughwalk.optimize_motion(
        "anymal_c",
        "flat",
        task,
        init=f"learned:{path}",
        costs__force_between_nodes_penalty=3.0,
        **problem,
    )
    assert mine.config["costs"]["force_between_nodes_penalty"] == 3.0
    plain = roughwalk.optimize_motion("anymal_c", "flat", task, init="heuristic", **problem)
    assert plain.config["costs"]["force_between_nodes_penalty"] == 0.0
    assert "force_between_nodes_penalty" not in plain.costs  # the term exists only if weighed


def test_a_spec_s_weights_reach_its_config_and_the_run_record(tmp_path: Path) -> None:
    spec = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0, costs=tuple(PENALTY.items()))
    assert spec.config().costs.force_between_nodes_penalty == 10.0
    assert ProblemSpec.from_dict(spec.to_dict()) == spec
    assert "costs" not in SPEC.to_dict()
    generate(spec, task_space("flat"), 0, tmp_path / "run", split="test", progress=None)
    meta = json.loads((tmp_path / "run" / "run.json").read_text())
    assert meta["costs"] == PENALTY
    generate(SPEC, task_space("flat"), 0, tmp_path / "plain", split="test", progress=None)
    assert "costs" not in json.loads((tmp_path / "plain" / "run.json").read_text())


def test_init_generate_sets_weights_as_optimize_does_and_names_a_bad_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from roughwalk.cli.main import main

    run = tmp_path / "run"
    argv = ["init", "generate", "--env", "flat", "--steps", "4", "--duration", "2.0"]
    argv += ["--tasks", "0", "--split", "test", "--out", str(run)]
    assert main([*argv, "--set", "costs.force_between_nodes_penalty=10"]) == 0
    meta = json.loads((run / "run.json").read_text())
    assert meta["costs"] == PENALTY
    assert meta["problem"]["costs"] == PENALTY
    capsys.readouterr()
    assert main([*argv, "--set", "costs.force.wieght=0.1"]) == 1
    assert "costs.force.wieght=0.1: not a cost weight" in capsys.readouterr().err
    assert main([*argv, "--set", "costs.force.weight=abc"]) == 1
    assert "costs.force.weight=abc" in capsys.readouterr().err
