"""The soft friction pyramid between force nodes: its value, its derivatives, and a pallet plan."""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np
import pytest
from _trajopt_problems import pallet_edge_climb

from roughwalk.robots import load_robot
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    Task,
    TerrainModel,
    make_gait,
    melon_config,
    optimize_motion,
)
from roughwalk.trajopt.parameters import CostWeights, TrajoptConfig
from roughwalk.trajopt.task import resolve

WEIGHT = 10.0


def _config(weight: float, **changes: object) -> TrajoptConfig:
    config = melon_config(**changes)
    return replace(config, costs=replace(config.costs, force_between_nodes_penalty=weight))


def _penalty(nlp: Formulation, x: np.ndarray, p: np.ndarray) -> float:
    names = [c.name for c in nlp.costs]
    return float(
        np.asarray(nlp.evaluator(x, p)[2]).ravel()[names.index("force_between_nodes_penalty")]
    )


def test_off_by_default_and_weights_are_checked() -> None:
    assert CostWeights().force_between_nodes_penalty == 0.0
    with pytest.raises(Exception, match="force_between_nodes_penalty"):
        CostWeights(force_between_nodes_penalty=-1.0)


def test_value_is_the_squared_excess_of_a_control_point() -> None:
    terrain = TerrainModel(load_terrain("flat"))
    nlp = Formulation(
        _config(WEIGHT, duration=2.0, steps=4), TOWR_ANYMAL, make_gait("walk", 4, 2.0), terrain
    )
    task = resolve(Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)), TOWR_ANYMAL, terrain)
    x, p = HeuristicInitializer().guess(nlp, task), task.vector()
    force = nlp.forces[0]
    parts = nlp.split(x)
    pos, vel = force.unpack(parts[force.name])
    for phase in nlp.stance_phases(0):
        pos[force.inner_nodes(phase)] = [0.0, 0.0, 200.0]
    vel[:] = 0.0
    parts[force.name] = force.pack(pos, vel)
    # Every foot's forces inside the cone with zero rates: the cost vanishes.
    for other in nlp.forces[1:]:
        q, v = other.unpack(parts[other.name])
        v[:] = 0.0
        parts[other.name] = other.pack(q, v)
    assert _penalty(nlp, nlp.join(parts), p) == pytest.approx(0.0, abs=1e-12)
    # A rate that makes the first inner node's next segment pull on the ground:
    # its first inner control point has f_z = 200 − d·8000/3 < 0, which breaks
    # 0 ≤ f·n by −f_z and each of the four pyramid rows by −μ f_z; the
    # previous segment's second one, 200 + d·8000/3, breaks f·n ≤ f_max.
    k = force.inner_nodes(nlp.stance_phases(0)[1])[0]
    vel[k, 2] = -8000.0
    parts[force.name] = force.pack(pos, vel)
    fz = 200.0 - float(force.spline.durations[k]) * 8000.0 / 3.0
    assert fz < -50.0
    mu, mg, f_max = TOWR_ANYMAL.friction, TOWR_ANYMAL.weight, TOWR_ANYMAL.force_limit
    above = max(0.0, 400.0 - fz - f_max)
    expected = WEIGHT * ((fz / mg) ** 2 * (1.0 + 4.0 * mu**2) + (above / mg) ** 2)
    assert _penalty(nlp, nlp.join(parts), p) == pytest.approx(expected, rel=1e-9)


def test_gradient_and_hessian_against_finite_differences() -> None:
    # On the pallet's edge the terrain basis depends on the footholds: the
    # formulation's hand-assembled chain rule through the terrain is in play.
    nlp, parts, task = pallet_edge_climb(_config(WEIGHT, duration=2.0, steps=4))
    p = task.vector()
    # Large force rates: many control points outside the pyramid, the hinge active.
    for force in nlp.forces:
        q, v = force.unpack(parts[force.name])
        v[:] = np.random.default_rng(7).normal(scale=2000.0, size=v.shape)
        parts[force.name] = force.pack(q, v)
    x = nlp.join(parts)
    x = x + np.random.default_rng(3).normal(scale=0.01, size=x.size)
    assert _penalty(nlp, x, p) > 1.0
    names = [nlp.x[i].name() for i in range(x.size)]
    columns = [i for i, n in enumerate(names) if n.startswith(("foot_force_0", "foot_motion_0"))]
    h = 1e-6

    def gradient(v: np.ndarray) -> np.ndarray:
        return np.asarray(nlp.grad_f(v, p)[1]).ravel()

    fd = np.array(
        [
            (float(nlp.evaluator(x + h * e, p)[0]) - float(nlp.evaluator(x - h * e, p)[0]))
            / (2 * h)
            for e in np.eye(x.size)[columns]
        ]
    )
    np.testing.assert_allclose(gradient(x)[columns], fd, rtol=1e-5, atol=1e-5)
    lam_g = np.zeros(nlp.n_constraints)
    hess = np.asarray(ca.densify(nlp.hess_lag(x, p, 1.0, lam_g)))
    hess = np.triu(hess) + np.triu(hess, 1).T
    hfd = np.array(
        [(gradient(x + 1e-5 * e) - gradient(x - 1e-5 * e)) / 2e-5 for e in np.eye(x.size)[columns]]
    ).T
    scale = np.maximum(1.0, np.abs(hfd))
    assert np.max(np.abs(hess[:, columns] - hfd) / scale) < 1e-4


def _pyramid_between_nodes(result) -> float:  # type: ignore[no-untyped-def]
    """Largest max(|f_x| − μ f_z, |f_y| − μ f_z, −f_z) [N] of a stance foot, every 5 ms."""
    plan = result.sample(200.0)
    f = plan["forces"]
    excess = np.maximum(
        np.abs(f[..., :2]).max(axis=-1) - result.body.friction * f[..., 2], -f[..., 2]
    )
    return float(np.where(plan["contact"], excess, -np.inf).max(initial=0.0))


def test_single_pallet_plan_stays_closer_to_the_pyramid() -> None:
    robot = load_robot("anymal_c")
    terrain = load_terrain("single_pallet")
    task = Task((0.0, 0.2, 0.2), (1.6, 0.0, 0.0))
    default = optimize_motion(robot, terrain, task, config=melon_config())
    soft = optimize_motion(robot, terrain, task, config=_config(WEIGHT))
    assert default.solved and soft.solved
    assert _pyramid_between_nodes(soft) < 0.5 * _pyramid_between_nodes(default)
