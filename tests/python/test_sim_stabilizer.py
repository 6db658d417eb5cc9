"""The CoP stabiliser: the measured centre of pressure against the planned ZMP."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from _sim_states import standing_step

import roughwalk
from roughwalk.errors import ConfigError
from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.config import IntegratorConfig, StabilizerConfig
from roughwalk.sim.cop_stabilizer import CopStabilizer, centre_of_pressure
from roughwalk.sim.joint_controller import JointController
from roughwalk.sim.leg_integrator import LegIntegrator
from roughwalk.sim.runner import Runner
from roughwalk.sim.world import World


def test_centre_of_pressure_is_the_force_weighted_mean_of_the_feet() -> None:
    feet = np.array([[0.1, 0.05, 0.0], [0.1, -0.05, 0.02], [-0.1, 0.05, 0.0], [-0.1, -0.05, 0.0]])
    forces = np.zeros((4, 3))
    forces[:, 2] = [10.0, 10.0, 0.0, 20.0]
    forces[:, 0] = 3.0  # tangential forces do not move it
    expected = (10 * feet[0, :2] + 10 * feet[1, :2] + 20 * feet[3, :2]) / 40
    np.testing.assert_allclose(centre_of_pressure(forces, feet), expected, atol=1e-15)
    forces[2, 2] = -5.0  # a pulling foot counts as unloaded
    np.testing.assert_allclose(centre_of_pressure(forces, feet), expected, atol=1e-15)
    assert centre_of_pressure(np.zeros((4, 3)), feet) is None


def test_shift_moves_against_the_cop_error_and_is_bounded(littledog) -> None:
    desired = standing_step(littledog)
    cfg = StabilizerConfig(estimate_s=0.1, follow_s=0.05, max_shift_m=0.01, leak_s=1e9)
    stab = CopStabilizer(cfg, 0.002)
    planned = centre_of_pressure(desired.forces, desired.feet)
    measured = type("M", (), {})()
    measured.time = 0.0
    measured.feet = desired.feet.copy()
    # Shift the measured load so the CoP sits 1 cm in +y of the plan.
    forces = desired.forces.copy()
    weight = forces[:, 2].sum()
    left = desired.feet[:, 1] > desired.base_pos[1]
    span = float(desired.feet[left, 1].mean() - desired.feet[~left, 1].mean())
    forces[left, 2] += 0.01 * weight / span / left.sum()
    forces[~left, 2] -= 0.01 * weight / span / (~left).sum()
    measured.foot_forces = forces
    error = centre_of_pressure(forces, desired.feet) - planned
    np.testing.assert_allclose(error, [0.0, 0.01], atol=1e-9)
    out = stab.update(desired, measured)
    # One tick: d = α·e, then s̈ = ω²·(−d), ṡ = s̈·dt, s = ṡ·dt.
    alpha, omega, dt = 1 - np.exp(-0.002 / 0.1), 1 / 0.05, 0.002
    np.testing.assert_allclose(stab.offset, alpha * error, atol=1e-15)
    np.testing.assert_allclose(stab.shift[:2], -(omega**2) * alpha * error * dt**2, atol=1e-15)
    np.testing.assert_allclose(out.base_pos - desired.base_pos, stab.shift, atol=1e-15)
    assert stab.shift[1] < 0 and abs(stab.shift[0]) < 1e-15
    # Once the estimate is past the bound, the shift settles on the bound, against e.
    stab.offset[:] = [0.0, 0.05]
    for _ in range(1000):
        stab.update(replace(desired, kind="recovery"), measured)  # a recovery reads no CoP
    np.testing.assert_allclose(stab.shift[:2], [0.0, -0.01], atol=1e-6)
    stab.reset()
    assert not np.any(stab.shift)
    off = CopStabilizer(StabilizerConfig(enabled=False))
    assert off.update(desired, measured) is desired


def test_estimate_holds_while_the_contacts_differ_from_the_plan(littledog) -> None:
    desired = standing_step(littledog)
    support = np.array([True, False, True, True])
    forces = desired.forces.copy()
    forces[1] = 0.0
    desired = replace(desired, support=support, forces=forces)
    stab = CopStabilizer(StabilizerConfig(holdoff_s=0.1), 0.002)
    measured = type("M", (), {})()
    measured.feet = desired.feet.copy()
    struck = forces.copy()
    struck[1, 2] = 3.0  # the swing foot strikes something
    for k, (loads, reads) in enumerate([(struck, False), (forces, False), (forces, False)]):
        measured.time = 0.04 * k
        measured.foot_forces = loads
        stab.update(desired, measured)
        assert np.any(stab.offset) == reads
    measured.time = 0.2  # the hold-off is over: the (struck-free) CoP is read again
    measured.foot_forces = forces + np.array([0.0, 0.0, 0.0])
    measured.foot_forces[0, 2] += 2.0
    stab.update(desired, measured)
    assert np.any(stab.offset)


def test_feet_offset_keeps_the_world_footholds_under_the_shifted_trunk(littledog) -> None:
    desired = standing_step(littledog)
    tilted = np.array([np.cos(0.2), 0.0, np.sin(0.2), 0.0])  # pitched 0.4 rad
    desired = replace(desired, base_quat=tilted)
    stab = CopStabilizer(StabilizerConfig())
    stab.shift[:] = [0.004, -0.007, 0.0]
    rot = quat_to_matrix(tilted)
    off = stab.feet_offset(desired)
    f_b = (desired.feet - desired.base_pos) @ rot
    world = (f_b + off) @ rot.T + desired.base_pos + stab.shift
    np.testing.assert_allclose(world, desired.feet, atol=1e-12)


def _standing_cop_error(robot, stabilized: bool, seconds: float = 1.6) -> list[float]:
    """|measured CoP − planned| [m] of the standing robot with a load on one side of its trunk."""
    terrain = roughwalk.load_terrain("flat")
    world = World(robot, terrain)
    runner = Runner(world)
    controller = JointController(world)
    integrator = LegIntegrator(robot, IntegratorConfig(), world.control_dt)
    stab = CopStabilizer(StabilizerConfig(enabled=stabilized), world.control_dt)
    desired = standing_step(robot)
    planned = centre_of_pressure(desired.forces, desired.feet)
    state = runner.reset(desired.q, desired.base_pos, desired.base_quat)
    errors = []
    for k in range(int(seconds / world.control_dt)):
        # From 0.2 s: 5 N pressing down 4 cm left of the trunk's centre (a payload off-centre).
        on = k >= 100
        world.data.xfrc_applied[world.base_body] = [0, 0, -5.0, -0.2, 0, 0] if on else 0.0
        steered = stab.update(desired, state)
        q = integrator.update(steered, state, stab.feet_offset(desired))
        state = runner.step(controller.command(q, steered, state))
        cop = centre_of_pressure(state.foot_forces, state.feet)
        errors.append(float(np.linalg.norm(cop - planned)) if cop is not None else np.inf)
    return errors


def test_stabiliser_brings_the_measured_cop_back_onto_the_plan(littledog) -> None:
    with_stab = _standing_cop_error(littledog, True)
    without = _standing_cop_error(littledog, False)
    assert without[-1] > 0.004  # the load does move the CoP off the plan ...
    assert with_stab[-1] < 0.3 * without[-1]  # ... and the stabiliser takes it back


def test_stabiliser_config_is_checked() -> None:
    with pytest.raises(ConfigError, match="stabilizer.estimate_s"):
        StabilizerConfig(estimate_s=0.0)
    with pytest.raises(ConfigError, match="stabilizer.min_load_n"):
        StabilizerConfig(min_load_n=-1.0)
