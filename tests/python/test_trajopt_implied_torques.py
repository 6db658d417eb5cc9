"""The joint torques a plan's forces imply: against MuJoCo's own Jacobians and by hand."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from roughwalk.robots import Robot, load_robot, reference_fk
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import Task, implied_torques, melon_config, optimize_motion
from roughwalk.trajopt.implied_torques import plan_joint_torques


@pytest.fixture(scope="module")
def anymal() -> Robot:
    return load_robot("anymal_c")


def _pose(anymal: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A tilted, turned base over a crouched stance: base position, quaternion, contact points."""
    base_pos = np.array([0.3, -0.1, 0.45])
    roll, yaw = 0.12, 0.2  # [rad]: the base turned by yaw about z after roll about x
    cr, sr, cy, sy = np.cos(roll / 2), np.sin(roll / 2), np.cos(yaw / 2), np.sin(yaw / 2)
    quat = np.array([cy * cr, cy * sr, sy * sr, sy * cr])
    q = anymal.nominal_q + np.linspace(-0.15, 0.15, 12)
    centres = anymal.foot_positions(q, base_pos, quat)
    return base_pos, quat, centres - [0.0, 0.0, anymal.foot_radius]


def test_torques_match_mujoco_applied_force(anymal: Robot) -> None:
    """−Jᵀf per leg equals minus MuJoCo's generalised force of f at the foot (mj_applyFT)."""
    base_pos, quat, feet = _pose(anymal)
    forces = np.array([[30.0, -20.0, 150.0], [-60.0, 10.0, 90.0], [5, 40, 200], [80, -30, 120]])
    contact = np.array([True, True, True, True])
    tau, reachable = plan_joint_torques(anymal, base_pos, quat, feet, forces, contact)
    assert reachable.all()

    m = anymal.mj_model()
    d = mujoco.MjData(m)
    q, _ = anymal.inverse_kinematics(feet + [0, 0, anymal.foot_radius], base_pos, quat)
    d.qpos[:] = anymal.qpos(q, base_pos, quat)
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    names = anymal.joint_names
    dofs = [int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)]) for n in names]
    centres = feet + [0.0, 0.0, anymal.foot_radius]
    expected = np.zeros(12)
    for leg, joints in enumerate(anymal.leg_joint_names):
        knee = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joints[2])
        qfrc = np.zeros(m.nv)
        mujoco.mj_applyFT(
            m, d, forces[leg], np.zeros(3), centres[leg], int(m.jnt_bodyid[knee]), qfrc
        )
        for n in joints:
            expected[names.index(n)] -= qfrc[dofs[names.index(n)]]
    np.testing.assert_allclose(tau, expected, atol=1e-6)


def test_vertical_force_by_hand(anymal: Robot) -> None:
    """A level base, a vertical force F on LF only: the HFE holds F times the horizontal lever."""
    stance = anymal.nominal_stance
    base_pos = np.array([0.0, 0.0, stance.base_height])
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    feet = stance.feet + base_pos - [0.0, 0.0, anymal.foot_radius]
    force = 200.0
    forces = np.zeros((4, 3))
    forces[:, 2] = force
    contact = np.array([True, False, False, False])
    tau, _ = plan_joint_torques(anymal, base_pos, quat, feet, forces, contact)

    leg = anymal.leg_descriptions[0]
    q = anymal.to_canonical(anymal.nominal_q)[:3]
    positions, rotations = reference_fk.leg_link_frames(leg, q)
    hfe = positions[1] + rotations[1] @ leg.anchor[1]
    axis = rotations[1] @ leg.axis[1]
    foot = stance.feet[0]
    # τ holds the moment of the ground's push about the axis: −((x − p) × f)·a.
    by_hand = -np.dot(np.cross(foot - hfe, [0.0, 0.0, force]), axis)
    assert abs(axis[1]) > 0.99  # HFE turns about the body's y axis
    assert tau[anymal.joint_names.index("LF_HFE")] == pytest.approx(by_hand, abs=1e-6)
    # For a pure y axis that is ±F times the foot's fore/aft offset from the HFE.
    assert abs(by_hand) == pytest.approx(force * abs(foot[0] - hfe[0]), rel=0.02)
    others = [i for i, n in enumerate(anymal.joint_names) if not n.startswith("LF")]
    assert np.all(tau[others] == 0.0)  # swing feet ask nothing


def test_a_plan_reports_its_largest_torque(anymal: Robot) -> None:
    """The flat walk's 0-iteration guess: the reported maximum is the one at its time and joint."""
    result = optimize_motion(
        anymal,
        load_terrain("flat"),
        Task((0.0, 0.0, 0.0), (0.6, 0.0, 0.0)),
        config=melon_config(gait="walk", steps=8, duration=3.0),
        max_iter=0,
    )
    found = implied_torques(result, anymal, rate_hz=50.0)
    plan = result.sample(times=[found.time_s])
    tau, _ = plan_joint_torques(
        anymal,
        plan["base_position"][0],
        plan["base_quat"][0],
        plan["feet_position"][0],
        plan["forces"][0],
        plan["contact"][0],
    )
    assert np.abs(tau).max() == pytest.approx(found.max_nm, rel=1e-9)
    assert anymal.joint_names[int(np.argmax(np.abs(tau)))] == found.joint
    assert found.limit_nm == 80.0
    assert 10.0 < found.max_nm < found.limit_nm  # a walk on flat ground stays within the motors
    assert found.to_dict()["joint"] == found.joint


def test_over_limit_counts_a_weaker_joint_than_the_most_loaded() -> None:
    # LittleDog's knees hold 1.4 N·m, its hips 2.5: a plan asking 2.2 of a hip
    # and 2.0 of a knee passes the knee's limit though its largest torque does not.
    from roughwalk.trajopt import ImpliedTorques

    worst = ImpliedTorques(
        max_nm=2.2,
        time_s=0.5,
        joint="LF_HFE",
        limit_nm=2.5,
        over_limit_fraction=0.1,
        unreachable_fraction=0.0,
    )
    assert worst.over_limit
