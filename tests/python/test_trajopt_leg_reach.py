"""The legs' reach in the NLP: each leg's ball against MuJoCo and our IK; plans it keeps sound."""

from __future__ import annotations

import itertools

import mujoco
import numpy as np
import pytest

from roughwalk.robots import Robot, load_robot
from roughwalk.robots._rotations import matrix_to_quat
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Task,
    TrajoptResult,
    melon_config,
    optimize_motion,
    rigid_body_from_robot,
)
from roughwalk.trajopt.parameters import MELON_CONSTRAINTS, MELON_REACH_CONSTRAINTS
from roughwalk.trajopt.robot_model import leg_reach_sphere

MIN_KNEE_BEND = 0.35


@pytest.fixture(scope="module")
def anymal() -> Robot:
    return load_robot("anymal_c")


def _foot_geoms(robot: Robot, model: mujoco.MjModel) -> list[int]:
    out = []
    for src in robot.description.feet:
        token = src.split(" ", 1)[1]
        out.append(int(token[1:]) if token.startswith("#") else model.geom(token.strip("'")).id)
    return out


def _knee_bend(data: mujoco.MjData, hfe: int, kfe: int, foot: int) -> float:
    """Angle [rad] between thigh and shank in the leg's plane (0: straight), from MuJoCo."""
    axis = data.xaxis[hfe] / np.linalg.norm(data.xaxis[hfe])
    thigh = data.xanchor[kfe] - data.xanchor[hfe]
    shank = data.geom_xpos[foot] - data.xanchor[kfe]
    thigh = thigh - (thigh @ axis) * axis
    shank = shank - (shank @ axis) * axis
    cos = thigh @ shank / (np.linalg.norm(thigh) * np.linalg.norm(shank))
    return float(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_reach_ball_is_the_set_of_knee_bends_mujoco_allows(anymal: Robot) -> None:
    """Inside the ball ⇔ knee bent ≥ φ_min, judged by MuJoCo's own joint anchors and feet."""
    sphere = leg_reach_sphere(anymal, MIN_KNEE_BEND)
    assert sphere is not None
    centres, radius = sphere
    model = anymal.mj_model()
    data = mujoco.MjData(model)
    feet = _foot_geoms(anymal, model)
    joints = [[model.joint(n).id for n in leg] for leg in anymal.leg_joint_names]
    rng = np.random.default_rng(3)
    inside = outside = 0
    for _ in range(300):
        q = rng.uniform(anymal.joint_lower, anymal.joint_upper)
        q = np.where(np.isfinite(q), q, 0.0)
        for leg in range(4):  # knees anywhere in ±1.5 rad of straight-ish, both branches
            q[anymal.joint_names.index(anymal.leg_joint_names[leg][1])] = rng.uniform(-1.5, 1.5)
            q[anymal.joint_names.index(anymal.leg_joint_names[leg][2])] = rng.uniform(-1.5, 1.5)
        data.qpos[:] = anymal.qpos(q)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)  # xanchor, xaxis
        for leg in range(4):
            bend = _knee_bend(data, joints[leg][1], joints[leg][2], feet[leg])
            distance = float(np.linalg.norm(data.geom_xpos[feet[leg]] - centres[leg]))
            if abs(bend - MIN_KNEE_BEND) < 1e-3:
                continue
            assert (distance <= radius) == (bend > MIN_KNEE_BEND), (leg, bend, distance, radius)
            inside += distance <= radius
            outside += distance > radius
    assert inside > 100 and outside > 100  # both sides of the boundary were probed


def _contact_to_base(body, robot: Robot, p: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Foot centres (4, 3) in the base frame for contact points p (4, 3) relative to the CoM."""
    return p + np.asarray(body.com_in_base) + np.array([0.0, 0.0, robot.foot_radius])


def test_every_corner_of_the_box_within_reach_is_reached_by_our_ik(anymal: Robot) -> None:
    """Box corners, pulled into the ball where they stick out, are reachable; 2 cm out is not."""
    body = rigid_body_from_robot(anymal)
    assert body.reach_centres is not None and body.reach_radius is not None
    centres, radius = np.asarray(body.reach_centres), body.reach_radius
    stance, dev = body.stance, np.asarray(body.max_deviation)
    pulled = 0
    for signs in itertools.product((-1.0, 1.0), repeat=3):
        corner = stance + np.asarray(signs) * dev
        target = corner.copy()
        for i in range(4):
            if np.linalg.norm(corner[i] - centres[i]) > radius:
                # Largest s with the point nominal + s (corner − nominal) inside the ball.
                lo, hi = 0.0, 1.0
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    point = stance[i] + mid * (corner[i] - stance[i])
                    inside = np.linalg.norm(point - centres[i]) <= radius
                    lo, hi = (mid, hi) if inside else (lo, mid)
                target[i] = stance[i] + lo * (corner[i] - stance[i])
                pulled += 1
                away = (target[i] - centres[i]) / np.linalg.norm(target[i] - centres[i])
                outside = target.copy()
                outside[i] = centres[i] + (radius + 0.02) * away
                _, ok = anymal.inverse_kinematics(_contact_to_base(body, anymal, outside))
                assert not ok[i], (signs, i)
        q, ok = anymal.inverse_kinematics(_contact_to_base(body, anymal, target))
        assert ok.all(), (signs, ok)
        np.testing.assert_allclose(
            anymal.foot_positions(q), _contact_to_base(body, anymal, target), atol=1e-6
        )
    assert pulled > 0  # the box alone reaches beyond the legs: the ball is what keeps plans sound


def test_towr_anymal_keeps_towrs_box_and_has_no_ball() -> None:
    assert TOWR_ANYMAL.max_deviation == (0.15, 0.10, 0.10)
    assert TOWR_ANYMAL.reach_centres is None and TOWR_ANYMAL.reach_radius is None


def test_reach_ball_survives_the_result_json(anymal: Robot) -> None:
    body = rigid_body_from_robot(anymal)
    result = optimize_motion(
        anymal, "flat", Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)), max_iter=0, steps=4, duration=2.0
    )
    assert result.body == body
    again = TrajoptResult.from_dict(result.to_dict())
    assert again.body == body


def _unreachable_fraction(result: TrajoptResult, robot: Robot) -> float:
    """Fraction of 10 ms samples with a planned stance foot out of IK reach of the planned base."""
    from roughwalk.tracking.reference import Reference

    reference = Reference.from_result(result)
    samples = reference.sample_many(np.arange(0.0, reference.duration, 0.01))
    bad = 0
    for s in samples:
        centres = s.feet_pos + np.array([0.0, 0.0, robot.foot_radius])
        _, ok = robot.inverse_kinematics(centres, s.base_pos, matrix_to_quat(s.base_rot))
        bad += bool(np.any(s.contact & ~ok))
    return bad / len(samples)


def test_single_pallet_plans_keep_stance_feet_within_reach(anymal: Robot) -> None:
    """With the ball, the planned base reaches its stance feet; with the box alone it does not."""
    terrain = load_terrain("single_pallet")
    task = Task((0.0, 0.2, 0.2), (1.6, 0.0, 0.0))
    with_ball = optimize_motion(
        anymal, terrain, task, config=melon_config(constraints=MELON_REACH_CONSTRAINTS)
    )
    assert with_ball.solved
    assert _unreachable_fraction(with_ball, anymal) < 0.01
    box_only = melon_config(constraints=MELON_CONSTRAINTS)
    without = optimize_motion(anymal, terrain, task, config=box_only)
    assert without.solved
    assert _unreachable_fraction(without, anymal) > 0.1
