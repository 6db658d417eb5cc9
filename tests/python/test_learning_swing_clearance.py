"""``swing_base_clearance`` is part of a learned problem: runs and models record it, and a
model trained under one value is refused by a problem under another."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from _learned_models import SPEC, heuristic_guess_model

from roughwalk.cli.main import main
from roughwalk.errors import ConfigError
from roughwalk.learning import ProblemSpec, TaskSpace, build_problem, generate
from roughwalk.learning.initializer import model_for_spec
from roughwalk.learning.model_file import problem_signature
from roughwalk.learning.problem_spec import cost_weights, nlp_settings

LOW = replace(SPEC, swing_base_clearance=0.5)
SPACE = TaskSpace("flat_small", "flat", (-0.1, -0.1, -0.2), (0.1, 0.1, 0.2), (0.4, 0.0, 0.0))


def test_init_generate_takes_the_clearance_as_a_set_item_and_records_it(tmp_path: Path) -> None:
    argv = ["init", "generate", "--env", "flat", "--goal", "0.4,0,0", "--steps", "4"]
    argv += ["--duration", "2", "--tasks", "0", "--set", "swing_base_clearance=0.5"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 0
    problem = json.loads((tmp_path / "run" / "run.json").read_text())["problem"]
    assert problem["swing_base_clearance"] == 0.5
    assert ProblemSpec.from_dict(problem) == LOW
    assert LOW.config().swing_base_clearance == 0.5
    # Runs and models made before the field (None: as base_clearance) read as before.
    assert "swing_base_clearance" not in SPEC.to_dict()
    assert nlp_settings(["swing_base_clearance=0.5", "costs.force.weight=0.1"]) == {
        "swing_base_clearance": 0.5
    }
    assert cost_weights(["swing_base_clearance=0.5"]) is None
    with pytest.raises(ConfigError, match="swing_base_clearance"):
        nlp_settings(["swing_base_clearance=-1"])


def test_a_model_is_refused_by_a_problem_at_another_clearance(tmp_path: Path) -> None:
    old = heuristic_guess_model()  # header as before the field: trained at None
    old.save(tmp_path / "old.npz")
    low = heuristic_guess_model(problem=LOW.to_dict())
    low.save(tmp_path / "low.npz")
    assert model_for_spec(f"learned:{tmp_path / 'old.npz'}", SPEC)
    assert model_for_spec(f"learned:{tmp_path / 'low.npz'}", LOW)
    with pytest.raises(ConfigError, match="swing_base_clearance is None in the model but 0.5"):
        model_for_spec(f"learned:{tmp_path / 'old.npz'}", LOW)
    with pytest.raises(ConfigError, match="swing_base_clearance is 0.5 in the model but None"):
        model_for_spec(f"learned:{tmp_path / 'low.npz'}", SPEC)
    # The built NLP's signature (what the initialiser checks before its guess) says it too.
    signature = problem_signature(build_problem(LOW).formulation)
    assert signature["swing_base_clearance"] == 0.5
    assert old.mismatches(signature) == ["swing_base_clearance is None in the model but 0.5 here"]
    assert not low.mismatches(signature)


def test_nearest_starts_take_seed_solves_made_at_another_clearance(tmp_path: Path) -> None:
    seed = generate(SPEC, SPACE, 1, tmp_path / "seed", progress=None, max_iter=60)
    assert seed["max_violation"][0] < 1e-3
    data = generate(LOW, SPACE, 1, tmp_path / "low", progress=None, seeds=[tmp_path / "seed"])
    # A seed solve is a start, not training data: the run records its own problem.
    np.testing.assert_array_equal(data["x0"][0], seed["x"][0])
    assert json.loads((tmp_path / "low" / "run.json").read_text())["problem"] == LOW.to_dict()
    # Another walk (a different variable layout) is still refused.
    other = replace(SPEC, duration=2.5)
    with pytest.raises(ConfigError, match="another problem"):
        generate(other, SPACE, 1, tmp_path / "x", progress=None, seeds=[tmp_path / "seed"])


def test_the_tracking_bench_solves_and_picks_models_at_the_walk_s_clearance() -> None:
    from _benchmarks import load_benchmark

    bench = load_benchmark("bench_tracking")
    space = replace(SPACE, swing_base_clearance=0.5)
    assert TaskSpace.from_dict(space.to_dict()) == space
    assert "swing_base_clearance" not in SPACE.to_dict()  # runs before the field resume
    # --trajopt's clearance reaches the problem a learned model must fit ...
    low = bench._spec("single_pallet", False, (("swing_base_clearance", "0.4"),))
    assert low.swing_base_clearance == 0.4
    why = bench.learned_model_for(
        "single_pallet", False, "learned", (("swing_base_clearance", "0.4"),)
    )
    assert "no shipped learned model fits" in why
    assert "5.5 s, swing_base_clearance 0.4; shipped" in why
    # ... and an environment's walk brings its own to every solve.
    assert bench._spec("double_pallet", False).swing_base_clearance == (
        bench.swing_clearance("double_pallet")
    )
    task = SPACE.task(0)
    job = bench.Job(
        "double_pallet", "double_pallet", "heuristic", 0, False, 0, task.start, task.goal
    )
    assert bench.job_config(job).swing_base_clearance == bench.swing_clearance("double_pallet")
