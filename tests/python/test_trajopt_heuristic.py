"""The heuristic guess: footholds under the base on level ground, evenly spaced elsewhere."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from roughwalk.errors import ConfigError
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    Task,
    TerrainModel,
    make_gait,
    optimize_motion,
    towr_config,
)
from roughwalk.trajopt.task import resolve

# TOWR's flat trot (issue 8): 16 steps, T = 3.5 s, 1.5 m ahead.
TROT = {"gait": "trot", "steps": 16, "duration": 3.5}
TASK = Task((0.0, 0.0, 0.0), (1.5, 0.0, 0.0))


def _guess(terrain_name: str, argument: str | None) -> tuple[Formulation, np.ndarray, np.ndarray]:
    """TOWR's trot problem on ``terrain_name``, its heuristic guess and task vector."""
    config = towr_config()
    terrain = TerrainModel(load_terrain(terrain_name), config.terrain, config.costs.step_edge_sigma)
    nlp = Formulation(config, TOWR_ANYMAL, make_gait("trot", 16, 3.5), terrain)
    task = resolve(TASK, TOWR_ANYMAL, terrain)
    return nlp, HeuristicInitializer(argument).guess(nlp, task), task.vector()


def _range_of_motion_margins(nlp: Formulation, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Each range-of-motion row's distance inside its box [m] (negative: outside)."""
    _, g, _ = nlp.evaluator(x, p)
    rows = nlp.row_slices()["range_of_motion"]
    g = np.asarray(g).ravel()[rows]
    return np.minimum(g - nlp.lbg[rows], nlp.ubg[rows] - g)


def test_level_footholds_keep_the_trots_feet_inside_their_box() -> None:
    # Evenly spaced footholds put a trot's diagonal pairs half a step out of
    # phase with the base: 38 rows within 1 cm of the box's side or beyond,
    # against 8 with each foothold under the base at the middle of its stance
    # (those left are the first stance's, fixed at the start while the base
    # sets off).
    under = _range_of_motion_margins(*_guess("flat", None))
    even = _range_of_motion_margins(*_guess("flat", "even"))
    assert np.sum(under < 0.01) <= 10
    assert np.sum(even < 0.01) >= 3 * np.sum(under < 0.01)


def test_uneven_ground_keeps_the_even_footholds() -> None:
    # On TOWR's gap the footholds under the base fall into the gap (its walk
    # and bound then stop at the 40 s limit): the guess there is unchanged.
    nlp, under, _ = _guess("towr_gap", None)
    _, even, _ = _guess("towr_gap", "even")
    np.testing.assert_array_equal(under, even)
    _, flat_under, _ = _guess("flat", None)
    _, flat_even, _ = _guess("flat", "even")
    assert not np.array_equal(flat_under, flat_even)


def test_only_even_is_an_argument() -> None:
    with pytest.raises(ConfigError):
        HeuristicInitializer("uneven")


def test_towr_flat_trot_solves_in_fewer_iterations_than_towr() -> None:
    # TOWR 1.4 takes 13 iterations on this task; from the evenly spaced
    # footholds IPOPT took 22, from the level ones 11.
    config = towr_config()
    result = optimize_motion(None, "flat", TASK, config=config, **TROT)
    assert result.solved and result.max_violation <= config.solver.constr_viol_tol
    assert result.iterations <= 13
    even = replace(config, init="heuristic:even")
    assert optimize_motion(None, "flat", TASK, config=even, **TROT).iterations > 13
