"""An environment's walk (steps, horizon) lives in its task space and reaches its far starts."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _benchmarks import load_benchmark
from scipy.optimize import linprog

from roughwalk.learning import TaskSpace, task_space
from roughwalk.learning.problem_spec import ProblemSpec, _ground
from roughwalk.trajopt import make_gait


def _farthest_travel(env: str, dt: float = 0.01) -> float:
    """The most [m] the base can advance along x in ``env``'s walk, feet kept in their box.

    A stance foot stays put, so while it is in stance the base advances at
    most the range-of-motion box's length along x (its first stance half
    of it, from the nominal start stance); a linear programme over the
    base's advance per time step, on flat ground, before any climb.
    """
    space = task_space(env)
    body, _ = _ground(ProblemSpec("anymal_c", space.terrain, "walk", space.steps, space.duration))
    box = 2 * body.max_deviation[0]
    gait = make_gait("walk", space.steps, space.duration)
    t = np.arange(int(round(space.duration / dt))) * dt
    rows, bounds = [], []
    for durations, in_contact in zip(gait.durations, gait.in_contact_at_start, strict=True):
        edges = np.concatenate([[0.0], np.cumsum(durations)])
        for k in range(len(durations)):
            if (k % 2 == 0) == in_contact:
                rows.append(((t >= edges[k]) & (t < edges[k + 1])).astype(float))
                bounds.append(box / 2 if k == 0 else box)
    n = len(t)
    best = linprog(-np.ones(n), A_ub=np.array(rows), b_ub=bounds, bounds=[(0, None)] * n)
    return float(-best.fun)


def test_the_double_pallet_walk_reaches_past_its_farthest_start() -> None:
    # 16 steps advance the base 2.30 m at the very most, and the double
    # pallet's farthest start is 2.3 m from its goal: no margin for the two
    # climbs, and no solve from farther than 1.74 m converged (session 13).
    space = task_space("double_pallet")
    farthest = space.goal[0] - space.start_low[0]
    assert farthest == pytest.approx(2.3)
    assert _farthest_travel("double_pallet") >= farthest + 0.5
    # The single pallet's walk is the paper's: 16 steps in 5.5 s.
    single = task_space("single_pallet")
    assert (single.steps, single.duration) == (16, 5.5)
    # The double pallet keeps the pallets' time per step, 5.5 s / 16.
    assert space.duration / space.steps == pytest.approx(5.5 / 16)


def test_a_space_records_its_walk_only_when_it_is_not_the_pallets() -> None:
    double = task_space("double_pallet")
    assert TaskSpace.from_dict(double.to_dict()) == double
    assert double.to_dict()["steps"] == double.steps
    single = task_space("single_pallet")
    assert "steps" not in single.to_dict()  # runs recorded before the field resume
    assert TaskSpace.from_dict(single.to_dict()) == single


def test_init_generate_and_the_tracking_bench_use_the_environment_s_walk(tmp_path: Path) -> None:
    from roughwalk.cli.main import main

    space = task_space("double_pallet")
    argv = ["init", "generate", "--env", "double_pallet", "--tasks", "0", "--split", "test"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 0
    problem = json.loads((tmp_path / "run" / "run.json").read_text())["problem"]
    assert (problem["steps"], problem["duration"]) == (space.steps, space.duration)
    bench = load_benchmark("bench_tracking")
    task = space.task(0)
    job = bench.Job(
        "double_pallet", "double_pallet", "heuristic", 0, False, 0, task.start, task.goal
    )
    config = bench.job_config(job)
    assert (config.steps, config.duration) == (space.steps, space.duration)
    assert bench.walk("flat") == (16, 5.5)


def test_the_tracking_bench_finds_a_shipped_model_of_the_double_pallet_s_walk() -> None:
    from roughwalk.learning.initializer import model_for_spec

    bench = load_benchmark("bench_tracking")
    assert bench.learned_model_for("double_pallet", False) == ""
    model = model_for_spec("learned", bench._spec("double_pallet", False))
    space = task_space("double_pallet")
    assert model.header["problem"]["steps"] == space.steps == 20
    assert model.header["problem"]["duration"] == space.duration
    # The walk's trunk may come within 0.5 h of a swinging foot, and its model is trained so.
    assert model.header["problem"]["swing_base_clearance"] == space.swing_base_clearance == 0.5
    assert (
        bench.job_config(
            bench.Job(
                "double_pallet", "double_pallet", "learned", 0, False, 0, (0, 0, 0), space.goal
            )
        ).swing_base_clearance
        == 0.5
    )


def test_the_single_pallet_walk_has_its_own_model_at_0_5_whose_forces_cannot_pull() -> None:
    from roughwalk.learning.initializer import model_for_spec

    bench = load_benchmark("bench_tracking")
    space = task_space("single_pallet")
    assert space.swing_base_clearance == 0.5
    assert bench.learned_model_for("single_pallet", False) == ""
    model = model_for_spec("learned", bench._spec("single_pallet", False))
    assert model.header["problem"]["swing_base_clearance"] == 0.5
    # Converged plans of the tasks that fell tracked to ~1 cm only once the
    # forces could not pull between nodes (session 17): the model is trained
    # so, and the bench solves every start of the environment so.
    constraints, _ = bench.learned_problem("single_pallet", False)
    assert constraints is not None and "unilateral_between_nodes" in constraints
    assert "unilateral_between_nodes" in model.header["constraints"]
    # The 0.7 model stays for roughwalk optimize's default clearance.
    default = model_for_spec("learned", ProblemSpec("anymal_c", "single_pallet", "walk", 16, 5.5))
    assert default.header["problem"].get("swing_base_clearance") is None


def test_the_init_bench_takes_the_shipped_model_of_the_environment_s_walk() -> None:
    # The 16-step double-pallet model stays shipped (roughwalk optimize's
    # default walk); the bench must not hand its guesses to the 20-step NLP.
    bench = load_benchmark("bench_init")
    for env in ("double_pallet", "single_pallet"):
        space = task_space(env)
        models = bench._models(None, space)
        assert len(models) == 1
        problem = models[0][1].header["problem"]
        assert (problem["steps"], problem["duration"]) == (space.steps, space.duration)


def test_the_init_bench_measures_the_walk_at_the_clearance_it_is_given() -> None:
    # The README's init row was measured on the single pallet's 0.7 problem;
    # since session 17 the walk plans at 0.5, and --swing-base-clearance none
    # measures the 0.7 problem and its model again.
    bench = load_benchmark("bench_init")
    ours = bench.walk_space("single_pallet")
    assert ours.swing_base_clearance == 0.5
    (model,) = bench._models(None, ours)
    assert model[1].header["problem"]["swing_base_clearance"] == 0.5
    default = bench.walk_space("single_pallet", "none")
    assert default.swing_base_clearance is None
    (model,) = bench._models(None, default)
    assert model[1].header["problem"].get("swing_base_clearance") is None
    assert bench.spec_of_models(default, [model]).swing_base_clearance is None
    assert bench.walk_space("single_pallet", "0.6").swing_base_clearance == 0.6
    assert bench._models(None, bench.walk_space("single_pallet", "0.6")) == []
    with pytest.raises(SystemExit, match="--swing-base-clearance"):
        bench.walk_space("single_pallet", "low")


def test_the_tracking_bench_finds_the_single_pallet_s_optimised_duration_model() -> None:
    # Melon et al.'s Fig. 8 executes plans with optimised phase durations too;
    # the bench's learned point there needs a model of that NLP (its layout
    # holds the phase durations), not the fixed-duration walk's.
    from roughwalk.learning.initializer import model_for_spec

    bench = load_benchmark("bench_tracking")
    space = task_space("single_pallet")
    assert bench.learned_model_for("single_pallet", True) == ""
    model = model_for_spec("learned", bench._spec("single_pallet", True))
    problem = model.header["problem"]
    assert problem["optimize_durations"] is True
    assert (problem["steps"], problem["duration"]) == (space.steps, space.duration)
    assert problem["swing_base_clearance"] == space.swing_base_clearance == 0.5
    durations = [size for name, size in model.header["layout"] if name.startswith("durations_")]
    assert len(durations) == 4 and min(durations) > 0
    # Trained on the fixed-duration walk's constraint set, so the bench's
    # heuristic and learned starts solve the same NLP.
    constraints, _ = bench.learned_problem("single_pallet", True)
    assert constraints is not None and "unilateral_between_nodes" in constraints
    # The fixed-duration walk keeps its own model.
    fixed = model_for_spec("learned", bench._spec("single_pallet", False))
    assert fixed.header["problem"]["optimize_durations"] is False
