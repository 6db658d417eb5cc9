"""Reach-aware references, knee limits and terrain-clearing swings of the tracking controller."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roughwalk import load_robot, load_terrain
from roughwalk.tracking import Reference, WholeBodyQP
from roughwalk.tracking.reach import LegReach, reach_aware_reference
from roughwalk.tracking.swing import SwingPlanner, SwingTrajectory, minimum_jerk


@pytest.fixture(scope="module")
def anymal_c():
    return load_robot("anymal_c")


def test_leg_reach_is_the_law_of_cosines_of_the_knee_bend(anymal_c):
    """distance() of forward-kinematics feet equals √(a² + b² + 2ab cos φ) for the knee bend φ."""
    reach = LegReach(anymal_c, 0.0)
    lower, upper = reach.joint_range(0.0, math.pi)
    a, b = anymal_c.leg_lengths[0]
    rng = np.random.default_rng(3)
    names = anymal_c.joint_names
    knees = [names.index(leg[2]) for leg in anymal_c.leg_joint_names]
    for _ in range(50):
        q = anymal_c.nominal_q + rng.uniform(-0.4, 0.4, 12)
        feet = anymal_c.foot_positions(q)
        for leg, k in enumerate(knees):
            # The straight knee is the kept range's end nearer the nominal angle.
            ends = (lower[k], upper[k])
            straight = min(ends, key=lambda e: abs(e - anymal_c.nominal_q[k]))
            bend = abs(q[k] - straight)
            expected = math.sqrt(a * a + b * b + 2 * a * b * math.cos(bend))
            assert reach.distance(feet)[leg] == pytest.approx(expected, abs=1e-6)


def test_knee_range_keeps_each_knee_on_its_nominal_branch(anymal_c):
    reach = LegReach(anymal_c)
    lower, upper = reach.joint_range(0.35, 2.4)
    for leg, (haa, _, kfe) in enumerate(anymal_c.leg_joint_names):
        k = anymal_c.joint_names.index(kfe)
        assert lower[k] < anymal_c.nominal_q[k] < upper[k]
        # Straightening the knee to the kept bound leaves the leg short of full reach.
        q = anymal_c.nominal_q.copy()
        q[k] = upper[k] if anymal_c.nominal_q[k] < 0.27 else lower[k]
        assert reach.distance(anymal_c.foot_positions(q))[leg] < float(
            np.sum(anymal_c.leg_lengths[leg])
        )
        i = anymal_c.joint_names.index(haa)
        assert anymal_c.joint_lower[i] < lower[i] < upper[i] < anymal_c.joint_upper[i]


def test_reach_aware_reference_lowers_a_too_high_base_smoothly_and_only_then(anymal_c):
    ns = anymal_c.nominal_stance
    feet = ns.feet + [0.0, 0.0, ns.base_height - anymal_c.foot_radius]
    reach = LegReach(anymal_c)
    # Nominal height: reachable, unchanged.
    low = Reference.standing([0.0, 0.0, ns.base_height], feet, anymal_c.mass, duration=1.0)
    same, _, drop = reach_aware_reference(low, reach)
    assert same is low and not drop.any()

    # A base 12 cm higher: every foot out of reach; lowered just enough.
    def sampler(t: float):
        z = ns.base_height + 0.12 * min(t / 0.5, 1.0)
        return Reference.standing([0.0, 0.0, z], feet, anymal_c.mass)(0.0)

    high = Reference(1.0, sampler)
    assert (reach.excess(high(1.0)) > 0.02).all()
    lowered, times, drop = reach_aware_reference(high, reach)
    assert drop.max() < 0.12
    for t in np.linspace(0.0, 1.0, 41):
        assert reach.excess(lowered(float(t))).max() <= 1e-6
    # The velocity and acceleration corrections are the position correction's derivatives.
    for t in (0.3, 0.55, 0.8):
        h = 1e-4
        dz = [lowered(t + k * h).base_pos[2] - high(t + k * h).base_pos[2] for k in (-1, 0, 1)]
        dv = lowered(t).base_vel[2] - high(t).base_vel[2]
        da = lowered(t).base_acc[2] - high(t).base_acc[2]
        assert dv == pytest.approx((dz[2] - dz[0]) / (2 * h), abs=1e-4)
        assert da == pytest.approx((dz[2] - 2 * dz[1] + dz[0]) / (h * h), abs=2e-2)


def test_qp_respects_acceleration_bounds(anymal_c):
    """With the joints' q̈ bounded the QP's q̈ stays inside, yet still obeys the dynamics."""
    from roughwalk.tracking.tasks import QPLayout, motion_task, regularisation

    nv = 18
    rng = np.random.default_rng(0)
    a = rng.normal(size=(nv, nv))
    mass = a @ a.T + nv * np.eye(nv)
    h = rng.normal(size=nv)
    qp = WholeBodyQP(np.arange(6, nv), np.full(12, 80.0), 0.6)
    layout = QPLayout(nv, 12, 0)
    want = np.zeros(nv)
    want[6:] = 50.0
    tasks = [motion_task("all", layout, np.eye(nv), np.zeros(nv), want, 1.0)]
    tasks += regularisation(layout, 1e-4, 1e-6)
    free = qp.solve(mass, h, np.zeros((0, nv)), tasks)
    bound = 0.5 * float(free.qacc[6:].max())
    assert bound > 0.1
    lower, upper = np.full(nv, -np.inf), np.full(nv, np.inf)
    upper[6:] = bound
    sol = qp.solve(mass, h, np.zeros((0, nv)), tasks, qacc_bounds=(lower, upper))
    assert sol.success
    assert (sol.qacc[6:] <= bound + 1e-6).all() and sol.qacc[6:].max() > bound - 1e-4
    residual = mass @ sol.qacc + h
    residual[6:] -= sol.tau
    assert np.abs(residual).max() < 1e-5


def test_minimum_jerk_derivatives_match_finite_differences():
    for x in (0.1, 0.37, 0.8):
        e = 1e-6
        s0, d0, dd0 = minimum_jerk(x)
        assert d0 == pytest.approx((minimum_jerk(x + e)[0] - minimum_jerk(x - e)[0]) / (2 * e))
        assert dd0 == pytest.approx(
            (minimum_jerk(x + e)[1] - minimum_jerk(x - e)[1]) / (2 * e), rel=1e-5
        )
    assert minimum_jerk(0.0) == (0.0, 0.0, 0.0) and minimum_jerk(1.0)[0] == 1.0


def test_swing_clears_the_pallet_and_lands_off_its_edge(anymal_c):
    terrain = load_terrain("single_pallet")
    planner = SwingPlanner(terrain, anymal_c.foot_radius, clearance=0.08)
    # Find the pallet's front edge along y = 0.
    xs = np.linspace(terrain.extent[0], terrain.extent[1], 2000)
    h = terrain.height(np.stack([xs, np.zeros_like(xs)], axis=1))
    top = float(h.max())
    edge = float(xs[np.argmax(h > 0.5 * top)])
    # A foothold planned on the edge moves to flat ground within reach of the plan.
    on_edge = np.array([edge + 0.005, 0.0, 0.5 * top])
    foothold = planner.foothold(on_edge)
    ring = foothold[:2] + (anymal_c.foot_radius + 0.03) * np.array(
        [[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 24)]
    )
    assert np.ptp(terrain.height(ring)) <= 0.01 + 1e-9
    assert np.linalg.norm(foothold[:2] - on_edge[:2]) <= 0.1 + 1e-9
    assert foothold[2] == pytest.approx(float(terrain.height(foothold[None, :2])[0]))
    # A swing from the ground onto the pallet stays above the terrain all the way.
    start = np.array([edge - 0.1, 0.0, 0.0])
    target = np.array([edge + 0.15, 0.0, top])
    swing = planner.swing(start, target, 1.0, 1.4)
    assert isinstance(swing, SwingTrajectory)
    path = np.array([swing(t)[0] for t in np.linspace(1.0, 1.4, 201)])
    ground = terrain.height(path[:, :2])
    assert (path[1:-1, 2] - ground[1:-1] > 0.0).all()
    np.testing.assert_allclose(swing(1.0)[0], start, atol=1e-12)
    np.testing.assert_allclose(swing(1.4)[0], target, atol=1e-12)
    # Velocities and accelerations are the position's derivatives.
    for t in (1.07, 1.2, 1.33):
        e = 1e-6
        p = [swing(t + k * e)[0] for k in (-1, 1)]
        v = [swing(t + k * e)[1] for k in (-1, 1)]
        np.testing.assert_allclose(swing(t)[1], (p[1] - p[0]) / (2 * e), atol=1e-5)
        np.testing.assert_allclose(swing(t)[2], (v[1] - v[0]) / (2 * e), atol=1e-3)


def test_a_foothold_shift_over_a_pallet_s_side_edge_keeps_the_planned_level(anymal_c):
    # Issue 10, double pallet task 2 at 0 iterations: RF planned on the upper
    # pallet at its side edge; the Raibert shift of a base drifting
    # right moved the target over the edge, and the foot landed 0.31 m lower,
    # beside the pallet, and the robot rolled over it.
    terrain = load_terrain("double_pallet")
    planner = SwingPlanner(terrain, anymal_c.foot_radius)
    ys = np.linspace(-1.0, 0.0, 2001)
    side = ys[np.argmax(terrain.height(np.stack([np.full_like(ys, 1.8), ys], axis=1)) > 0.2)]
    planned = np.array([1.8, side + 0.02, 0.31])
    level = float(terrain.height(planned[None, :2])[0])
    assert level > 0.3
    shift = np.array([0.0, -0.08, 0.0])
    # The shift alone puts the foot beside the pallet, on the ground.
    assert terrain.height((planned + shift)[None, :2])[0] < 0.01
    foothold = planner.foothold(planned, shift)
    ring = foothold[:2] + (anymal_c.foot_radius + 0.03) * np.array(
        [[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 24)]
    )
    # On the planned foothold's level, flat under the whole foot, at the foot's height.
    np.testing.assert_allclose(terrain.height(ring), level, atol=0.01)
    assert foothold[2] == pytest.approx(float(terrain.height(foothold[None, :2])[0]))
    # A shift that stays on the level is kept.
    inward = planner.foothold(planned, np.array([0.05, 0.06, 0.0]))
    assert inward[:2] == pytest.approx(planned[:2] + (0.05, 0.06))
