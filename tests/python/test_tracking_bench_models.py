"""The tracking bench's ``--models DIR``: a candidate model is run and solved with its own NLP."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from _benchmarks import load_benchmark

pytest.importorskip("roughwalk.learning")

from roughwalk.learning import LearnedModel  # noqa: E402
from roughwalk.learning.initializer import MODELS_DIR  # noqa: E402
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS  # noqa: E402

DOUBLE = MODELS_DIR / "anymal_c_double_pallet_walk20_swing05.npz"  # the walk's model


@pytest.fixture
def candidate(tmp_path: Path) -> Path:
    """A folder holding one double-pallet model under another name."""
    shutil.copy(DOUBLE, tmp_path / "candidate.npz")
    return tmp_path


def test_without_a_folder_the_shipped_model_is_used() -> None:
    bench = load_benchmark("bench_tracking")
    assert bench.learned_init("double_pallet", False, None) == "learned"


def test_the_folder_s_model_that_fits_the_problem_is_used(candidate: Path) -> None:
    bench = load_benchmark("bench_tracking")
    init = bench.learned_init("double_pallet", False, candidate)
    assert init == f"learned:{candidate / 'candidate.npz'}"
    assert bench.learned_model_for("double_pallet", False, init) == ""
    chosen, costs = bench.learned_problem("double_pallet", False, init)
    assert chosen == (*MELON_REACH_CONSTRAINTS, "unilateral_between_nodes", "joint_torques")
    assert costs is None  # the shipped model records no weights


def _double_pallet_model_with(
    bench: Any, costs: dict[str, float], folder: Path
) -> tuple[str, Any, Any]:
    """The shipped double-pallet model recording ``costs``, saved in ``folder``:
    its ``--init`` value, and the constraint set and weights the bench solves it with."""
    model = LearnedModel.load(DOUBLE)
    model.header["costs"] = costs
    model.save(folder / "recorded.npz")
    init = bench.learned_init("double_pallet", False, folder)
    constraints, recorded = bench.learned_problem("double_pallet", False, init)
    return init, constraints, recorded


def test_the_heuristic_start_solves_with_the_model_s_weights_too(tmp_path: Path) -> None:
    # Both starts must solve one NLP, objective included: a model trained with
    # a penalty gives it to the heuristic's jobs as well, and --trajopt wins.
    bench = load_benchmark("bench_tracking")
    init, constraints, costs = _double_pallet_model_with(
        bench, {"force_between_nodes_penalty": 10.0}, tmp_path
    )
    assert costs == (("force_between_nodes_penalty", 10.0),)
    task = {"max_iter": 0, "optimize_durations": False, "index": 0}
    task |= {"start": (0.0, 0.0, 0.0), "goal": (1.0, 0.0, 0.0)}
    jobs = [
        bench.Job(
            "double_pallet", "double_pallet", name, **task, constraints=constraints, costs=costs
        )
        for name in ("heuristic", init)
    ]
    configs = [bench.job_config(job) for job in jobs]
    assert configs[0] == configs[1]
    assert configs[0].costs.force_between_nodes_penalty == 10.0
    trajopt = bench._trajopt_settings("costs.force_between_nodes_penalty=3,costs.swing_height=4")
    mine = bench.job_config(replace(jobs[0], trajopt=trajopt))
    assert mine.costs.force_between_nodes_penalty == 3.0
    assert mine.costs.swing_height == 4.0
    untouched = bench._trajopt_settings("costs.swing_height=4")
    kept = bench.job_config(replace(jobs[0], trajopt=untouched))
    assert kept.costs.force_between_nodes_penalty == 10.0


def test_a_two_level_trajopt_weight_wins_over_the_model_s_recorded_one(tmp_path: Path) -> None:
    bench = load_benchmark("bench_tracking")
    _, constraints, costs = _double_pallet_model_with(bench, {"force.weight": 0.2}, tmp_path)
    job = bench.Job(
        "double_pallet", "double_pallet", "heuristic", 0, False, 0, (0.0, 0.0, 0.0),
        (1.0, 0.0, 0.0), constraints=constraints, costs=costs,
    )  # fmt: skip
    assert bench.job_config(job).costs.force.weight == 0.2
    trajopt = bench._trajopt_settings("costs.force.weight=0.3")
    assert bench.job_config(replace(job, trajopt=trajopt)).costs.force.weight == 0.3


def test_a_folder_without_a_fitting_model_is_reported_not_replaced(candidate: Path) -> None:
    bench = load_benchmark("bench_tracking")
    init = bench.learned_init("single_pallet", False, candidate)
    assert init == f"learned:{candidate}"
    assert bench.learned_model_for("single_pallet", False, init) != ""


def test_a_job_whose_model_cannot_be_loaded_is_a_failed_row_not_a_crash(tmp_path: Path) -> None:
    bench = load_benchmark("bench_tracking")
    terrain, tasks, _ = bench.held_out_tasks("flat", 1, 0)
    task = tasks[0]
    missing = f"learned:{tmp_path / 'missing.npz'}"
    job = bench.Job(
        "flat", terrain, missing, 0, False, 0, task.start, task.goal, (), None, (), (), None
    )
    row = bench.run_job(job)
    assert row["success"] is False
    assert row["reason"].startswith("solve raised ConfigError")
    assert "missing.npz" in row["reason"]
    assert row["model"] is None
