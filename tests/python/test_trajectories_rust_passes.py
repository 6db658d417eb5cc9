"""The Rust evaluation of CHOMP's passes equals the numpy reference it replaced.

Both backends evaluate the trunk pass (IK of the supporting legs, body
points, SDF, obstacle, reachability and ZMP support terms with their
gradient) and the swing pass (obstacle and joint speed) of real footsteps:
the Figure-8 barrier step, where the obstacle term is active, and a step of
a crawl whose trunk is pushed so far that feet are lost, where the
reachability term is. The Rust obstacle gradient is also checked against
finite differences of its own value.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _trajectory_plans import BARRIER, barrier_step_plan, low_swing_config

import roughwalk as rw
from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.body_pass import DAMPING, BodyPass, resolve_backend
from roughwalk.trajectories.chomp import Evaluation
from roughwalk.trajectories.costs.obstacle import ObstacleCost
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.step_report import capsule_clearances, capsule_clearances_numpy
from roughwalk.trajectories.swing_pass import SwingPass


@pytest.fixture(scope="module")
def barrier():
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain(BARRIER)
    cfg = rw.trajectories.trajectory_config(**low_swing_config())
    gen = FootstepTrajectoryGenerator(robot, terrain, config=cfg)
    prepared = gen.prepare(barrier_step_plan(robot, terrain, gen.wb))
    return gen, gen.initial_state(prepared, 0, prepared.start)


@pytest.fixture(scope="module")
def crawl():
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    gen = FootstepTrajectoryGenerator(robot, terrain)
    plan = straight_crawl_plan(robot, terrain, (0.3, 0.0), steps=2)
    prepared = gen.prepare(plan)
    return gen, gen.initial_state(prepared, 0, prepared.start)


def _body_passes(
    gen, state, mode: str = "functional", damping: float = DAMPING, **weights
) -> tuple[BodyPass, BodyPass]:
    cfg = dataclasses.replace(gen.config.chomp, gradient=mode, **weights)
    obstacle = ObstacleCost(
        gen.sdf, gen.wb.points.radius, cfg.obstacle_epsilon, cfg.obstacle_weight, mode
    )
    return tuple(  # type: ignore[return-value]
        BodyPass(gen.wb, state, obstacle, cfg, gen.config.validity, backend=b, damping=damping)
        for b in ("rust", "python")
    )


def _same(a: Evaluation, b: Evaluation) -> None:
    assert a.parts.keys() == b.parts.keys()
    for k in a.parts:
        assert a.parts[k] == pytest.approx(b.parts[k], rel=1e-9, abs=1e-12), k
    scale = max(float(np.abs(b.gradient).max()), 1e-9)
    np.testing.assert_allclose(a.gradient, b.gradient, rtol=1e-7, atol=1e-9 * scale)
    assert a.feasible == b.feasible
    assert a.violation == pytest.approx(b.violation, abs=1e-12)


def _perturbed(xi: np.ndarray, seed: int, size: float) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [xi, xi + size * rng.normal(size=xi.shape)]


@pytest.mark.parametrize("mode", ["functional", "exact"])
def test_body_pass_backends_agree_on_the_barrier_step(barrier, mode: str) -> None:
    gen, state = barrier
    rust, python = _body_passes(gen, state, mode)
    assert (rust.backend, python.backend) == ("rust", "python")
    for xi in _perturbed(state.body[1:-1], 1, 0.004):
        ev = rust.evaluate(xi)
        assert ev.parts["obstacle"] > 0  # the knee and shin meet the barrier
        _same(ev, python.evaluate(xi))


def test_body_pass_backends_agree_when_feet_are_out_of_reach(crawl) -> None:
    gen, state = crawl
    rust, python = _body_passes(gen, state)
    xi = state.body[1:-1].copy()
    xi[:, 2] += 0.04  # lift the trunk: the supporting feet leave the workspace
    xi[:, 4] += 0.1
    ev = rust.evaluate(xi)
    assert ev.parts["reachability"] > 0 and ev.violation > 0
    _same(ev, python.evaluate(xi))
    _same(rust.evaluate(state.body[1:-1]), python.evaluate(state.body[1:-1]))


def test_swing_pass_backends_agree(barrier) -> None:
    gen, state = barrier
    passes = [
        SwingPass(gen.wb, state, gen.sdf, gen.config.chomp, gen.config.validity, True, backend=b)
        for b in ("rust", "python")
    ]
    for xi in _perturbed(passes[0].initial, 2, 0.05):
        ev = passes[0].evaluate(xi)
        assert ev.parts["obstacle"] > 0
        _same(ev, passes[1].evaluate(xi))
    fast = passes[0].initial.copy()
    fast[len(fast) // 2] += 0.5  # a dash: the joint-speed term and the excess
    ev = passes[0].evaluate(fast)
    assert ev.parts["joint_speed"] > 0 and ev.violation > 0
    _same(ev, passes[1].evaluate(fast))


def _directional_errors(evaluate, xi: np.ndarray, seed: int, h: float = 1e-6):
    grad = evaluate(xi).gradient
    rng = np.random.default_rng(seed)
    for _ in range(6):
        v = rng.normal(size=xi.shape)
        v /= np.linalg.norm(v)
        fd = (evaluate(xi + h * v).value - evaluate(xi - h * v).value) / (2 * h)
        yield float(np.sum(grad * v)), fd


def test_rust_obstacle_gradient_matches_finite_differences(barrier) -> None:
    gen, state = barrier
    cfg = dataclasses.replace(gen.config.chomp, gradient="exact")
    # The swing leg's points move exactly with R·J_pB: a tight match.
    swing = SwingPass(gen.wb, state, gen.sdf, cfg, gen.config.validity, True, backend="rust")
    for analytic, fd in _directional_errors(swing.evaluate, swing.initial, 4):
        assert analytic == pytest.approx(fd, rel=1e-5, abs=1e-9)
    # The trunk's moves carry the supporting legs through a damped J_fB⁻¹;
    # as the damping vanishes the gradient is that of the IK's exact inverse.
    rust, _ = _body_passes(
        gen, state, "exact", damping=1e-7, reachability_weight=0.0, support_weight=0.0
    )
    for analytic, fd in _directional_errors(rust.evaluate, state.body[1:-1], 3):
        assert analytic == pytest.approx(fd, rel=2e-4, abs=1e-7)


def test_backend_choice() -> None:
    class FakeField:
        pass

    assert resolve_backend("auto", FakeField()) == "python"
    with pytest.raises(InvalidArgumentError, match="compiled"):
        resolve_backend("rust", FakeField())
    with pytest.raises(InvalidArgumentError, match="known: auto, rust, python"):
        resolve_backend("numba", FakeField())


def test_batched_com_and_feet_equal_the_numpy_link_frames(barrier) -> None:
    gen, state = barrier
    wb = gen.wb
    rng = np.random.default_rng(5)
    q = state.q + 0.2 * rng.normal(size=state.q.shape)
    frames = wb.link_frames(q)
    np.testing.assert_allclose(
        wb.center_of_mass(q), wb.center_of_mass(q, frames), rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        wb.foot_positions(q), wb.foot_positions(q, frames), rtol=0, atol=1e-12
    )


def test_capsule_clearances_equal_the_numpy_reference(barrier) -> None:
    gen, state = barrier
    rng = np.random.default_rng(6)
    q = state.q + 0.1 * rng.normal(size=state.q.shape)
    args = (gen.wb, gen.sdf, q, state.body[:, :3], state.rotation)
    rust = capsule_clearances(*args)
    numpy = capsule_clearances_numpy(*args)
    assert rust.shape == numpy.shape == (state.n_samples, len(gen.wb.collision))
    assert numpy.min() < 0.01  # the barrier is near
    np.testing.assert_allclose(rust, numpy, rtol=0, atol=1e-12)


def test_reach_by_height_and_tilt_equals_the_numpy_reference(crawl) -> None:
    """The Rust trunk adjustment for reach equals the numpy loop it replaced.

    From the crawl's touchdown stance, the trunk is raised, shifted and tilted
    at random, so that feet are lost and found again over the 30 rounds (or
    stay lost, where the loop runs to its end); both must agree on whether
    anything changed and on the pose to 1e-9.
    """
    from roughwalk.trajectories.initial_trajectory import (
        _reach_by_height_and_tilt,
        reach_by_height_and_tilt_reference,
    )

    gen, state = crawl
    feet = state.step.stance_after
    base = state.body[state.touchdown]
    rng = np.random.default_rng(7)
    outcomes = {"unchanged": 0, "reached": 0, "still out of reach": 0}
    for _ in range(40):
        pose = base + np.concatenate(
            [rng.uniform(-0.03, 0.03, 2), rng.uniform(-0.02, 0.07, 1), rng.uniform(-0.3, 0.3, 3)]
        )
        for iterations in (1, 30):
            rust = _reach_by_height_and_tilt(gen.wb, feet, pose, iterations)
            numpy = reach_by_height_and_tilt_reference(gen.wb, feet, pose, iterations)
            assert (rust is None) == (numpy is None)
            if rust is None or numpy is None:
                outcomes["unchanged"] += 1
                continue
            np.testing.assert_allclose(rust, numpy, rtol=0, atol=1e-9)
            rot = rw.trajectories.euler.rpy_to_matrix(rust[3:])
            _, reached = gen.wb.inverse_kinematics(((feet - rust[:3]) @ rot)[None])
            outcomes["reached" if reached.all() else "still out of reach"] += 1
    # The random poses cover all three outcomes.
    assert min(outcomes.values()) > 0, outcomes
