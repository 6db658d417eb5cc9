"""The simulation's pieces: world, runner, buffer, integrators, reflex triggers."""

from __future__ import annotations

import dataclasses
import re

import mujoco
import numpy as np
import pytest
from _sim_states import standing_step

import roughwalk
from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.robots.registry import list_robots
from roughwalk.sim.config import IntegratorConfig, ReflexConfig, WorldConfig
from roughwalk.sim.joint_controller import JointController
from roughwalk.sim.leg_integrator import LegIntegrator
from roughwalk.sim.measured_state import measure
from roughwalk.sim.outcome import OutcomeMonitor
from roughwalk.sim.recovery import hold_segment, pose_segment
from roughwalk.sim.reflexes import ReflexMonitor, lean_toward
from roughwalk.sim.runner import Runner, ServoCommand
from roughwalk.sim.trajectory_buffer import Segment, TrajectoryBuffer
from roughwalk.sim.world import World
from roughwalk.terrain import list_generators


@pytest.fixture(scope="module")
def flat() -> roughwalk.Terrain:
    return roughwalk.load_terrain("flat")


def standing_segment(robot: roughwalk.Robot, xy: tuple[float, float] = (0.5, 0.0)) -> Segment:
    """Hold the nominal stance with the trunk over (x, y) on flat ground."""
    st = robot.nominal_stance
    base = np.array([xy[0], xy[1], st.base_height])
    feet = st.feet + base
    return pose_segment(
        robot,
        np.array([base, base]),
        np.zeros((2, 3)),
        np.array([feet, feet]),
        np.ones(4, dtype=bool),
        1.0,
        "hold",
        0.0,
    )


@pytest.mark.parametrize("robot_name", [r.name for r in list_robots()])
def test_world_compiles_and_steps_for_every_robot_and_generator(robot_name: str) -> None:
    # The contract over every registered robot and terrain generator: build,
    # reset, step under the servos, no NaN, and the robot ends up standing.
    robot = roughwalk.load_robot(robot_name)
    stance = robot.nominal_stance
    for info in list_generators():
        terrain = roughwalk.load_terrain(info.name)
        world = World(robot, terrain)
        runner = Runner(world)
        x0, x1, y0, y1 = terrain.extent
        x, y = x0 + 0.3 * (x1 - x0), 0.5 * (y0 + y1)
        ground = float(terrain.height(np.array([[x, y]]))[0])
        runner.reset(robot.nominal_q, [x, y, ground + stance.base_height + 0.02], [1, 0, 0, 0])
        hold = ServoCommand(robot.nominal_q, np.zeros(12), np.zeros(12), np.ones(12))
        for _ in range(100):
            state = runner.step(hold)
        assert np.all(np.isfinite(world.data.qpos)), (robot_name, info.name)
        assert np.all(np.isfinite(state.foot_forces)), (robot_name, info.name)
        assert state.base_pos[2] > terrain.height_range[0], (robot_name, info.name)
        # Same joints, same order as the robot's own model.
        assert world.model.nq == robot.mj_model().nq


def test_world_keeps_the_robots_actuators_and_limits(littledog, flat) -> None:
    world = World(littledog, flat)
    np.testing.assert_allclose(world.torque_limit, littledog.joint_torque_limit)
    own = littledog.mj_model()
    assert world.model.nu == own.nu
    np.testing.assert_allclose(world.model.actuator_forcerange, own.actuator_forcerange)
    # The terrain is one height-field geom whose surface is the terrain's.
    assert world.model.ngeom == own.ngeom + 1
    assert world.model.geom_type[world.roles.terrain] == mujoco.mjtGeom.mjGEOM_HFIELD
    assert set(world.roles.leg[world.roles.foot]) == {0, 1, 2, 3}
    assert len(world.roles.trunk) >= 1


def test_physics_step_is_an_integer_fraction_of_the_control_period(littledog, flat) -> None:
    cfg = WorldConfig(physics_hz=2000.0, control_hz=500.0)
    assert cfg.substeps == 4
    world = World(littledog, flat, cfg)
    assert world.physics_dt == pytest.approx(0.0005)
    assert world.control_dt == pytest.approx(0.002)
    runner = Runner(world)
    seg = standing_segment(littledog)
    runner.reset(seg.q[0], seg.base_pos[0], seg.base_quat[0])
    hold = ServoCommand(seg.q[0], np.zeros(12), np.zeros(12), np.ones(12))
    for k in range(1, 11):
        state = runner.step(hold)
        assert state.time == pytest.approx(k * 0.002, abs=1e-12)
    with pytest.raises(ConfigError, match="integer multiple"):
        WorldConfig(physics_hz=1000.0, control_hz=300.0)
    with pytest.raises(ConfigError, match="timeconst"):
        WorldConfig(physics_hz=200.0, control_hz=100.0)


def test_contact_forces_carry_the_robots_weight(littledog, flat) -> None:
    world = World(littledog, flat)
    runner = Runner(world)
    seg = standing_segment(littledog)
    runner.reset(seg.q[0], seg.base_pos[0], seg.base_quat[0])
    hold = ServoCommand(seg.q[0], np.zeros(12), np.zeros(12), np.ones(12))
    for _ in range(300):
        state = runner.step(hold)
    total = state.foot_forces.sum(axis=0)
    weight = littledog.mass * 9.81
    assert total[2] == pytest.approx(weight, rel=0.02)
    assert abs(total[0]) < 0.02 * weight and abs(total[1]) < 0.02 * weight
    assert np.all(state.foot_forces[:, 2] > 0.1 * weight)
    assert not state.trunk_contact and not np.any(state.shin_contact)


def test_torque_limits_hold_even_when_the_servos_demand_more(littledog, flat) -> None:
    world = World(littledog, flat)
    runner = Runner(world)
    seg = standing_segment(littledog)
    runner.reset(seg.q[0], seg.base_pos[0], seg.base_quat[0])
    # A target 0.5 rad away asks kp·0.5 = 12.5 N·m of every joint: 5-9× the limits.
    target = seg.q[0] + 0.5 * np.sign(littledog.nominal_q + 1e-3)
    command = ServoCommand(target, np.zeros(12), np.zeros(12), np.ones(12))
    runner._target = target.copy()  # skip the rate limiter: a step demand
    peaks = np.zeros(12)
    for _ in range(5):
        state = runner.step(command)
        peaks = np.maximum(peaks, np.abs(state.actuator_force))
    limit = littledog.joint_torque_limit
    assert np.all(runner.max_actuator_force <= limit + 1e-9)
    # The limit is reached, so the clamp (not a small demand) is what held it.
    np.testing.assert_allclose(peaks, limit, rtol=1e-9)


def test_runner_limits_the_commanded_joint_speed(littledog, flat) -> None:
    world = World(littledog, flat)
    runner = Runner(world)
    seg = standing_segment(littledog)
    runner.reset(seg.q[0], seg.base_pos[0], seg.base_quat[0])
    jump = seg.q[0] + 0.3
    before = runner.target
    runner.step(ServoCommand(jump, np.zeros(12), np.zeros(12), np.ones(12)))
    moved = np.abs(runner.target - before)
    np.testing.assert_allclose(moved, littledog.joint_velocity_limit * world.control_dt)


def test_buffer_plays_segments_first_in_first_out_and_waits_for_late_ones(littledog) -> None:
    seg = standing_segment(littledog)
    a = hold_segment(seg.sample(0.0), 0.1, 0.0, kind="a")
    moved = seg.sample(0.0)
    b_state = type(moved)(**{**moved.__dict__, "q": moved.q + 0.1})
    b = hold_segment(b_state, 0.1, 0.0, kind="b")
    buf = TrajectoryBuffer()
    buf.append(a)
    buf.append(b.with_ready_at(0.15))
    kinds, waits = [], []
    for k in range(200):
        now = 0.002 * k
        state, waiting, _ = buf.advance(now)
        assert state is not None
        kinds.append(buf.current.kind if buf.current is not None else None)
        waits.append(waiting)
    kinds_arr = np.array(kinds, dtype=object)
    waits_arr = np.array(waits)
    t = 0.002 * np.arange(200)
    assert np.all(kinds_arr[t <= 0.1 - 1e-9] == "a")
    # b is late: the robot holds a's end from 0.1 s to 0.15 s and the wait shows.
    late = (t > 0.1 + 1e-9) & (t < 0.15 - 1e-9)
    assert np.all(waits_arr[late]) and np.all(kinds_arr[late] == None)  # noqa: E711
    assert np.all(kinds_arr[(t >= 0.15) & (t <= 0.25 - 1e-9)] == "b")
    assert len(buf) == 0


def test_segment_knows_the_time_to_each_touchdown(littledog) -> None:
    seg = standing_segment(littledog)
    n = 11
    t = np.linspace(0.0, 1.0, n)
    support = np.ones((n, 4), dtype=bool)
    support[2:7, 1] = False  # RF in flight from t = 0.2 to 0.6, down again at 0.7
    s = Segment(
        t=t,
        q=np.repeat(seg.q[:1], n, 0),
        qd=np.zeros((n, 12)),
        base_pos=np.repeat(seg.base_pos[:1], n, 0),
        base_quat=np.repeat(seg.base_quat[:1], n, 0),
        feet=np.repeat(seg.feet[:1], n, 0),
        support=support,
        forces=np.zeros((n, 4, 3)),
        phase=np.zeros(n, dtype=np.int64),
    )
    assert s.sample(0.3).touchdown_in[1] == pytest.approx(0.4)
    assert s.sample(0.45).touchdown_in[1] == pytest.approx(0.25)
    assert np.isinf(s.sample(0.3).touchdown_in[0])
    with pytest.raises(InvalidArgumentError):
        Segment(
            t=t[::-1],
            q=s.q,
            qd=s.qd,
            base_pos=s.base_pos,
            base_quat=s.base_quat,
            feet=s.feet,
            support=s.support,
            forces=s.forces,
            phase=s.phase,
        )


def _hold_with_load(robot, terrain, integrator_on: bool, seconds: float = 3.0) -> list[float]:
    """Trunk position error [m] while a constant external force pushes the standing robot."""
    world = World(robot, terrain)
    runner = Runner(world)
    controller = JointController(world)
    integrator = LegIntegrator(robot, IntegratorConfig(enabled=integrator_on), world.control_dt)
    desired = standing_segment(robot).sample(0.0)
    state = runner.reset(desired.q, desired.base_pos, desired.base_quat)
    errors = []
    for k in range(int(seconds / world.control_dt)):
        # The forced offset: 10 N down and 5 N sideways on the trunk from 0.5 s on.
        world.data.xfrc_applied[world.base_body, :3] = [4.0, 3.0, -10.0] if k >= 250 else 0.0
        q = integrator.update(desired, state)
        state = runner.step(controller.command(q, desired, state))
        errors.append(float(np.linalg.norm(state.base_pos - desired.base_pos)))
    return errors


def test_leg_integrators_reduce_the_body_error_after_a_forced_offset(littledog, flat) -> None:
    # Zucker 2011, §6: the integrators shorten or lengthen the supporting legs
    # until the trunk is back where it should be.
    with_integrators = _hold_with_load(littledog, flat, True)
    without = _hold_with_load(littledog, flat, False)
    offset = max(with_integrators[250:300])
    assert offset > 0.0015  # the force does displace the trunk
    assert with_integrators[-1] < 0.4 * offset  # and the integrators take it back
    assert with_integrators[-1] < 0.3 * without[-1]


def test_integrator_decays_in_flight_and_follows_the_update_rule(littledog) -> None:
    integrator = LegIntegrator(littledog, IntegratorConfig(gain=0.01, flight_decay_s=0.05), 0.002)
    desired = standing_segment(littledog).sample(0.0)
    support = desired.support.copy()
    support[3] = False
    desired = type(desired)(**{**desired.__dict__, "support": support})
    measured = type("M", (), {})()
    measured.base_pos = desired.base_pos + np.array([0.0, 0.0, -0.01])  # trunk 1 cm low
    measured.rotation = np.eye(3)
    measured.foot_forces = np.tile([0.0, 0.0, 8.0], (4, 1))  # every foot bears load
    integrator.delta[3] = [0.0, 0.0, 0.02]
    q = integrator.update(desired, measured)
    # Supporting legs: Δ = γ(f_B − f̄_B) = 0.01 · (0, 0, −0.01): lengthen the legs.
    np.testing.assert_allclose(integrator.delta[:3], [[0.0, 0.0, -1e-4]] * 3, atol=1e-12)
    np.testing.assert_allclose(integrator.delta[3], [0.0, 0.0, 0.02 * np.exp(-0.002 / 0.05)])
    # q = IK_B(f_B + Δ): the commanded feet sit Δ below the desired ones in the body frame.
    feet_b = littledog.foot_positions(q)
    np.testing.assert_allclose(
        feet_b - littledog.foot_positions(desired.q), integrator.delta, atol=1e-9
    )


def test_integrator_holds_on_a_planned_support_foot_that_bears_no_load(littledog) -> None:
    integrator = LegIntegrator(littledog, IntegratorConfig(gain=0.01, min_load_n=1.0), 0.002)
    desired = standing_segment(littledog).sample(0.0)
    measured = type("M", (), {})()
    measured.base_pos = desired.base_pos + np.array([0.0, 0.0, -0.01])
    measured.rotation = np.eye(3)
    measured.foot_forces = np.tile([0.0, 0.0, 8.0], (4, 1))
    measured.foot_forces[1, 2] = 0.5  # RF planned down, lifted off by a rocking trunk
    integrator.delta[1] = [0.0, 0.0, 0.005]
    integrator.update(desired, measured)
    np.testing.assert_allclose(integrator.delta[[0, 2, 3]], [[0.0, 0.0, -1e-4]] * 3, atol=1e-12)
    # RF's Δ neither grows nor decays.
    np.testing.assert_array_equal(integrator.delta[1], [0.0, 0.0, 0.005])


def _roll_after_a_side_push(robot, terrain, min_load_n: float, impulse_ns: float) -> list[float]:
    """|Trunk roll| [rad] of the standing robot after a sideways push of ``impulse_ns`` [N·s]."""
    world = World(robot, terrain)
    runner = Runner(world)
    controller = JointController(world)
    config = IntegratorConfig(min_load_n=min_load_n)
    integrator = LegIntegrator(robot, config, world.control_dt)
    desired = standing_segment(robot).sample(0.0)
    state = runner.reset(desired.q, desired.base_pos, desired.base_quat)
    rolls = []
    for k in range(int(2.5 / world.control_dt)):
        # 0.1 s of force from 0.2 s on.
        push = [0.0, impulse_ns / 0.1, 0.0] if 100 <= k < 150 else [0.0, 0.0, 0.0]
        world.data.xfrc_applied[world.base_body, :3] = push
        q = integrator.update(desired, state)
        state = runner.step(controller.command(q, desired, state))
        r = state.rotation
        rolls.append(float(abs(np.arctan2(r[2, 1], r[2, 2]))))
    return rolls


def test_a_standing_robot_rocked_by_a_push_settles_without_integrator_windup(
    littledog, flat
) -> None:
    # A 1.5 N·s side push rocks LittleDog onto two feet. Integrating the
    # lifted legs' errors while they hang pumps the rocking until it falls;
    # holding their Δ (anti-windup) lets it settle.
    settled = _roll_after_a_side_push(littledog, flat, 1.0, 1.5)
    assert max(settled) > 0.1  # the push really rocks it (> 6°)
    assert max(settled[-250:]) < 0.01
    wound_up = _roll_after_a_side_push(littledog, flat, 0.0, 1.5)
    assert max(wound_up) > 0.6  # the same push, integrating every planned support: it falls


def test_reflex_fires_only_on_errors_that_persist(littledog) -> None:
    monitor = ReflexMonitor(ReflexConfig(body_position_m=0.02, persist_s=0.03))
    desired = standing_segment(littledog).sample(0.0)
    measured = type("M", (), {})()
    measured.feet = desired.feet.copy()
    measured.foot_forces = desired.forces.copy()
    measured.base_quat = desired.base_quat.copy()
    fired = []
    for k in range(40):
        measured.time = 0.002 * k
        # A 1-tick glitch at k = 3, then a lasting 3 cm offset from k = 10.
        offset = 0.03 if (k == 3 or k >= 10) else 0.0
        measured.base_pos = desired.base_pos + np.array([0.0, offset, 0.0])
        trigger = monitor.check(desired, measured)
        fired.append(trigger)
    hits = [k for k, f in enumerate(fired) if f is not None]
    assert hits and hits[0] == 25  # 10 + 0.03 s / 0.002 s
    assert fired[25].kind == "body_position"
    assert fired[25].value == pytest.approx(0.03)


def _foot_force_hits(littledog, per_leg: bool, short_legs) -> list[int]:
    """Ticks at which the foot-force reflex fires; ``short_legs(k)``: the feet unloaded at k."""
    monitor = ReflexMonitor(ReflexConfig(persist_s=0.03, foot_force_per_leg=per_leg))
    desired = standing_step(littledog, in_contact=(True, True, False, True), kind="hold")
    measured = type("M", (), {})()
    measured.feet = desired.feet.copy()
    measured.base_pos = desired.base_pos.copy()
    tilt = 0.05  # beyond foot_force_tilt_rad: the trunk tips
    measured.base_quat = np.array([np.cos(tilt / 2), np.sin(tilt / 2), 0.0, 0.0])
    hits = []
    for k in range(60):
        measured.time = 0.002 * k
        forces = desired.forces.copy()
        forces[short_legs(k), 2] = 0.0
        measured.foot_forces = forces
        trigger = monitor.check(desired, measured)
        if trigger is not None and trigger.kind == "foot_force":
            hits.append(k)
    return hits


def test_a_foot_force_reflex_per_leg_waits_for_one_foot_short_of_load_throughout(
    littledog,
) -> None:
    """``reflex.foot_force_per_leg``: board AE, bench large rocks seed 0, at 0.77-0.79 s.

    RH chattered on a rock face (0 N every other tick) while LF let go for
    a few ticks at a time: no one foot lost its load for 0.03 s, but some
    foot always lacked it, and the reflex fired.
    """
    # LF (0) and RH (3) short of load in turn, 2 ticks each.
    in_turn = lambda k: [0] if (k // 2) % 2 == 0 else [3]  # noqa: E731
    assert _foot_force_hits(littledog, False, in_turn)  # any foot: fires
    assert _foot_force_hits(littledog, True, in_turn) == []
    # One foot short throughout fires with either, the persistence time
    # after the feet count as settled (down 0.06 s: tick 30).
    lf = lambda k: [0] if k >= 10 else []  # noqa: E731
    assert _foot_force_hits(littledog, False, lf)[0] == 45
    assert _foot_force_hits(littledog, True, lf)[0] == 45


def test_a_supporting_foot_sliding_2_5_cm_fires_the_default_foot_position_reflex(
    littledog,
) -> None:
    """``reflex.foot_position_m``: board AE, bench large rocks seed 3 (``--expansions 40000``).

    LF slid 2.2–2.8 cm down a rock while RF swung; at 3.5 cm no reflex
    fired until the trunk had tipped 0.21 rad 0.1 s later, and the
    recovery's stance had no plan. Caught at 2.5 cm, it reached the goal.
    """
    monitor = ReflexMonitor(ReflexConfig())
    desired = standing_segment(littledog).sample(0.0)
    measured = type("M", (), {})()
    measured.base_pos = desired.base_pos.copy()
    measured.base_quat = desired.base_quat.copy()
    measured.foot_forces = desired.forces.copy()
    hits = []
    for k in range(80):
        measured.time = 0.002 * k
        measured.feet = desired.feet.copy()
        if k >= 40:  # LF, down 0.08 s (settled), slides 2.5 cm
            measured.feet[0, 0] -= 0.025
        trigger = monitor.check(desired, measured)
        if trigger is not None:
            hits.append((k, trigger.kind, trigger.leg))
    assert hits and hits[0] == (55, "foot_position", "LF")  # 40 + 0.03 s / 0.002 s


def _lost_load_hits(
    littledog, config: ReflexConfig, in_contact, planned, carried, descent_m_s: float
) -> list[int]:
    """Ticks at which the foot-force reflex fires for a foot that carries less than planned.

    ``planned`` and ``carried`` (4,): vertical loads [N]; the planned trunk
    sinks at ``descent_m_s`` [m/s], the measured one follows it tilted 0.045 rad.
    """
    monitor = ReflexMonitor(config)
    standing = standing_step(littledog, in_contact=in_contact)
    forces = standing.forces.copy()
    forces[:, 2] = planned
    measured = type("M", (), {})()
    measured.feet = standing.feet.copy()
    tilt = 0.045  # beyond foot_force_tilt_rad
    measured.base_quat = np.array([np.cos(tilt / 2), 0.0, np.sin(tilt / 2), 0.0])
    measured.foot_forces = forces.copy()
    measured.foot_forces[:, 2] = carried
    hits = []
    for k in range(60):
        measured.time = 0.002 * k
        base = standing.base_pos - np.array([0.0, 0.0, descent_m_s * measured.time])
        desired = dataclasses.replace(standing, base_pos=base, forces=forces)
        measured.base_pos = base.copy()
        measured.com = base.copy()
        trigger = monitor.check(desired, measured)
        if trigger is not None and trigger.kind == "foot_force":
            hits.append(k)
    return hits


def test_a_lightly_planned_foot_unloaded_by_a_planned_descent_is_no_tip(littledog) -> None:
    """``reflex.foot_force_descent_m_s`` / ``foot_force_descent_n``: recorded loads.

    Bench gap seed 1 (``--expansions 40000``) at 7.95-7.98 s: LF swings down
    to the trench floor, the planned trunk sinks 0.14 m/s, RH (planned 3.3 N)
    carries nothing and the trunk is 0.04-0.05 rad off its plan: a false
    alarm. Pushed right at 2.0 s on flat ground (``bench_push_recovery.py
    --direction -90``) at 2.36-2.39 s: LF (planned 2.9 N) carries nothing
    with the trunk level in its plan, and the reflex is a rescue.
    """
    cfg = ReflexConfig(
        persist_s=0.03,
        foot_force_descent_m_s=0.05,
        foot_force_descent_n=4.0,
        foot_force_descent_lean_m=-1.0,  # whatever the lean: the planned loads alone
    )
    off = ReflexConfig(persist_s=0.03, foot_force_descent_n=0.0)  # off
    trench = ((False, True, True, True), [0.0, 13.1, 10.7, 3.3], [0.0, 14.0, 11.3, 0.0])
    assert _lost_load_hits(littledog, off, *trench, 0.14)  # judged as before: it fires
    assert _lost_load_hits(littledog, cfg, *trench, 0.14) == []
    pushed = ((True, True, True, False), [2.9, 13.1, 10.4, 0.0], [0.0, 20.3, 6.1, 0.0])
    assert _lost_load_hits(littledog, cfg, *pushed, 0.0)[0] == 45  # settled at 30, + 0.03 s
    # A descent does not hide a foot planned to carry a real share.
    heavy = ((False, True, True, True), [0.0, 10.0, 6.0, 10.0], [0.0, 12.0, 8.0, 0.0])
    assert _lost_load_hits(littledog, cfg, *heavy, 0.14)


# Recorded ticks (``bench_littledog.py --expansions 40000``, session 17): the
# planned support, planned and carried vertical loads [N], measured and planned
# feet [m], the measured centre of mass [m] and the planned trunk's descent [m/s].
_GAP_1_RH_LIGHT = {  # gap seed 1 at 7.976 s: LF swings down to the trench floor
    "support": (False, True, True, True),
    "planned": [0.0, 13.27, 10.74, 3.29],
    "carried": [0.0, 15.28, 13.05, 0.0],
    "feet": [
        [0.9961, 0.0515, -0.0067],
        [0.8983, -0.0689, 0.0102],
        [0.8165, 0.0634, 0.0102],
        [0.7591, -0.0347, 0.0107],
    ],
    "feet_desired": [
        [0.9933, 0.0535, 0.0001],
        [0.8939, -0.0677, 0.0103],
        [0.8080, 0.0636, 0.0103],
        [0.7575, -0.0323, 0.0103],
    ],
    "com": [0.8510, -0.0087, 0.1211],
    "descent": 0.138,
}
_LARGE_ROCKS_2_LF_LIGHT = {  # board AE, large rocks seed 2 at 1.520 s: RH swings
    "support": (True, True, True, False),
    "planned": [2.37, 14.98, 8.87, 0.0],
    "carried": [0.0, 17.25, 10.29, 0.0],
    "feet": [
        [0.3435, 0.3373, 0.0971],
        [0.2589, 0.2566, 0.1005],
        [0.1321, 0.3567, 0.0855],
        [0.1365, 0.2260, 0.1218],
    ],
    "feet_desired": [
        [0.3429, 0.3354, 0.0959],
        [0.2545, 0.2563, 0.0999],
        [0.1288, 0.3574, 0.0863],
        [0.1353, 0.2277, 0.1269],
    ],
    "com": [0.2161, 0.2920, 0.2243],
    "descent": 0.126,
}


def _recorded_load_hits(littledog, config: ReflexConfig, recorded: dict) -> list[int]:
    """Ticks at which the foot-force reflex fires on a recorded tick held still.

    The trunk sinks as recorded, the measured one tilted 0.045 rad from its plan.
    """
    monitor = ReflexMonitor(config)
    standing = standing_step(littledog, in_contact=recorded["support"])
    forces = np.zeros((4, 3))
    forces[:, 2] = recorded["planned"]
    measured = type("M", (), {})()
    measured.feet = np.array(recorded["feet"])
    measured.com = np.array(recorded["com"])
    tilt = 0.045  # beyond foot_force_tilt_rad
    measured.base_quat = np.array([np.cos(tilt / 2), 0.0, np.sin(tilt / 2), 0.0])
    measured.foot_forces = np.zeros((4, 3))
    measured.foot_forces[:, 2] = recorded["carried"]
    hits = []
    for k in range(60):
        measured.time = 0.002 * k
        base = standing.base_pos - np.array([0.0, 0.0, recorded["descent"] * measured.time])
        desired = dataclasses.replace(
            standing, base_pos=base, forces=forces, feet=np.array(recorded["feet_desired"])
        )
        measured.base_pos = base.copy()
        trigger = monitor.check(desired, measured)
        if trigger is not None and trigger.kind == "foot_force":
            hits.append(k)
    return hits


def test_the_descent_exemption_needs_the_robot_to_lean_onto_the_light_foot(littledog) -> None:
    """``reflex.foot_force_descent_lean_m``: recorded loads and centre of mass.

    Gap seed 1's false alarm: RH light while the trunk sinks towards the
    trench, the centre of mass 0.9 cm past the RF–LH line on RH's side.
    Large rocks seed 2's rescue: LF light on a rock face while the trunk
    sinks as fast, the centre of mass on the RF–LH line (0.1 cm): the
    session-16 exemption (no lean asked) hid it as well.
    """
    gap, rocks = _GAP_1_RH_LIGHT, _LARGE_ROCKS_2_LF_LIGHT
    lean = lean_toward(np.array(gap["com"]), np.array(gap["feet"]), np.array(gap["support"]))
    assert lean[3] == pytest.approx(0.0089, abs=5e-4)
    lean = lean_toward(np.array(rocks["com"]), np.array(rocks["feet"]), np.array(rocks["support"]))
    assert lean[0] == pytest.approx(0.0011, abs=5e-4)
    off = ReflexConfig(persist_s=0.03, foot_force_descent_n=0.0)  # no exemption: both fire
    assert _recorded_load_hits(littledog, off, gap)[0] == 45  # settled at 30, + 0.03 s
    assert _recorded_load_hits(littledog, off, rocks)[0] == 45
    exempt = dict(persist_s=0.03, foot_force_descent_m_s=0.05, foot_force_descent_n=4.0)
    leaning = ReflexConfig(**exempt)  # the lean asked by default: 0.5 cm
    assert ReflexConfig().foot_force_descent_n == 4.0  # the default since session 17
    assert _recorded_load_hits(littledog, leaning, gap) == []
    assert _recorded_load_hits(littledog, leaning, rocks)[0] == 45
    any_lean = ReflexConfig(**exempt, foot_force_descent_lean_m=-1.0)  # session 16's exemption
    assert _recorded_load_hits(littledog, any_lean, rocks) == []


def _pairs(world: World) -> set[frozenset[str]]:
    """Body-name pairs of the active contacts."""
    m, d = world.model, world.data
    return {
        frozenset((m.body(m.geom_bodyid[c.geom1]).name, m.body(m.geom_bodyid[c.geom2]).name))
        for c in d.contact[: d.ncon]
    }


def test_littledog_legs_never_touch_its_trunk_hull_but_the_trunk_meets_the_ground(
    littledog, flat
) -> None:
    # The trunk box is a hull wider than the body between the hip joints: with
    # the nominal hip flexion and knee angles the right hind upper leg meets
    # it from about 0.20 rad of hip roll, which rocky starts hold. No leg link
    # may touch it, at any hip roll of its range; the trunk still meets the
    # terrain.
    world = World(littledog, flat)
    m, d = world.model, world.data
    home = m.key("home").qpos.copy()
    legs = [b for bodies in littledog.description.leg_bodies for b in bodies]
    assert len(legs) == 12
    rolls = [m.joint(f"{leg}_HAA").qposadr[0] for leg in ("LF", "RF", "LH", "RH")]
    for roll in np.linspace(-0.6, 0.6, 13):
        d.qpos[:] = home
        d.qpos[2] += 0.3
        d.qpos[rolls] = roll
        mujoco.mj_forward(m, d)
        touching = [p for p in _pairs(world) if "trunk" in p and p - {"trunk"} <= set(legs)]
        assert not touching, f"hip roll {roll:.2f} rad: {touching}"
    d.qpos[:] = home
    d.qpos[2] = 0.02  # the trunk lowered onto the floor, legs splayed through it
    mujoco.mj_forward(m, d)
    assert any("trunk" in p and "world" in p for p in _pairs(world))


def test_a_robot_file_whose_legs_touch_its_trunk_shows_as_self_contacts(
    littledog, flat, tmp_path
) -> None:
    # A user's MJCF with a trunk hull the legs reach: the measured state says
    # so on every tick it happens, and the run's outcome counts the ticks.
    text = littledog.mjcf_path.read_text()
    without = re.sub(r"<contact>.*?</contact>", "", text, flags=re.S)
    assert without != text
    path = tmp_path / "littledog_no_excludes.xml"
    path.write_text(without)
    rubbing = roughwalk.load_robot(path)
    for robot, expected in ((littledog, False), (rubbing, True)):
        world = World(robot, flat)
        m, d = world.model, world.data
        d.qpos[:] = m.key("home").qpos
        d.qpos[2] += 0.3
        d.qpos[m.joint("RH_HAA").qposadr[0]] = 0.5  # towards the trunk
        mujoco.mj_forward(m, d)
        state = measure(world)
        assert state.self_contact is expected
        monitor = OutcomeMonitor(np.array([1.0, 0.0]), np.zeros(2))
        monitor.update(state, None)
        monitor.update(state, None)
        assert monitor.self_contacts == (2 if expected else 0)
