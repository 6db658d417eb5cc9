"""Unit tests of the tracking wing: the whole-body QP, the reference and the contact states."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from roughwalk import load_robot, load_terrain
from roughwalk.tracking import (
    ContactStateConfig,
    ContactStateMachine,
    LegContact,
    Reference,
    TrackingConfig,
    WholeBodyQP,
    friction_pyramid,
)
from roughwalk.tracking.controller import rotation_error, tracking_world
from roughwalk.tracking.tasks import motion_task, regularisation
from roughwalk.tracking.world_terrain import terrain_covering

MU = 0.6


@pytest.fixture(scope="module")
def world():
    robot = load_robot("anymal_c")
    terrain = terrain_covering(load_terrain("flat"), [[0.0, 0.0]])
    w = tracking_world(robot, terrain, TrackingConfig())
    ns = robot.nominal_stance
    base = np.array([0.0, 0.0, ns.base_height])
    q, _ = robot.inverse_kinematics(ns.feet + base, base, [1.0, 0.0, 0.0, 0.0])
    w.reset(q, base, np.array([1.0, 0.0, 0.0, 0.0]))
    return w


def _problem(world, rng, base_acc):
    """M, h, stacked foot Jacobians and tasks at a perturbed, moving state."""
    m, d = world.model, world.data
    data = mujoco.MjData(m)
    data.qpos[:] = d.qpos
    data.qpos[world.joint_qpos] += rng.normal(0.0, 0.05, 12)
    data.qvel[:] = rng.normal(0.0, 0.3, m.nv)
    mujoco.mj_forward(m, data)
    mass = np.zeros((m.nv, m.nv))
    if hasattr(data, "qM"):
        mujoco.mj_fullM(m, mass, data.qM)
    else:
        mujoco.mj_fullM(m, data, mass)
    h = data.qfrc_bias - data.qfrc_passive
    jac = np.zeros((4, 3, m.nv))
    for leg, g in enumerate(world.roles.foot):
        mujoco.mj_jac(m, data, jac[leg], None, data.geom_xpos[g], int(m.geom_bodyid[g]))
    qp = WholeBodyQP(world.joint_dof, world.torque_limit, MU, 2.0, 1500.0)
    layout = qp.layout(m.nv, 4)
    j_base = np.zeros((6, m.nv))
    j_base[:, :6] = np.eye(6)
    tasks = [motion_task("base", layout, j_base, np.zeros(6), base_acc, 1.0)]
    for leg in range(4):
        tasks.append(motion_task("stance", layout, jac[leg], np.zeros(3), np.zeros(3), 100.0))
    tasks += regularisation(layout, 1e-4, 1e-6)
    return data, mass, h, jac.reshape(12, m.nv), qp, tasks


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_qp_solution_satisfies_equations_of_motion_friction_and_torque_limits(world, seed):
    rng = np.random.default_rng(seed)
    # Ask for far more than the robot can do, so friction and torque limits bind.
    demand = rng.normal(0.0, 1.0, 6) * np.array([40.0, 40.0, 60.0, 100.0, 100.0, 100.0])
    _, mass, h, jc, qp, tasks = _problem(world, rng, demand)
    sol = qp.solve(mass, h, jc, tasks)
    assert sol.success
    s_tau = np.zeros(mass.shape[0])
    s_tau[world.joint_dof] = sol.tau
    residual = mass @ sol.qacc + h - s_tau - jc.T @ sol.forces.ravel()
    assert np.abs(residual).max() < 1e-5 * (1.0 + np.abs(h).max())
    f = sol.forces
    assert np.all(f[:, 2] >= 2.0 - 1e-5)
    assert np.all(np.abs(f[:, 0]) <= MU * f[:, 2] + 1e-5)
    assert np.all(np.abs(f[:, 1]) <= MU * f[:, 2] + 1e-5)
    assert np.all(np.abs(sol.tau) <= world.torque_limit + 1e-5)
    # The demand is out of reach, so some limit is active: the test exercises them.
    active_torque = np.isclose(np.abs(sol.tau), world.torque_limit, atol=1e-3).any()
    active_friction = np.isclose(np.abs(f[:, :2]), MU * f[:, 2:], atol=1e-3).any()
    assert active_torque or active_friction


def test_qp_torques_and_forces_produce_its_accelerations_in_mujoco(world):
    """MuJoCo's own forward dynamics, fed the QP's τ and f, gives back the QP's q̈."""
    rng = np.random.default_rng(7)
    data, mass, h, jc, qp, tasks = _problem(world, rng, np.array([0.5, -0.3, 0.8, 0.2, -0.4, 0.1]))
    sol = qp.solve(mass, h, jc, tasks)
    assert sol.success
    m = world.model
    saved = m.opt.disableflags
    m.opt.disableflags = saved | int(
        mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
    )
    try:
        data.ctrl[world.actuator_of_joint] = sol.tau
        data.qfrc_applied[:] = jc.T @ sol.forces.ravel()
        mujoco.mj_forward(m, data)
        np.testing.assert_allclose(data.qacc, sol.qacc, atol=1e-5 * (1 + np.abs(sol.qacc).max()))
    finally:
        m.opt.disableflags = saved


def test_qp_hard_contacts_keep_stance_feet_still(world):
    rng = np.random.default_rng(11)
    _, mass, h, jc, qp, tasks = _problem(world, rng, np.array([3.0, -2.0, 4.0, 5.0, -5.0, 2.0]))
    bias = rng.normal(0.0, 0.5, jc.shape[0])
    sol = qp.solve(mass, h, jc, tasks, contact_bias=bias)
    assert sol.success
    np.testing.assert_allclose(jc @ sol.qacc + bias, 0.0, atol=1e-6)
    soft = qp.solve(mass, h, jc, tasks)
    assert np.abs(jc @ soft.qacc + bias).max() > 1e-3  # the hard rows did something


def test_qp_with_unholdable_hard_contacts_falls_back_to_stance_tasks_within_limits(world):
    """Feet that no torque within the limits can hold still: a solution, not a failed tick.

    A failed tick re-applies the previous tick's torques; on the double pallet
    that happened on up to 20 ticks of a run (issue 10).
    """
    rng = np.random.default_rng(13)
    _, mass, h, jc, qp, tasks = _problem(world, rng, np.zeros(6))
    # Holding the feet still would take 300 m/s² at every foot: far past 80 N·m.
    bias = np.tile([300.0, -300.0, 300.0], 4)
    sol = qp.solve(mass, h, jc, tasks, contact_bias=bias)
    assert sol.success and sol.relaxed
    assert np.all(np.abs(sol.tau) <= world.torque_limit + 1e-5)
    f = sol.forces
    assert np.all(f[:, 2] >= 2.0 - 1e-5)
    assert np.all(np.abs(f[:, :2]) <= MU * f[:, 2:] + 1e-5)
    s_tau = np.zeros(mass.shape[0])
    s_tau[world.joint_dof] = sol.tau
    residual = mass @ sol.qacc + h - s_tau - jc.T @ f.ravel()
    assert np.abs(residual).max() < 1e-5 * (1.0 + np.abs(h).max())
    held = qp.solve(mass, h, jc, tasks, contact_bias=np.zeros(jc.shape[0]))
    assert held.success and not held.relaxed


def test_qp_of_a_real_tick_that_proxqp_called_infeasible_is_solved():
    """A single-pallet tick's QP (dynamics rows only: feasible by construction).

    With proxqp's default infeasibility tolerance (1e-4) it was declared
    primally infeasible after a few iterations and the tick failed (issue 10;
    12 such ticks in that run).
    """
    path = Path(__file__).resolve().parents[1] / "data" / "tracking_qp_spuriously_infeasible.npz"
    z = np.load(path)
    qp = WholeBodyQP(z["actuated"], z["torque_limit"], MU)
    x, stalled = qp._solve_qp(z["p"], z["q"], z["g"], z["g_h"], z["a_eq"], z["b_eq"], None, None)
    assert x is not None and not stalled
    np.testing.assert_allclose(z["a_eq"] @ x, z["b_eq"], atol=1e-5 * (1 + np.abs(z["b_eq"]).max()))
    assert np.all(z["g"] @ x <= z["g_h"] + 1e-5)


def test_friction_pyramid_contains_the_cone_inside_and_excludes_outside():
    rng = np.random.default_rng(3)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    c = friction_pyramid(normal, 0.5)
    t = np.cross(normal, [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    inside = 10.0 * normal + 0.5 * 10.0 / np.sqrt(2) * 0.99 * t  # within the inscribed cone
    outside = 10.0 * normal + 0.5 * 10.0 * 1.01 * t * np.sqrt(2)  # beyond the pyramid's corner
    assert np.all(c @ inside <= 0)
    assert np.any(c @ outside > 0)


def test_rotation_error_is_the_rotation_vector_between_orientations():
    rng = np.random.default_rng(5)
    for _ in range(10):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(0.0, 3.0)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        delta = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
        q = rng.normal(size=4)
        r = np.zeros(9)
        mujoco.mju_quat2Mat(r, q / np.linalg.norm(q))
        r = r.reshape(3, 3)
        np.testing.assert_allclose(rotation_error(delta @ r, r), angle * axis, atol=1e-9)


def test_standing_reference_holds_pose_and_shares_weight():
    feet = np.array([[0.4, 0.3, 0.0], [0.4, -0.3, 0.0], [-0.4, 0.3, 0.0], [-0.4, -0.3, 0.0]])
    ref = Reference.standing([0.0, 0.0, 0.5], feet, mass=40.0, duration=1.0)
    for t in (0.0, 0.5, 3.0):
        s = ref(t)
        np.testing.assert_allclose(s.base_pos, [0.0, 0.0, 0.5])
        np.testing.assert_allclose(s.forces.sum(axis=0), [0.0, 0.0, 40.0 * 9.81])
        assert s.contact.all() and not s.base_vel.any()


def test_contact_state_machine_early_late_flicker_and_slip():
    sm = ContactStateMachine(ContactStateConfig(contact_force_n=5.0, slip_speed_m_s=0.1))
    planned = np.array([True, False, False, True])
    force = np.array([100.0, 0.0, 0.0, 100.0])
    zero = np.zeros(4)
    est = sm.update(0.0, planned, [0.0, 0.3, 0.3, 0.0], force, zero)
    assert est.states == (LegContact.STANCE, LegContact.SWING, LegContact.SWING, LegContact.STANCE)
    # A touch early in the swing is a scuff; after half the swing it is an early touchdown.
    est = sm.update(0.01, planned, [0.0, 0.3, 0.7, 0.0], [100.0, 20.0, 20.0, 100.0], zero)
    assert est.states[1] == LegContact.SWING
    assert est.states[1] == LegContact.SWING
    assert est.states[2] == LegContact.EARLY_TOUCHDOWN and est.stance[2]
    assert sm.counts["early_touchdown"] == 1
    # Leg 1 reaches its planned stance without touching: late, reaching down, no load.
    planned = np.array([True, True, True, True])
    est = sm.update(0.02, planned, zero, [100.0, 0.0, 20.0, 100.0], zero)
    assert est.states[1] == LegContact.LATE_TOUCHDOWN and not est.stance[1]
    assert est.states[2] == LegContact.STANCE
    est = sm.update(0.12, planned, zero, [100.0, 0.0, 20.0, 100.0], zero)
    assert est.late_since[1] == pytest.approx(0.1)
    assert sm.counts["late_touchdown"] == 1
    est = sm.update(0.13, planned, zero, [100.0, 30.0, 20.0, 100.0], zero)
    assert est.states[1] == LegContact.STANCE and est.late_since[1] == 0.0
    # A loaded foot stays loaded down to the release force, and not below it.
    est = sm.update(0.14, planned, zero, [3.0, 30.0, 20.0, 100.0], zero)
    assert est.states[0] == LegContact.STANCE
    est = sm.update(0.15, planned, zero, [0.5, 30.0, 20.0, 100.0], zero)
    assert est.states[0] == LegContact.LATE_TOUCHDOWN
    est = sm.update(0.16, planned, zero, [3.0, 30.0, 20.0, 100.0], zero)
    assert est.states[0] == LegContact.LATE_TOUCHDOWN
    # A sliding stance foot slips, counted once per onset.
    speed = np.array([0.0, 0.5, 0.0, 0.0])
    est = sm.update(0.21, planned, zero, [50.0, 30.0, 20.0, 100.0], speed)
    assert est.slipping.tolist() == [False, True, False, False]
    sm.update(0.22, planned, zero, [50.0, 30.0, 20.0, 100.0], speed)
    assert sm.counts["slip"] == 1


def test_a_planned_stance_foot_resting_on_the_ground_is_in_stance_however_light():
    """A foot on the ground under 1 N is in stance, not late (issue 10's flicker)."""
    sm = ContactStateMachine(ContactStateConfig(contact_force_n=5.0, release_force_n=1.0))
    planned = np.ones(4, dtype=bool)
    zero = np.zeros(4)
    light = np.array([0.5, 0.0, 0.5, 100.0])
    on_ground = np.array([True, True, False, True])
    est = sm.update(0.0, planned, zero, light, zero, on_ground)
    assert est.states[:3] == (LegContact.STANCE, LegContact.STANCE, LegContact.LATE_TOUCHDOWN)
    # Without the contact flags the force alone decides: all three are late.
    est = ContactStateMachine(sm.config).update(0.0, planned, zero, light, zero)
    assert est.states[:3] == (LegContact.LATE_TOUCHDOWN,) * 3
    # A swinging foot that brushes the ground early in its swing still swings.
    swing = np.array([False, True, True, True])
    est = sm.update(0.01, swing, [0.2, 0.0, 0.0, 0.0], light, zero, on_ground)
    assert est.states[0] == LegContact.SWING


def test_terrain_covering_pads_with_edge_heights_and_keeps_the_original():
    terrain = load_terrain("single_pallet")
    grown = terrain_covering(terrain, [[-2.0, 0.0], [1.0, 2.0]], margin=0.5)
    x0, x1, y0, y1 = grown.extent
    assert x0 <= -2.5 + 1e-9 and y1 >= 2.5 - 1e-9
    xy = np.array([[0.0, 0.0], [1.2, 0.3], [2.0, -1.0]])
    np.testing.assert_allclose(grown.height(xy), terrain.height(xy))
    edge = terrain.height(np.array([[terrain.extent[0], 0.0]]))
    np.testing.assert_allclose(grown.height(np.array([[-2.3, 0.0]])), edge)
    assert terrain_covering(terrain, [[0.0, 0.0]], margin=0.5) is terrain


def test_a_first_pose_out_of_reach_is_a_reported_failure_not_an_exception():
    from roughwalk.tracking import execute_reference

    robot = load_robot("anymal_c")
    feet = np.array([[0.4, 0.3, 0.0], [0.4, -0.3, 0.0], [-0.4, 0.3, 0.0], [-0.4, -0.3, 0.0]])
    reference = Reference.standing([0.0, 0.0, 1.5], feet, robot.mass)  # legs are 0.6 m long
    outcome = execute_reference(reference, robot, load_terrain("flat"))
    assert not outcome.success and outcome.reason.startswith("not started")
    assert outcome.simulated_s == 0.0


def test_first_leg_contact_names_the_leg_the_time_and_the_planned_phase():
    from roughwalk.tracking.outcome import TrackingLog, first_leg_contact

    n = 5
    zeros = {k: np.zeros((n, 3)) for k in ("base_pos", "base_pos_ref", "orientation_error")}
    log = TrackingLog(
        t=np.arange(n) * 0.0025,
        base_angvel=np.zeros((n, 3)),
        base_angvel_ref=np.zeros((n, 3)),
        forces=np.zeros((n, 4, 3)),
        forces_ref=np.zeros((n, 4, 3)),
        forces_qp=np.zeros((n, 4, 3)),
        contact_ref=np.tile([True, True, False, True], (n, 1)),
        stance=np.ones((n, 4), dtype=bool),
        torques=np.zeros((n, 12)),
        shin_contact=np.zeros((n, 4), dtype=bool),
        qpos=np.zeros((n, 19)),
        **zeros,
    )
    assert first_leg_contact(log) is None
    log.shin_contact[3:, 2] = True  # LH from the fourth tick, planned in swing
    log.shin_contact[4, 1] = True
    assert first_leg_contact(log) == {"leg": "LH", "t": 0.0075, "planned": "swing"}
    log.shin_contact[2, 1] = True  # RF earlier, planned in stance
    assert first_leg_contact(log) == {"leg": "RF", "t": 0.005, "planned": "stance"}


def test_the_first_pose_puts_planned_stance_feet_on_the_terrain_not_into_or_above_it():
    from roughwalk.tracking.track import _start

    robot = load_robot("anymal_c")
    ns = robot.nominal_stance
    base = np.array([0.0, 0.0, ns.base_height])
    feet = np.array(ns.feet, dtype=float) + base
    feet[:, 2] = [-0.04, 0.05, -0.003, 0.0]  # a plan's first stance feet 4 cm under, 5 cm over
    terrain = terrain_covering(load_terrain("flat"), [[0.0, 0.0]])
    world = tracking_world(robot, terrain, TrackingConfig())
    assert _start(world, Reference.standing(base, feet, robot.mass)) == ""
    mujoco.mj_forward(world.model, world.data)
    centres = world.data.geom_xpos[world.roles.foot]
    # Centimetres off: on the ground; millimetres off: as planned.
    np.testing.assert_allclose(
        centres[:, 2], robot.foot_radius + np.array([0, 0, -0.003, 0]), atol=1e-3
    )
    np.testing.assert_allclose(centres[:, :2], feet[:, :2], atol=1e-3)
