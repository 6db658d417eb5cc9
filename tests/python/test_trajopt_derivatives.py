"""Closed-form costs against quadrature; hand-assembled derivatives against finite differences."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from _trajopt_problems import central_differences, pallet_edge_climb
from scipy.integrate import quad

from roughwalk.robots import load_robot
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    SingleRigidBody,
    TerrainModel,
    make_gait,
    melon_config,
    rigid_body_from_robot,
)
from roughwalk.trajopt.costs.integral import melon_integral
from roughwalk.trajopt.costs.normal_force import stance_share
from roughwalk.trajopt.optimize import _splines
from roughwalk.trajopt.parameters import MELON_CONSTRAINTS, MELON_REACH_CONSTRAINTS
from roughwalk.trajopt.task import Task, resolve
from roughwalk.trajopt.variables import (
    NumericSpline,
    angular_acceleration,
    angular_velocity,
    polynomial_value,
)

# Gauss–Legendre with 8 nodes integrates polynomials up to degree 15 exactly.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(8)


def _quadrature(spline: NumericSpline, integrand) -> float:  # type: ignore[no-untyped-def]
    """Σ over the spline's polynomials of ∫ integrand(pos, vel, acc) dt, by Gauss–Legendre."""
    total = 0.0
    for start, d in zip(spline.node_times[:-1], spline.durations, strict=True):
        t = start + 0.5 * d * (_NODES + 1.0)
        # Stay inside the polynomial: the spline gives a junction to the earlier one.
        total += 0.5 * d * float(np.dot(_WEIGHTS, integrand(*spline.evaluate(t))))
    return total


@pytest.fixture(scope="module")
def problem() -> tuple[Formulation, np.ndarray, np.ndarray]:
    """A short climb onto the pallet, every cost on, at a perturbed guess."""
    nlp, parts, task = pallet_edge_climb(melon_config(duration=2.0, steps=4))
    x = nlp.join(parts)
    x = x + np.random.default_rng(3).normal(scale=0.01, size=x.size)
    return nlp, x, task.vector()


def test_melon_integral_closed_form_against_quadrature() -> None:
    rng = np.random.default_rng(0)
    for _ in range(5):
        coeffs = rng.normal(size=4)
        d, ref, w = rng.uniform(0.05, 0.8), rng.normal(), rng.uniform(0.0, 0.5)

        def integrand(s: float, c: np.ndarray = coeffs, r: float = ref, wd: float = w) -> float:
            x = polynomial_value(tuple(c), s)
            xd = polynomial_value(tuple(k * c[k] for k in range(1, 4)), s)
            return (x - r) ** 2 + wd * xd**2

        assert melon_integral(list(coeffs), d, ref, w) == pytest.approx(quad(integrand, 0, d)[0])


def test_integral_costs_equal_quadrature_of_the_splines(problem) -> None:  # type: ignore[no-untyped-def]
    nlp, x, p = problem
    _, _, costs = nlp.evaluator(x, p)
    value = dict(zip([c.name for c in nlp.costs], np.asarray(costs).ravel(), strict=True))
    parts = nlp.split(x)
    durations = [d.unpack(parts[d.name]) for d in nlp.durations]
    s = _splines(nlp, parts, durations)
    w = nlp.config.costs
    mg = nlp.body.weight

    vertical = _quadrature(
        s.base_linear,
        lambda pos, vel, acc: (
            vel[:, 2] ** 2 + w.base_vertical_velocity.derivative_weight * acc[:, 2] ** 2
        ),
    )
    assert value["base_vertical_velocity"] == pytest.approx(
        w.base_vertical_velocity.weight * vertical
    )

    angular = _quadrature(
        s.base_angular,
        lambda pos, vel, acc: (
            (vel**2).sum(1) + w.base_angular_velocity.derivative_weight * (acc**2).sum(1)
        ),
    )
    assert value["base_angular_velocity"] == pytest.approx(w.base_angular_velocity.weight * angular)

    force = sum(
        _quadrature(
            f,
            lambda pos, vel, acc: (
                ((pos / mg) ** 2).sum(1) + w.force.derivative_weight * ((vel / mg) ** 2).sum(1)
            ),
        )
        for f in s.forces
    )
    assert value["force"] == pytest.approx(w.force.weight * force)

    # The desired normal force: over each stance phase, its share of the weight.
    normal = 0.0
    for foot, f in enumerate(s.forces):
        bounds = np.concatenate([[0.0], np.cumsum(durations[foot])])
        for phase in nlp.stance_phases(foot):
            middle = 0.5 * (bounds[phase] + bounds[phase + 1])
            n = nlp.terrain.normal(s.feet[foot].evaluate([middle])[0][:, :2])[0]
            share = stance_share(nlp.schedule, foot, phase)

            def integrand(
                t: float, f: NumericSpline = f, n: np.ndarray = n, share: float = share
            ) -> float:
                pos, vel, _ = f.evaluate([t])
                return float(
                    (pos[0] @ n / mg - share) ** 2
                    + w.normal_force.derivative_weight * (vel[0] @ n / mg) ** 2
                )

            knots = f.node_times[
                (f.node_times > bounds[phase]) & (f.node_times < bounds[phase + 1])
            ]
            normal += quad(integrand, bounds[phase], bounds[phase + 1], points=knots, limit=200)[0]
    assert value["normal_force"] == pytest.approx(w.normal_force.weight * normal, rel=1e-6)


def test_swing_height_and_step_edge_costs(problem) -> None:  # type: ignore[no-untyped-def]
    nlp, x, p = problem
    _, _, costs = nlp.evaluator(x, p)
    value = dict(zip([c.name for c in nlp.costs], np.asarray(costs).ravel(), strict=True))
    parts = nlp.split(x)
    edge, swing = 0.0, 0.0
    for foot, motion in enumerate(nlp.feet):
        pos, _ = motion.unpack(parts[motion.name])
        for phase in nlp.stance_phases(foot):
            if not nlp.fixed_foothold(foot, phase):
                edge += nlp.terrain.edge_cost(pos[motion.phase_nodes(phase)[0]][None, :2])[0]
        for phase in nlp.swing_phases(foot):
            before, apex, after = (pos[n] for n in motion.phase_nodes(phase))
            swing += (apex[2] - 0.5 * (before[2] + after[2])) ** 2
    assert edge > 0.5  # a foothold stands on the pallet's edge: the cost is felt
    assert value["step_edge"] == pytest.approx(nlp.config.costs.step_edge * edge)
    assert value["swing_height"] == pytest.approx(nlp.config.costs.swing_height * swing)


def test_block_jacobian_and_gradient_against_finite_differences(problem) -> None:  # type: ignore[no-untyped-def]
    # The Jacobian is assembled by hand from row blocks and the terrain's chain rule.
    nlp, x, p = problem
    columns = np.random.default_rng(4).choice(x.size, 40, replace=False)
    # Include every foothold variable, whose derivatives go through the terrain spline.
    footholds = [i for i in range(x.size) if nlp.x[i].name().startswith("foot_motion")][:30]
    columns = np.unique(np.concatenate([columns, footholds]))

    def g(v: np.ndarray) -> np.ndarray:
        return np.asarray(nlp.evaluator(v, p)[1]).ravel()

    def f(v: np.ndarray) -> np.ndarray:
        return np.atleast_1d(float(nlp.evaluator(v, p)[0]))

    _, jac = nlp.jac_g(x, p)
    jac = np.asarray(ca.densify(jac))
    fd = central_differences(g, x, columns)
    scale = np.maximum(1.0, np.abs(fd))
    assert np.max(np.abs(jac[:, columns] - fd) / scale) < 1e-5
    _, grad = nlp.grad_f(x, p)
    np.testing.assert_allclose(
        np.asarray(grad).ravel()[columns],
        central_differences(f, x, columns)[0],
        rtol=1e-5,
        atol=1e-6,
    )


def test_block_hessian_against_finite_differences_of_the_gradient(problem) -> None:  # type: ignore[no-untyped-def]
    nlp, x, p = problem
    rng = np.random.default_rng(5)
    lam_g = rng.normal(size=nlp.n_constraints)
    lam_f = 0.7

    def lagrangian_gradient(v: np.ndarray) -> np.ndarray:
        _, jac = nlp.jac_g(v, p)
        _, grad = nlp.grad_f(v, p)
        return lam_f * np.asarray(grad).ravel() + np.asarray(ca.densify(jac)).T @ lam_g

    hess = np.asarray(ca.densify(nlp.hess_lag(x, p, lam_f, lam_g)))
    hess = np.triu(hess) + np.triu(hess, 1).T
    columns = rng.choice(x.size, 25, replace=False)
    fd = central_differences(lagrangian_gradient, x, columns, h=1e-5)
    scale = np.maximum(1.0, np.abs(fd))
    assert np.max(np.abs(hess[:, columns] - fd) / scale) < 1e-4


def test_euler_angular_acceleration_is_the_derivative_of_angular_velocity() -> None:
    rng = np.random.default_rng(6)
    eta, rates, acc = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    h = 1e-6
    plus = angular_velocity(eta + h * rates, rates + h * acc)
    minus = angular_velocity(eta - h * rates, rates - h * acc)
    np.testing.assert_allclose(
        angular_acceleration(eta, rates, acc), (plus - minus) / (2 * h), atol=1e-7
    )


def test_terrain_gradient_and_edges() -> None:
    terrain = TerrainModel(load_terrain("towr_slope"))
    xy = np.array([[1.3, 0.2], [2.4, -0.1], [0.5, 0.0], [1.9, 0.3]])
    values = terrain.evaluate(xy)
    h = 1e-5
    for axis in (0, 1):
        e = np.zeros(2)
        e[axis] = h
        fd = (terrain.height(xy + e) - terrain.height(xy - e)) / (2 * h)
        np.testing.assert_allclose(values[:, 1 + axis], fd, atol=1e-6)
    # The slope's own gradient is 0.7 up, −0.7 down, 0 on the flat.
    np.testing.assert_allclose(values[:3, 1], [0.7, -0.7, 0.0], atol=1e-6)
    pallet = TerrainModel(load_terrain("single_pallet"))
    cost = pallet.edge_cost([[1.0, 0.0], [1.05, 0.0], [1.6, 0.0], [0.0, 0.0]])
    assert cost[0] > 0.9 and cost[1] < cost[0] and cost[2] < 1e-3 and cost[3] < 1e-3


def _pallet_walk(
    optimize_durations: bool, reach: bool
) -> tuple[Formulation, SingleRigidBody, TerrainModel]:
    """A 4-step Melon walk onto the single pallet, with or without the leg-reach rows."""
    constraints = MELON_REACH_CONSTRAINTS if reach else MELON_CONSTRAINTS
    config = melon_config(
        duration=2.0, steps=4, optimize_durations=optimize_durations, constraints=constraints
    )
    body = rigid_body_from_robot(load_robot("anymal_c")) if reach else TOWR_ANYMAL
    terrain = TerrainModel(
        load_terrain("single_pallet"), config.terrain, config.costs.step_edge_sigma
    )
    return Formulation(config, body, make_gait("walk", 4, 2.0), terrain), body, terrain


@pytest.mark.parametrize(
    ("optimize_durations", "reach"), [(False, False), (True, False), (False, True), (True, True)]
)
def test_hessian_equals_casadis_of_the_whole_lagrangian(
    optimize_durations: bool, reach: bool
) -> None:
    # The dynamics, range-of-motion and leg-reach rows are mapped from their
    # functions' own small Hessians (Aᵀ ∇²ᵤ A), all calls of a function at once;
    # with optimised durations their inputs are not affine and the points'
    # curvature is added. Both must equal CasADi's Hessian of the Lagrangian
    # as one MX expression, terrain splines included.
    nlp, body, terrain = _pallet_walk(optimize_durations, reach)
    called = {rows.name for rows in nlp.rows if rows.calls}
    assert {"dynamics", "range_of_motion"} <= called
    assert ("leg_reach" in called) == reach
    task = resolve(Task((0.55, 0.0, 0.0), (0.95, 0.05, 0.1)), body, terrain)
    rng = np.random.default_rng(7)
    x = HeuristicInitializer().guess(nlp, task) + 0.01 * rng.normal(size=nlp.n_variables)
    p = task.vector()
    lam_g = rng.normal(size=nlp.n_constraints)
    x_mx, p_mx = nlp.nlp["x"], nlp.nlp["p"]
    lam_f_mx, lam_g_mx = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", nlp.n_constraints)
    lagrangian = lam_f_mx * nlp.nlp["f"] + ca.dot(lam_g_mx, nlp.nlp["g"])
    reference = ca.Function(
        "reference", [x_mx, p_mx, lam_f_mx, lam_g_mx], [ca.triu(ca.hessian(lagrangian, x_mx)[0])]
    )
    expected = np.asarray(ca.densify(reference(x, p, 0.7, lam_g)))
    hess = np.asarray(ca.densify(nlp.hess_lag(x, p, 0.7, lam_g)))
    assert np.max(np.abs(expected)) > 100.0
    np.testing.assert_allclose(hess, expected, rtol=0, atol=1e-9 * np.max(np.abs(expected)))


@pytest.mark.parametrize(
    ("optimize_durations", "reach"), [(False, False), (True, False), (False, True), (True, True)]
)
def test_jacobian_equals_casadis_of_the_whole_constraints(
    optimize_durations: bool, reach: bool
) -> None:
    # The rows made of calls are differentiated as blockdiag(∂F/∂u)·∂u/∂z
    # (∂u/∂z = A with fixed durations, each distinct point's own Jacobian with
    # optimised ones) and projected onto the rows' sparsity; IPOPT must see
    # the structure and values of CasADi's Jacobian of g as one MX expression.
    nlp, body, terrain = _pallet_walk(optimize_durations, reach)
    task = resolve(Task((0.55, 0.0, 0.0), (0.95, 0.05, 0.1)), body, terrain)
    rng = np.random.default_rng(5)
    x = HeuristicInitializer().guess(nlp, task) + 0.01 * rng.normal(size=nlp.n_variables)
    p = task.vector()
    x_mx, p_mx = nlp.nlp["x"], nlp.nlp["p"]
    reference = ca.Function("reference", [x_mx, p_mx], [ca.jacobian(nlp.nlp["g"], x_mx)])
    expected = reference(x, p)
    _, jac = nlp.jac_g(x, p)
    assert jac.sparsity() == expected.sparsity()
    dense, dense_expected = np.asarray(ca.densify(jac)), np.asarray(ca.densify(expected))
    assert np.max(np.abs(dense_expected)) > 100.0
    np.testing.assert_allclose(
        dense, dense_expected, rtol=0, atol=1e-12 * np.max(np.abs(dense_expected))
    )
