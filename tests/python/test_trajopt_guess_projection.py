"""The guess projection: a guess moved onto the NLP's linearised rows before IPOPT starts."""

from __future__ import annotations

import numpy as np
import pytest
from _trajopt_problems import pallet_edge_climb

from roughwalk.errors import ConfigError, PlanningError
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    GuessProjection,
    HeuristicInitializer,
    TerrainModel,
    make_gait,
    melon_config,
    optimize_motion,
)
from roughwalk.trajopt.guess_projection import between_node_rows, project_guess
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS
from roughwalk.trajopt.task import Task, resolve

# force_between_nodes is in the set only so that its violation can be read off g.
WITH_BETWEEN = (*MELON_REACH_CONSTRAINTS, "force_between_nodes")


def _violation(nlp: Formulation, x: np.ndarray, p: np.ndarray, name: str) -> float:
    g = np.asarray(nlp.evaluator(x, p)[1]).ravel()
    rows = nlp.row_slices()[name]
    return float(max((nlp.lbg[rows] - g[rows]).max(), (g[rows] - nlp.ubg[rows]).max(), 0.0))


@pytest.fixture(scope="module")
def flat_walk() -> tuple[Formulation, np.ndarray, np.ndarray]:
    """A 4-step flat walk whose guessed forces slide, pull and miss the dynamics."""
    config = melon_config(duration=2.0, steps=4, constraints=WITH_BETWEEN)
    flat = TerrainModel(load_terrain("flat"))
    nlp = Formulation(config, TOWR_ANYMAL, make_gait("walk", 4, 2.0), flat)
    task = resolve(Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)), TOWR_ANYMAL, flat)
    parts = nlp.split(HeuristicInitializer().guess(nlp, task))
    rng = np.random.default_rng(3)
    for force in nlp.forces:
        pos, vel = force.unpack(parts[force.name])
        # What the learned guesses do: hundreds of newtons sideways, steep rates.
        pos[:, :2] += rng.normal(scale=150.0, size=pos[:, :2].shape)
        vel += rng.normal(scale=3000.0, size=vel.shape)
        parts[force.name] = force.pack(pos, vel)
    return nlp, nlp.join(parts), task.vector()


def test_projection_puts_forces_inside_the_pyramid_everywhere(
    flat_walk: tuple[Formulation, np.ndarray, np.ndarray],
) -> None:
    nlp, x0, p = flat_walk
    before = {n: _violation(nlp, x0, p, n) for n in ("force", "force_between_nodes", "dynamics")}
    assert before["force"] > 50.0 and before["force_between_nodes"] > 200.0
    x = project_guess(nlp, x0, p, GuessProjection(steps=2))
    after = {n: _violation(nlp, x, p, n) for n in before}
    # The pyramid rows are linear on flat ground: the projection meets them.
    assert after["force"] < 1.0 and after["force_between_nodes"] < 1.0
    assert after["dynamics"] < 0.1 * before["dynamics"]
    # The forces gave way; the base's path moved by centimetres (the walk is 30 cm).
    base = nlp.base_lin
    pos0, _ = base.unpack(nlp.split(x0)[base.name])
    pos, _ = base.unpack(nlp.split(x)[base.name])
    assert np.abs(pos - pos0).max() < 0.1


def test_no_steps_is_the_guess_itself(
    flat_walk: tuple[Formulation, np.ndarray, np.ndarray],
) -> None:
    nlp, x0, p = flat_walk
    assert project_guess(nlp, x0, p, GuessProjection(steps=0)) is x0


def test_between_node_rows_are_the_constraints_rows_on_a_pallet_edge() -> None:
    # The projection's own rows (terrain basis at the footholds) against
    # force_between_nodes' on an edge foothold, where the basis is tilted.
    config = melon_config(constraints=WITH_BETWEEN)
    nlp, parts, task = pallet_edge_climb(config)
    x = nlp.join(parts)
    rng = np.random.default_rng(0)
    for force in nlp.forces:
        parts[force.name] = parts[force.name] + rng.normal(scale=100.0, size=force.size)
    x = nlp.join(parts)
    values, jac, lower, upper = between_node_rows(nlp, x, nlp.body.friction, nlp.body.force_limit)
    g = np.asarray(nlp.evaluator(x, task.vector())[1]).ravel()
    rows = nlp.row_slices()["force_between_nodes"]
    np.testing.assert_allclose(values, g[rows], atol=1e-6)
    np.testing.assert_array_equal(lower, nlp.lbg[rows])
    np.testing.assert_array_equal(upper, nlp.ubg[rows])
    assert jac.shape == (values.size, nlp.n_variables)


def test_settings_are_checked() -> None:
    with pytest.raises(ConfigError, match="steps"):
        GuessProjection(steps=-1)
    with pytest.raises(ConfigError, match="force_n"):
        GuessProjection(force_n=0.0)


def test_optimize_motion_projects_the_guess_when_asked() -> None:
    # With no IPOPT iteration the result is the guess: projected, it meets
    # the dynamics at the knots that the heuristic guess misses.
    task = Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
    results = {
        steps: optimize_motion(
            None,
            "flat",
            task,
            config=melon_config(duration=2.0, steps=4, body_model="towr_anymal"),
            init="heuristic",
            max_iter=0,
            guess_projection__steps=steps,
        )
        for steps in (0, 1)
    }
    before, after = (results[s].violations for s in (0, 1))
    assert before["dynamics"] > 10.0
    assert after["dynamics"] < 0.1 * before["dynamics"]
    assert after["force"] < 1.0


def test_left_out_rows_keep_the_guess_s_violation(
    flat_walk: tuple[Formulation, np.ndarray, np.ndarray],
) -> None:
    # A guess that starts 5 cm ahead of the task's start: projected, it starts
    # there; with initial_state left out it keeps its own start.
    nlp, x0, p = flat_walk
    parts = nlp.split(x0)
    base = nlp.base_lin
    pos, vel = base.unpack(parts[base.name])
    pos[:, 0] += 0.05
    parts[base.name] = base.pack(pos, vel)
    shifted = nlp.join(parts)
    assert _violation(nlp, shifted, p, "initial_state") > 0.04
    moved = project_guess(nlp, shifted, p, GuessProjection(steps=1))
    kept = project_guess(nlp, shifted, p, GuessProjection(steps=1, left_out=("initial_state",)))
    assert _violation(nlp, moved, p, "initial_state") < 0.005
    assert _violation(nlp, kept, p, "initial_state") > 0.04
    assert _violation(nlp, kept, p, "force_between_nodes") < 1.0


def test_an_unknown_left_out_name_is_refused(
    flat_walk: tuple[Formulation, np.ndarray, np.ndarray],
) -> None:
    nlp, x0, p = flat_walk
    with pytest.raises(PlanningError, match="'initial_stat'.*initial_state"):
        project_guess(nlp, x0, p, GuessProjection(steps=1, left_out=("initial_stat",)))
