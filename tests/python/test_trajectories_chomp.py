"""CHOMP (Ratliff 2009; Zucker 2011, §5.1): every hand-written gradient against finite
differences, the objective going down at every iteration, and the covariant update's
independence of the number of samples."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _trajectory_plans import BARRIER, barrier_step_plan, low_swing_config

import roughwalk as rw
from roughwalk.trajectories.body_pass import BodyPass
from roughwalk.trajectories.chomp import Chomp, ChompStatus, Evaluation
from roughwalk.trajectories.costs import (
    ObstacleCost,
    Smoothness,
    ZmpSupportCost,
    obstacle_potential,
    reachability_cost,
)
from roughwalk.trajectories.costs.joint_speed import joint_speed_cost
from roughwalk.trajectories.euler import rpy_rate_matrix, rpy_to_matrix
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.support_polygon import convex_polygon
from roughwalk.trajectories.swing_pass import SwingPass


class BallField:
    """The signed distance field of a ball, in closed form."""

    def __init__(self, centre: np.ndarray, radius: float) -> None:
        self.centre = np.asarray(centre, dtype=float)
        self.radius = radius

    def query_spheres(
        self, centers: np.ndarray, radii: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        v = np.asarray(centers) - self.centre
        n = np.linalg.norm(v, axis=1)
        return n - self.radius - radii, v / n[:, None]


BALL = BallField(np.array([0.0, 0.0, 0.0]), 0.3)
START, END = np.array([-1.0, 0.05, 0.0]), np.array([1.0, 0.05, 0.0])


def _line(n: int) -> np.ndarray:
    s = np.arange(1, n + 1)[:, None] / (n + 1)
    return START + s * (END - START)


def _point_evaluate(obstacle: ObstacleCost):
    def evaluate(xi: np.ndarray) -> Evaluation:
        full = np.vstack([START, xi, END])[:, None, :]
        ev = obstacle.evaluate(full, np.ones(full.shape[:2], dtype=bool))
        return Evaluation(
            ev.value, ev.workspace_gradient[:, 0, :], {}, bool(np.all(ev.clearance > 0))
        )

    return evaluate


def _finite_difference(f, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    g = np.zeros_like(x)
    for idx in np.ndindex(x.shape):
        d = np.zeros_like(x)
        d[idx] = h
        g[idx] = (f(x + d) - f(x - d)) / (2 * h)
    return g


# ---- smoothness ---------------------------------------------------------------------


@pytest.mark.parametrize("order", [1, 2])
def test_smoothness_is_KtK_of_finite_differences(order: int) -> None:
    n = 9
    rng = np.random.default_rng(order)
    ref = rng.normal(size=(n, 2))
    sm = Smoothness(ref, order, 0.7, [1.0, 4.0])
    # K: differences of the change δ padded with zeros beyond the fixed ends.
    rows = n + order
    k = np.zeros((rows, n))
    stencil = [1.0, -1.0] if order == 1 else [1.0, -2.0, 1.0]
    for r in range(rows):
        for j, c in enumerate(stencil):
            col = r - j
            if 0 <= col < n:
                k[r, col] = c
    h = 1.0 / (n + 1)
    np.testing.assert_allclose(sm.matrix(), k.T @ k / h ** (2 * order - 1), atol=1e-9)
    xi = rng.normal(size=(n, 2))
    np.testing.assert_allclose(
        sm.gradient(xi), _finite_difference(sm.value, xi), rtol=1e-6, atol=1e-5
    )
    # ξᵀAξ + ξᵀb + c form, per coordinate, with the metric weights and λ/2.
    a, b = sm.matrix(), sm.linear_term()
    c = np.einsum("nd,nm,md->d", ref, a, ref)
    quad = np.einsum("nd,nm,md->d", xi, a, xi) + np.sum(xi * b, axis=0) + c
    assert sm.value(xi) == pytest.approx(0.5 * 0.7 * float(quad @ [1.0, 4.0]))
    # The banded solve is the dense one.
    g = rng.normal(size=(n, 2))
    np.testing.assert_allclose(sm.precondition(g), np.linalg.solve(a, g) / [1.0, 4.0], atol=1e-12)


def test_smoothness_with_held_samples_is_the_restricted_metric() -> None:
    n = 12
    fixed = np.zeros(n, dtype=bool)
    fixed[[3, 8]] = True
    full = Smoothness(np.zeros((n, 1)), 2, 1.0, [1.0])
    held = Smoothness(np.zeros((n, 1)), 2, 1.0, [1.0], fixed=fixed)
    free = np.flatnonzero(~fixed)
    np.testing.assert_allclose(held.matrix(), full.matrix()[np.ix_(free, free)], atol=1e-9)
    step = held.precondition(np.ones((n, 1)))
    assert np.all(step[fixed] == 0.0) and np.all(step[~fixed] != 0.0)


# ---- obstacle -------------------------------------------------------------------------


def test_obstacle_potential_and_its_derivative() -> None:
    eps = 0.05
    d = np.linspace(-0.1, 0.1, 401)
    c, dc = obstacle_potential(d, eps)
    assert np.all(c >= 0) and np.all(c[d > eps] == 0)
    np.testing.assert_allclose(c[d < 0], -d[d < 0] + eps / 2)
    h = 1e-7
    fd = (obstacle_potential(d + h, eps)[0] - obstacle_potential(d - h, eps)[0]) / (2 * h)
    np.testing.assert_allclose(dc, fd, atol=1e-5)


def _bent_path(n: int) -> np.ndarray:
    xi = _line(n)
    s = np.arange(1, n + 1) / (n + 1)
    xi[:, 1] += 0.25 * np.sin(np.pi * s) ** 2
    xi[:, 2] += 0.1 * np.sin(2 * np.pi * s)
    return xi


def test_exact_obstacle_gradient_matches_finite_differences() -> None:
    obstacle = ObstacleCost(BALL, [0.05], epsilon=0.2, weight=3.0, gradient="exact")
    evaluate = _point_evaluate(obstacle)
    xi = _bent_path(15)
    np.testing.assert_allclose(
        evaluate(xi).gradient, _finite_difference(lambda x: evaluate(x).value, xi), atol=1e-7
    )


def test_functional_gradient_is_orthogonal_to_the_path_and_the_limit_of_the_exact_one() -> None:
    """Ratliff 2009: the arc-length weighting projects the potential's gradient off the path."""
    errors = []
    for n in (20, 40, 80, 160):
        xi = _bent_path(n)
        full = np.vstack([START, xi, END])[:, None, :]
        active = np.ones(full.shape[:2], dtype=bool)
        functional = ObstacleCost(BALL, [0.05], 0.2, gradient="functional").evaluate(full, active)
        exact = ObstacleCost(BALL, [0.05], 0.2, gradient="exact").evaluate(full, active)
        tangent = (full[2:] - full[:-2])[:, 0]
        g = functional.workspace_gradient[:, 0]
        cos = np.abs(np.sum(g * tangent, axis=1)) / (
            np.linalg.norm(g, axis=1) * np.linalg.norm(tangent, axis=1) + 1e-300
        )
        assert cos.max() < 1e-6  # orthogonal to the path at every sample
        # Per unit of arc length the two gradients converge.
        scale = np.linalg.norm(tangent, axis=1)[:, None] / 2
        diff = (g - exact.workspace_gradient[:, 0]) / scale
        errors.append(float(np.sqrt(np.mean(diff**2))))
    # First order in the sample spacing: each doubling at least a third off.
    assert all(b < 0.67 * a for a, b in zip(errors, errors[1:], strict=False))


# ---- other terms --------------------------------------------------------------------------


def test_reachability_gradient_is_the_virtual_force_and_matches_finite_differences() -> None:
    """Zucker 2011 §3.2: Δx ∝ Σe, ω ∝ Σ(f′ − x) × e is the descent direction of ½Σ‖e‖²."""
    robot = rw.load_robot("littledog")
    from roughwalk.trajectories.whole_body import WholeBody

    wb = WholeBody(robot)
    stance = robot.nominal_stance
    feet = stance.feet + [0.0, 0.0, stance.base_height]
    feet[0] += [0.06, 0.0, -0.03]  # LF out of reach
    feet[3] += [-0.05, -0.02, -0.02]  # RH too
    active = np.array([[True, True, True, True]])

    def cost(pose: np.ndarray) -> tuple[float, np.ndarray]:
        x, rpy = pose[:3], pose[3:]
        rot = rpy_to_matrix(rpy)
        q, _ = wb.inverse_kinematics(((feet - x) @ rot)[None])
        e = feet - (x + wb.foot_positions(q)[0] @ rot.T)
        return reachability_cost(
            e[None], feet[None], x[None], rpy_rate_matrix(rpy)[None], active, 5.0
        )

    pose = np.array([0.0, 0.0, 0.0, 0.02, -0.05, 0.03])
    value, grad = cost(pose)
    assert value > 1e-5
    fd = _finite_difference(lambda p: cost(p)[0], pose, h=1e-7)
    np.testing.assert_allclose(grad[0], fd, rtol=1e-4, atol=1e-8)


def test_support_term_gradient_matches_finite_differences() -> None:
    rng = np.random.default_rng(5)
    t = 30
    feet = np.array([[0.1, 0.06, 0.0], [0.1, -0.06, 0.0], [-0.1, 0.06, 0.0], [-0.1, -0.06, 0.0]])
    polys = [convex_polygon(feet), convex_polygon(feet[[1, 2, 3]])]
    index = np.where(np.arange(t) < 12, 0, 1)
    cost = ZmpSupportCost(
        polys,
        index,
        rng.normal(0, 0.002, (t, 2)),
        rng.normal(0, 0.01, (t, 2)),
        0.17,
        0.02,
        0.02,
        7.0,
    )
    path = np.cumsum(rng.normal(0, 0.004, (t, 2)), axis=0)
    value, grad, _ = cost.evaluate(path)
    assert value > 0

    def f(inner: np.ndarray) -> float:
        full = path.copy()
        full[1:-1] = inner
        return cost.evaluate(full)[0]

    np.testing.assert_allclose(grad, _finite_difference(f, path[1:-1], 1e-7), rtol=1e-4, atol=1e-9)


def test_joint_speed_term_gradient_matches_finite_differences() -> None:
    rng = np.random.default_rng(6)
    q = np.cumsum(rng.normal(0, 0.2, (20, 3)), axis=0)
    limit = np.array([5.0, 7.5, 14.0])

    def f(inner: np.ndarray) -> float:
        full = q.copy()
        full[1:-1] = inner
        return joint_speed_cost(full, 0.02, limit, 0.8, 3.0)[0]

    value, grad = joint_speed_cost(q, 0.02, limit, 0.8, 3.0)
    assert value > 0
    np.testing.assert_allclose(grad, _finite_difference(f, q[1:-1], 1e-7), rtol=1e-5, atol=1e-7)


# ---- the robot's passes: assembled gradients ------------------------------------------------


@pytest.fixture(scope="module")
def barrier_state():
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain(BARRIER)
    cfg = rw.trajectories.trajectory_config(**low_swing_config(**{"chomp.gradient": "exact"}))
    gen = FootstepTrajectoryGenerator(robot, terrain, config=cfg)
    prepared = gen.prepare(barrier_step_plan(robot, terrain, gen.wb))
    return gen, prepared


def _directional_check(evaluate, xi: np.ndarray, seed: int, h: float = 1e-6) -> None:
    rng = np.random.default_rng(seed)
    grad = evaluate(xi).gradient
    for _ in range(4):
        v = rng.normal(size=xi.shape)
        v /= np.linalg.norm(v)
        fd = (evaluate(xi + h * v).value - evaluate(xi - h * v).value) / (2 * h)
        assert float(np.sum(grad * v)) == pytest.approx(fd, rel=2e-3, abs=1e-7)


def test_body_pass_gradient_matches_finite_differences(barrier_state) -> None:
    gen, prepared = barrier_state
    state = gen.initial_state(prepared, 0, prepared.start)
    base = gen.config.chomp
    for weights in (
        {"reachability_weight": 0.0, "support_weight": 0.0},  # obstacle alone
        {"obstacle_weight": 0.0, "reachability_weight": 0.0, "zmp_margin": 0.05},  # support alone
    ):
        cfg = dataclasses.replace(base, **weights)
        obstacle = ObstacleCost(
            gen.sdf, gen.wb.points.radius, cfg.obstacle_epsilon, cfg.obstacle_weight, "exact"
        )
        # A vanishing damping of J_fB⁻¹ makes the gradient exact (1 mm/rad is off by ~1 %).
        body = BodyPass(gen.wb, state, obstacle, cfg, gen.config.validity, damping=1e-7)
        ev = body.evaluate(state.body[1:-1])
        assert ev.value > 0
        _directional_check(body.evaluate, state.body[1:-1], 7)


def test_swing_pass_gradient_matches_finite_differences(barrier_state) -> None:
    gen, prepared = barrier_state
    state = gen.initial_state(prepared, 0, prepared.start)
    swing = SwingPass(gen.wb, state, gen.sdf, gen.config.chomp, gen.config.validity, True)
    assert swing.evaluate(swing.initial).parts["obstacle"] > 0
    _directional_check(swing.evaluate, swing.initial, 8)


# ---- CHOMP itself --------------------------------------------------------------------------------


def _point_chomp(n: int, line_search: bool, step: float = 20.0) -> tuple[Chomp, np.ndarray]:
    obstacle = ObstacleCost(BALL, [0.05], epsilon=0.2, weight=5.0)
    sm = Smoothness(_line(n), 2, 0.02, [1.0, 1.0, 1.0])
    return Chomp(sm, _point_evaluate(obstacle), step_size=step, line_search=line_search), _line(n)


def test_objective_decreases_at_every_iteration_on_a_point_path() -> None:
    chomp, xi0 = _point_chomp(30, line_search=False)
    res = chomp.optimize(xi0, 20, stop_when_feasible=False)
    u = np.array(res.objective)
    assert res.iterations == 20
    assert np.all(np.diff(u) < 0)
    assert u[-1] < 0.5 * u[0]
    full = np.vstack([START, res.xi, END])
    assert np.all(np.linalg.norm(full - BALL.centre, axis=1) > BALL.radius + 0.05)


def test_objective_decreases_at_every_iteration_on_a_footstep(barrier_state) -> None:
    """The robot's trunk and swing passes over the barrier, plain CHOMP steps (no line search)."""
    gen, prepared = barrier_state
    state = gen.initial_state(prepared, 0, prepared.start)
    cfg = gen.config.chomp
    obstacle = ObstacleCost(
        gen.sdf, gen.wb.points.radius, cfg.obstacle_epsilon, cfg.obstacle_weight
    )
    body = BodyPass(gen.wb, state, obstacle, cfg, gen.config.validity)
    swing = SwingPass(gen.wb, state, gen.sdf, cfg, gen.config.validity, True)
    for block, xi0, project in (
        (body, state.body[1:-1], None),
        (swing, swing.initial, swing.project),
    ):
        chomp = Chomp(
            block.smoothness,
            block.evaluate,
            step_size=0.1,
            max_step=cfg.max_step,
            line_search=False,
            project=project,
        )
        u = np.array(chomp.optimize(xi0, 15, stop_when_feasible=False).objective)
        assert np.all(np.diff(u) < 0), u
        # The body pass drops 22 % with a 0.4 s swing, 18 % with the 0.34 s
        # that timing.swing_trunk "moving" gives this step, and one pass
        # only 14 % with the 0.30 s that timing.measured_speed 0.95 makes of
        # it (over 15 % with 0.9's 0.32 s).
        assert u[-1] < 0.9 * u[0]


def test_covariant_update_is_invariant_to_the_number_of_samples() -> None:
    """Ratliff 2009 / Zucker 2011 §5.1: doubling the samples hardly changes the result."""
    results = {}
    for n in (24, 49):  # sample times k/25 and k/50: the coarse ones are among the fine
        chomp, xi0 = _point_chomp(n, line_search=False)
        results[n] = chomp.optimize(xi0, 25, stop_when_feasible=False).xi
    coarse, fine = results[24], results[49][1::2]
    deflection = np.abs(coarse[:, 1] - 0.05).max()
    assert deflection > 0.2  # the path really went round the ball
    assert np.abs(coarse - fine).max() < 0.03 * deflection

    # Plain gradient descent, each grid with its own largest stable step, depends on it.
    euclid = {}
    for n in (24, 49):
        obstacle = ObstacleCost(BALL, [0.05], epsilon=0.2, weight=5.0)
        evaluate = _point_evaluate(obstacle)
        sm = Smoothness(_line(n), 2, 0.02, [1.0, 1.0, 1.0])
        alpha = 1.0 / (0.02 * np.linalg.eigvalsh(sm.matrix()).max())
        xi = _line(n)
        for _ in range(25):
            xi = xi - alpha * (evaluate(xi).gradient + sm.gradient(xi))
        euclid[n] = xi
    moved = np.abs(euclid[24][:, 1] - 0.05).max()
    plain = np.abs(euclid[24] - euclid[49][1::2]).max() / moved
    assert plain > 0.5 > 10 * np.abs(coarse - fine).max() / deflection


def test_chomp_stops_when_feasible_and_reports_it() -> None:
    obstacle = ObstacleCost(BALL, [0.05], epsilon=0.2, weight=5.0)
    evaluate = _point_evaluate(obstacle)
    sm = Smoothness(_line(20), 2, 0.02, [1.0, 1.0, 1.0])
    res = Chomp(sm, evaluate, step_size=20.0).optimize(_line(20), 200)
    assert res.status == ChompStatus.VALID and 0 < res.iterations < 200
    assert res.last.feasible
