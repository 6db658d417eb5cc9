"""A model with a solution library guesses the nearest training task's solution."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from roughwalk.errors import InvalidArgumentError
from roughwalk.learning import LearnedModel
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_file import MODEL_FORMAT
from roughwalk.learning.solution_library import SolutionLibrary
from roughwalk.trajopt import Task

N_X, N_G = 7, 4


def _library(candidates: int = 1) -> SolutionLibrary:
    # Three tasks; the start yaw varies ten times less than x, so the scaled
    # distance must weigh a yaw difference ten times more.
    goal = [1.6, 0.0, 0.0]
    tasks = [[-0.5, 0.0, 0.0, *goal], [0.5, 0.0, 0.0, *goal], [0.0, 0.0, 0.1, *goal]]
    x = np.arange(3)[:, None] * np.ones(N_X)
    lam_g = 10.0 + np.arange(3)[:, None] * np.ones(N_G)
    return SolutionLibrary.build(tasks, x, lam_g, candidates)


def _model(library: SolutionLibrary | None) -> LearnedModel:
    rng = np.random.default_rng(0)
    mlp = MLP(
        (rng.normal(size=(6, 3)).astype(np.float32), rng.normal(size=(3, N_X)).astype(np.float32)),
        (np.zeros(3, np.float32), np.zeros(N_X, np.float32)),
        "tanh",
        np.zeros(6),
        np.ones(6),
        np.zeros(N_X),
        np.ones(N_X),
    )
    header = {"format": MODEL_FORMAT, "version": 1, "problem": {}, "layout": []}
    return LearnedModel(mlp, header, None, library)


def test_nearest_task_is_found_in_the_spread_scaled_distance() -> None:
    lib = _library()
    # Unscaled, x = 0.22 is nearer task 2 (0.22 in x, 0.1 in yaw: 0.24) than
    # task 1 (0.28 in x); scaled by the spread (x 0.41, yaw 0.047), task 1.
    query = [[0.22, 0.0, 0.0, 1.6, 0.0, 0.0], [-0.4, 0.0, 0.0, 1.6, 0.0, 0.0]]
    unscaled = np.argmin(np.linalg.norm(np.array(query)[:, None] - lib.tasks[None], axis=2), 1)
    assert unscaled.tolist() == [2, 0]
    assert lib.nearest(query)[:, 0].tolist() == [1, 0]
    assert lib.nearest(query, 2).tolist() == [[1, 0], [0, 1]]


def test_pick_takes_the_candidate_solution_nearest_the_network_s_guess() -> None:
    """The nearest task's solution may lie in another basin; the guess's is preferred."""
    task = [[0.45, 0.0, 0.0, 1.6, 0.0, 0.0]]  # nearest task 1, then 0, then 2 (yaw)
    guess = np.full((1, N_X), 1.8)  # nearest solution: task 2's (all 2)
    scale = np.ones(N_X)
    assert _library(1).pick(task, guess, scale).tolist() == [1]
    assert _library(2).pick(task, guess, scale).tolist() == [1]
    assert _library(3).pick(task, guess, scale).tolist() == [2]
    assert _library(2).pick(task, np.full((1, N_X), -0.4), scale).tolist() == [0]


def test_library_model_guesses_the_neighbour_s_solution_and_multipliers(tmp_path: Path) -> None:
    model = LearnedModel.load(_model(_library()).save(tmp_path / "lib.npz"))
    assert model.library is not None and len(model.library) == 3
    task = Task((0.45, 0.0, 0.0), (1.6, 0.0, 0.0))
    np.testing.assert_array_equal(model.predict(task), np.ones(N_X))
    lam_x, lam_g = model.predict_multipliers([task])
    assert lam_x is not None and lam_g is not None
    np.testing.assert_array_equal(lam_g[0], np.full(N_G, 11.0))
    np.testing.assert_array_equal(lam_x[0], np.zeros(N_X))  # no multiplier network: none active
    # Without the library the same networks guess something else, and say
    # they have no multipliers.
    plain = LearnedModel.load(_model(None).save(tmp_path / "plain.npz"))
    assert plain.library is None
    assert not np.allclose(plain.predict(task), np.ones(N_X))
    assert plain.predict_multipliers([task]) == (None, None)
    assert model.fingerprint != plain.fingerprint


def test_library_of_mismatched_rows_is_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="as many"):
        SolutionLibrary.build(np.zeros((3, 6)), np.zeros((2, N_X)), np.zeros((3, N_G)))
