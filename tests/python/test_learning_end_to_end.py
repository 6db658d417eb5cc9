"""Melon et al.'s Algorithm 1 end to end on a small problem: LearnedInit beats the heuristic.

40 flat-ground tasks (four steps in 2 s, a short walk) are solved from the
heuristic guess, filtered, learned by a tiny MLP; held-out tasks then
converge from the learned guess in fewer IPOPT iterations than from the
heuristic, to the same optimum.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import roughwalk
from roughwalk.learning import (
    LearnedModel,
    ProblemSpec,
    TaskSpace,
    filter_good,
    generate,
    learned_init_rounds,
    train_model,
)
from roughwalk.trajopt import Task

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
SPACE = TaskSpace("flat_small", "flat", (-0.1, -0.1, -0.2), (0.1, 0.1, 0.2), (0.4, 0.0, 0.0))
LIMIT = 60


@pytest.fixture(scope="module")
def experience(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("experience") / "run"
    generate(SPEC, SPACE, 40, folder, progress=None, max_iter=LIMIT)
    return folder


def test_learned_init_converges_in_fewer_iterations_on_held_out_tasks(
    experience: Path, tmp_path: Path
) -> None:
    from roughwalk.learning.experience import read_run

    data = read_run(experience)
    assert len(data) == 40
    model, report = train_model(data, layers=(16, 16), max_epochs=300)
    assert report.n_good >= 20, report.summary()
    path = model.save(tmp_path / "tiny.npz")
    options: dict[str, Any] = {"gait": "walk", "steps": 4, "duration": 2.0, "max_iter": LIMIT}
    iterations: dict[str, list[int]] = {"heuristic": [], f"learned:{path}": []}
    for i in range(6):
        task = SPACE.task(i, split="test")
        for init, counts in iterations.items():
            result = roughwalk.optimize_motion("anymal_c", "flat", task, init=init, **options)
            # An unsolved task counts as the whole budget.
            counts.append(result.iterations if result.solved else LIMIT)
            if init != "heuristic":
                assert result.solved and result.objective < report.g_max
    heuristic, learned = iterations.values()
    assert np.mean(learned) < np.mean(heuristic), iterations


def test_library_model_restarts_a_training_task_from_its_own_solution(
    experience: Path, tmp_path: Path
) -> None:
    from roughwalk.learning.experience import read_run

    data = read_run(experience)
    model, report = train_model(data, layers=(16, 16), max_epochs=50, library=True)
    assert model.library is not None and len(model.library) == report.n_good
    # The task's own solution, not the one of its candidates nearest the network's guess.
    model.library = replace(model.library, candidates=1)
    path = model.save(tmp_path / "library.npz")
    row = int(np.flatnonzero(np.isclose(data["cost"], np.min(data["cost"])))[0])
    task = (tuple(data["start"][row]), tuple(data["goal"][row]))
    guess = LearnedModel.load(path).predict(Task(*task))
    np.testing.assert_allclose(guess, data["x"][row], atol=1e-5)
    options: dict[str, Any] = {"gait": "walk", "steps": 4, "duration": 2.0, "max_iter": LIMIT}
    result = roughwalk.optimize_motion("anymal_c", "flat", task, init=f"learned:{path}", **options)
    # A KKT point with its multipliers: IPOPT's guess options take 2-5 iterations from one.
    assert result.solved and result.iterations <= 6, result.iterations
    assert result.objective == pytest.approx(data["cost"][row], rel=1e-3)


def test_iteration_rounds_write_models_that_reload(experience: Path, tmp_path: Path) -> None:
    rounds = learned_init_rounds(experience, tmp_path, rounds=2, n_tasks=12, width=8)
    assert [r.round for r in rounds] == [1, 2]
    first, second = (LearnedModel.load(r.model_path) for r in rounds)
    assert first.mlp.hidden_layers == (8, 8) and second.mlp.hidden_layers == (8, 8, 8)
    assert second.header["training"]["learned_init_round"] == 2
    assert second.header["training"]["source_init"] == "learned:learned_init_1.npz"
    # Round 2 learned from the re-solves of round 1's guesses with N_θ = 25.
    resolved = rounds[0].resolved
    assert resolved is not None and len(resolved) == 12
    assert int(resolved["iterations"].max()) <= 25
    assert filter_good(resolved, rounds[0].train.g_max).n_good >= 10


def test_cli_trains_a_library_model_of_round_two(experience: Path, tmp_path: Path) -> None:
    from roughwalk.cli.main import main
    from roughwalk.learning.experience import read_run

    model = tmp_path / "library.npz"
    args = ["init", "train", str(experience), "--out", str(model), "--layers", "8"]
    assert main([*args, "--max-epochs", "20", "--round", "2", "--library"]) == 0
    loaded = LearnedModel.load(model)
    training = loaded.header["training"]
    assert training["learned_init_round"] == 2
    # The library holds D_good: every kept task's own solution, row for row.
    assert loaded.library is not None and len(loaded.library) == training["n_good"]
    assert loaded.header["library"]["n_solutions"] == training["n_good"]
    data = read_run(experience)
    tasks = np.column_stack([data["start"], data["goal"]])
    for row in (0, len(loaded.library) - 1):
        match = np.flatnonzero(np.all(np.isclose(tasks, loaded.library.tasks[row]), axis=1))
        assert match.size == 1
        np.testing.assert_allclose(loaded.library.x[row], data["x"][match[0]], rtol=1e-6)


def test_cli_trains_a_model_that_optimize_uses(experience: Path, tmp_path: Path) -> None:
    from roughwalk.cli.main import main

    model = tmp_path / "cli.npz"
    args = [
        "init",
        "train",
        str(experience),
        "--out",
        str(model),
        "--layers",
        "8",
        "--max-epochs",
        "50",
    ]
    assert main(args) == 0
    assert LearnedModel.load(model).header["training"]["n_tasks"] == 40
    out = tmp_path / "result.json"
    code = main(
        [
            "optimize",
            "--terrain",
            "flat",
            "--steps",
            "4",
            "--duration",
            "2",
            "--start=0,0,0",
            "--goal",
            "0.4,0,0",
            "--init",
            f"learned:{model}",
            "--json",
            str(out),
        ]
    )
    assert code == 0 and out.is_file()
    # The same model on another step count is refused, naming it.
    assert (
        main(
            [
                "optimize",
                "--terrain",
                "flat",
                "--steps",
                "8",
                "--duration",
                "2",
                "--start=0,0,0",
                "--goal",
                "0.4,0,0",
                "--init",
                f"learned:{model}",
            ]
        )
        == 1
    )


def test_training_copies_the_run_s_cost_weights_into_the_header(
    experience: Path, tmp_path: Path
) -> None:
    from roughwalk.learning.experience import read_run
    from roughwalk.learning.model_costs import recorded_costs

    data = read_run(experience)
    assert "costs" not in data.meta  # solved with the default weights
    plain, _ = train_model(data, layers=(4,), max_epochs=5)
    assert recorded_costs(plain) is None
    data.meta["costs"] = {"force_between_nodes_penalty": 10.0}
    model, _ = train_model(data, layers=(4,), max_epochs=5)
    loaded = LearnedModel.load(model.save(tmp_path / "penalty.npz"))
    assert recorded_costs(loaded) == {"force_between_nodes_penalty": 10.0}
