"""The Rust leg kinematics and body-pose steps through their bindings.

Forward kinematics and Jacobians are checked against MuJoCo on a synthetic MJCF
quadruped whose legs have rotated bodies, offset joint anchors and flipped axes;
IK against FK (property test) and brute force; every Jacobian against central
differences (Zucker 2011, §3.1–3.4).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from roughwalk._core import (
    LegChain,
    Quadruped,
    support_polygon_margin,
    support_triangle_incircle,
)
from roughwalk.errors import InvalidArgumentError, RobotModelError

LEGS = ("LF", "RF", "LH", "RH")
HIPS = {
    "LF": (0.2, 0.08, 0.0),
    "RF": (0.2, -0.08, 0.0),
    "LH": (-0.2, 0.08, 0.0),
    "RH": (-0.2, -0.08, 0.0),
}
LOWER = (-0.8, -2.5, -2.8)
UPPER = (0.8, 2.5, 2.8)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _quat_to_mat(q: np.ndarray) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=float))
    return m.reshape(3, 3)


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return out


def _rotvec_quat(w: np.ndarray) -> np.ndarray:
    angle = np.linalg.norm(w)
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * w / angle])


def _fmt(v) -> str:
    return " ".join(f"{x:.17g}" for x in np.ravel(v))


def _leg_xml(rng: np.random.Generator, name: str) -> str:
    """One leg with random body rotations and anchors, HFE ∥ KFE ⟂ HAA."""
    quats = [_unit(rng.normal(size=4)) for _ in range(3)]
    rots = [_quat_to_mat(q) for q in quats]
    haa = _unit(rng.normal(size=3))
    hfe_in_hip = _unit(np.cross(haa, rng.normal(size=3)))
    hfe = rots[1].T @ hfe_in_hip
    kfe = rng.choice([-1.0, 1.0]) * rots[2].T @ rots[1].T @ hfe_in_hip
    pos = [np.array(HIPS[name]), rng.uniform(-0.06, 0.06, 3), rng.uniform(-0.15, 0.15, 3)]
    pos[2] += 0.2 * _unit(rng.normal(size=3))
    anchors = [rng.uniform(-0.03, 0.03, 3) for _ in range(3)]
    foot = rng.uniform(-0.05, 0.05, 3) + 0.22 * _unit(rng.normal(size=3))
    axes = [haa, hfe, kfe]
    inertial = '<inertial pos="0 0 0" mass="0.3" diaginertia="1e-3 1e-3 1e-3"/>'
    xml = ""
    for k, joint in enumerate(("HAA", "HFE", "KFE")):
        xml += (
            f'<body name="{name}_{k}" pos="{_fmt(pos[k])}" quat="{_fmt(quats[k])}">{inertial}'
            f'<joint name="{name}_{joint}" type="hinge" pos="{_fmt(anchors[k])}" '
            f'axis="{_fmt(axes[k])}" range="{LOWER[k]} {UPPER[k]}" limited="true"/>'
        )
    xml += f'<site name="{name}_foot" pos="{_fmt(foot)}" size="0.01"/>'
    return xml + "</body>" * 3


def _model(seed: int) -> mujoco.MjModel:
    rng = np.random.default_rng(seed)
    legs = "".join(_leg_xml(rng, name) for name in LEGS)
    xml = f"""
    <mujoco>
      <compiler angle="radian"/>
      <worldbody>
        <body name="trunk" pos="0 0 0.5">
          <freejoint/>
          <inertial pos="0 0 0" mass="5" diaginertia="0.1 0.1 0.1"/>
          {legs}
        </body>
      </worldbody>
    </mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def _leg_from_model(model: mujoco.MjModel, name: str, knee_sign: float = 1.0) -> LegChain:
    bodies = [model.body(f"{name}_{k}").id for k in range(3)]
    joints = [model.joint(f"{name}_{j}").id for j in ("HAA", "HFE", "KFE")]
    return LegChain(
        body_pos=model.body_pos[bodies],
        body_quat=model.body_quat[bodies],
        anchor=model.jnt_pos[joints],
        axis=model.jnt_axis[joints],
        lower=model.jnt_range[joints, 0],
        upper=model.jnt_range[joints, 1],
        velocity_limit=[np.inf] * 3,
        foot=model.site_pos[model.site(f"{name}_foot").id],
        foot_radius=0.01,
        knee_sign=knee_sign,
        name=name,
    )


@pytest.fixture(scope="module")
def model() -> mujoco.MjModel:
    return _model(7)


@pytest.fixture(scope="module")
def robot(model: mujoco.MjModel) -> Quadruped:
    return Quadruped([_leg_from_model(model, name) for name in LEGS])


def _set_state(model, data, base_pos, base_quat, q) -> None:
    data.qpos[:3] = base_pos
    data.qpos[3:7] = base_quat
    for i, name in enumerate(LEGS):
        for k, joint in enumerate(("HAA", "HFE", "KFE")):
            data.qpos[model.jnt_qposadr[model.joint(f"{name}_{joint}").id]] = q[3 * i + k]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)


def _random_q(rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(np.tile(LOWER, 4), np.tile(UPPER, 4))


def test_fk_frames_and_jacobians_match_mujoco(model, robot):
    data = mujoco.MjData(model)
    rng = np.random.default_rng(1)
    for _ in range(20):
        base_pos = rng.uniform(-1, 1, 3)
        base_quat = _unit(rng.normal(size=4))
        q = _random_q(rng)
        _set_state(model, data, base_pos, base_quat, q)
        r = _quat_to_mat(base_quat)
        feet = robot.foot_positions(q, base_pos, base_quat)
        for i, (name, leg) in enumerate(zip(LEGS, robot.legs, strict=True)):
            qi = q[3 * i : 3 * i + 3]
            site = model.site(f"{name}_foot").id
            np.testing.assert_allclose(feet[i], data.site_xpos[site], rtol=0, atol=1e-9)
            np.testing.assert_allclose(r @ leg.fk(qi) + base_pos, data.site_xpos[site], atol=1e-9)
            pos, rot = leg.link_frames(qi)
            for k in range(3):
                body = model.body(f"{name}_{k}").id
                np.testing.assert_allclose(r @ pos[k] + base_pos, data.xpos[body], atol=1e-9)
                np.testing.assert_allclose(r @ rot[k], data.xmat[body].reshape(3, 3), atol=1e-9)
            dofs = [model.jnt_dofadr[model.joint(f"{name}_{j}").id] for j in ("HAA", "HFE", "KFE")]
            jacp = np.zeros((3, model.nv))
            mujoco.mj_jacSite(model, data, jacp, None, site)
            np.testing.assert_allclose(r @ leg.jacobian(qi), jacp[:, dofs], atol=1e-9)
            # A point on the thigh: MuJoCo's mj_jac at its world position.
            point = np.array([0.01, -0.02, 0.03])
            p, jac = leg.point_jacobian(qi, 1, point)
            body = model.body(f"{name}_1").id
            world = data.xpos[body] + data.xmat[body].reshape(3, 3) @ point
            np.testing.assert_allclose(r @ p + base_pos, world, atol=1e-9)
            mujoco.mj_jac(model, data, jacp, None, world, body)
            np.testing.assert_allclose(r @ jac, jacp[:, dofs], atol=1e-9)


@settings(max_examples=300, deadline=None)
@given(
    u=st.tuples(*[st.floats(0.0, 1.0)] * 3),
    leg_index=st.integers(0, 3),
    knee_sign=st.sampled_from([None, 1.0, -1.0]),
)
def test_ik_inverts_fk_inside_the_workspace(robot, u, leg_index, knee_sign):
    leg = robot.legs[leg_index]
    q = np.array(LOWER) + np.array(u) * (np.array(UPPER) - np.array(LOWER))
    f = leg.fk(q)
    q_ik, reachable, within_limits, error = leg.ik(f, knee_sign)
    assert reachable and within_limits
    assert np.all(q_ik >= leg.lower) and np.all(q_ik <= leg.upper)
    assert np.linalg.norm(leg.fk(q_ik) - f) <= 1e-9
    assert error <= 1e-9


def test_out_of_reach_targets_get_the_closest_reachable_foot(robot):
    """IK's foot is at least as close as the best of a dense 41³ sampling of q within limits."""
    n = 41
    grid = np.stack(
        np.meshgrid(*[np.linspace(lo, hi, n) for lo, hi in zip(LOWER, UPPER, strict=True)]),
        axis=-1,
    ).reshape(-1, 3)
    rng = np.random.default_rng(3)
    unreachable = 0
    for i, leg in enumerate(robot.legs):
        rows = np.zeros((len(grid), 12))
        rows[:, 3 * i : 3 * i + 3] = grid
        sampled = robot.fk_batch(rows)[:, i, :]
        hip = leg.link_frames(np.zeros(3))[0][0]
        reach = np.max(np.linalg.norm(sampled - hip, axis=1))
        for _ in range(8):
            # Around the edge of the workspace, where joint limits and reach both bind.
            target = hip + rng.uniform(0.8, 1.5) * reach * _unit(rng.normal(size=3))
            q, reachable, _, error = leg.ik(target)
            best = np.min(np.linalg.norm(sampled - target, axis=1))
            assert np.all(np.isfinite(q))
            assert np.all(q >= leg.lower) and np.all(q <= leg.upper)
            assert error == pytest.approx(np.linalg.norm(leg.fk(q) - target), abs=1e-12)
            assert reachable == (error <= 1e-9)
            assert error <= best + 1e-9
            unreachable += not reachable
    assert unreachable >= 16
    leg = robot.legs[0]
    for target in ([0.0, 0.0, 0.0], [1e300, -1e300, 3.0], [0.0, 0.0, 1e6]):
        q, reachable, _, error = leg.ik(target)
        assert np.all(np.isfinite(q)) and not reachable and not np.isnan(error)


def _finite_difference(f, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    cols = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=1)


def _assert_jacobian(analytic: np.ndarray, numeric: np.ndarray, rel: float = 1e-6) -> None:
    scale = max(np.max(np.abs(analytic)), np.max(np.abs(numeric)), 1e-12)
    np.testing.assert_allclose(analytic, numeric, rtol=0, atol=rel * scale)


def test_leg_jacobians_match_central_differences(robot):
    rng = np.random.default_rng(4)
    for leg in robot.legs:
        for _ in range(5):
            q = rng.uniform(LOWER, UPPER)
            _assert_jacobian(leg.jacobian(q), _finite_difference(leg.fk, q))
            for link in range(3):
                point = rng.uniform(-0.05, 0.05, 3)
                _, jac = leg.point_jacobian(q, link, point)
                fd = _finite_difference(
                    lambda q, leg=leg, link=link, p=point: leg.point_jacobian(q, link, p)[0], q
                )
                _assert_jacobian(jac, fd)


BASE_POS = np.array([0.05, -0.02, 0.0])
BASE_QUAT = _unit(np.array([0.97, 0.05, -0.08, 0.1]))


def _stance(robot: Quadruped) -> np.ndarray:
    """World feet of a well-conditioned stance: per leg, the sampled q whose foot
    Jacobian has the best singular-value ratio (the §3.4 Jacobians invert it)."""
    rng = np.random.default_rng(6)
    q = []
    for leg in robot.legs:
        samples = rng.uniform(LOWER, UPPER, size=(200, 3))
        conditioning = [np.linalg.svd(leg.jacobian(s), compute_uv=False) for s in samples]
        q.append(samples[int(np.argmax([s[-1] / s[0] for s in conditioning]))])
    return robot.foot_positions(np.concatenate(q), BASE_POS, BASE_QUAT)


@pytest.mark.parametrize(
    ("leg", "link", "point"),
    [
        (None, 0, (0.1, 0.05, -0.02)),
        (0, 0, (0.01, 0.0, -0.01)),
        (1, 1, (0.0, 0.02, -0.05)),
        (3, 2, (0.02, 0.0, 0.05)),
    ],
)
def test_pose_jacobians_with_feet_fixed_match_central_differences(robot, leg, link, point):
    feet = _stance(robot)
    _, j_x, j_r = robot.point_pose_jacobians(feet, BASE_POS, BASE_QUAT, leg, link, point)

    def after_translation(dx: np.ndarray) -> np.ndarray:
        return robot.point_pose_jacobians(feet, BASE_POS + dx, BASE_QUAT, leg, link, point)[0]

    def after_rotation(w: np.ndarray) -> np.ndarray:
        quat = _quat_mul(_rotvec_quat(w), BASE_QUAT)
        return robot.point_pose_jacobians(feet, BASE_POS, quat, leg, link, point)[0]

    _assert_jacobian(j_x, _finite_difference(after_translation, np.zeros(3)))
    _assert_jacobian(j_r, _finite_difference(after_rotation, np.zeros(3)))
    if leg is None:
        np.testing.assert_array_equal(j_x, np.eye(3))


def test_obstacle_step_moves_the_point_along_the_gradient_and_keeps_the_feet(robot):
    feet = _stance(robot)
    leg, link, point = 2, 2, np.array([0.02, 0.0, 0.05])
    g = _unit(np.array([0.2, -0.3, 0.9]))
    p, j_x, j_r = robot.point_pose_jacobians(feet, BASE_POS, BASE_QUAT, leg, link, point)
    step = robot.obstacle_avoidance_step(
        feet, BASE_POS, BASE_QUAT, leg, link, point, -0.003, g, alpha=0.5, beta=5.0, clearance=0.002
    )
    assert step.value_before == -0.003
    # Δx = α(c − d)·J_xᵀg and ω = β(c − d)·J_Rᵀg, exactly as documented.
    np.testing.assert_allclose(step.delta_x, 0.5 * 0.005 * j_x.T @ g, atol=1e-15)
    np.testing.assert_allclose(step.omega, 5.0 * 0.005 * j_r.T @ g, atol=1e-15)
    p_new = robot.point_pose_jacobians(feet, step.base_pos, step.base_quat, leg, link, point)[0]
    predicted = j_x @ step.delta_x + j_r @ step.omega
    assert np.dot(p_new - p, g) > 0
    assert np.linalg.norm(p_new - p - predicted) < 0.05 * np.linalg.norm(predicted)
    q, reached = robot.inverse_kinematics(feet, step.base_pos, step.base_quat)
    assert reached.all()
    np.testing.assert_allclose(
        robot.foot_positions(q, step.base_pos, step.base_quat), feet, atol=1e-9
    )
    clear = robot.obstacle_avoidance_step(
        feet, BASE_POS, BASE_QUAT, leg, link, point, 0.01, g, alpha=0.5, beta=5.0, clearance=0.002
    )
    assert not clear.delta_x.any() and not clear.omega.any()


def test_reachability_step_reduces_the_foot_error(robot):
    feet = _stance(robot)
    pos, quat = (
        BASE_POS + np.array([0.05, 0.0, 0.35]),
        _quat_mul(_rotvec_quat(np.array([0.2, 0.1, 0.0])), BASE_QUAT),
    )
    errors = []
    for _ in range(20):
        step = robot.reachability_step(feet, pos, quat, alpha=0.2, beta=1.0)
        errors.append(step.value_before)
        assert step.q is not None and step.reachable is not None
        pos, quat = step.base_pos, step.base_quat
    assert errors[0] > 0.1
    assert all(b < a or b < 1e-9 for a, b in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 0.05 * errors[0]


def test_support_polygon_helpers_know_their_triangles():
    centre, r = support_triangle_incircle([0, 0], [3, 0], [0, 4])
    assert r == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(centre, [1.0, 1.0], atol=1e-15)
    centre, r = support_triangle_incircle([0, 0, 1], [2, 0, 5], [1, np.sqrt(3), -2])
    assert r == pytest.approx(1 / np.sqrt(3), abs=1e-15)
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    assert support_polygon_margin([0.5, 0.5], square) == pytest.approx(0.5)
    assert support_polygon_margin([0.1, 0.6, 9.0], square) == pytest.approx(0.1)
    assert support_polygon_margin([2.0, 2.0], square) == pytest.approx(-np.sqrt(2))
    with pytest.raises(InvalidArgumentError, match=r"shape \(2,\) or \(3,\)"):
        support_polygon_margin([1.0], square)


def test_com_support_step_brings_the_com_inside_with_a_margin():
    feet = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.4, 0.0]])
    offset = np.array([0.02, -0.01, 0.0])
    pos, quat = np.array([0.5, -0.3, 0.2]), np.array([1.0, 0.0, 0.0, 0.0])
    for _ in range(30):
        step = Quadruped.com_support_step(feet, pos, quat, offset, margin=0.04, max_step=0.05)
        assert np.linalg.norm(step.delta_x) <= 0.05 + 1e-15 and step.delta_x[2] == 0.0
        pos = step.base_pos
    assert support_polygon_margin((pos + offset)[:2], feet) == pytest.approx(0.04, abs=1e-12)


def test_batches_agree_with_single_calls(robot):
    rng = np.random.default_rng(5)
    q = np.stack([_random_q(rng) for _ in range(300)])
    feet = robot.fk_batch(q)
    assert feet.shape == (300, 4, 3)
    np.testing.assert_array_equal(feet[17], robot.foot_positions(q[17]))
    q_ik, reached = robot.ik_batch(feet)
    assert q_ik.shape == (300, 12) and reached.shape == (300, 4) and reached.all()
    np.testing.assert_allclose(robot.fk_batch(q_ik), feet, atol=1e-9)


def test_bad_models_and_arguments_are_refused(model, robot):
    leg = robot.legs[0]
    bad_axis = leg.axis.copy()
    bad_axis[2] = np.cross(bad_axis[2], [0.3, 0.4, 0.5])
    kwargs = dict(
        body_pos=leg.body_pos,
        body_quat=leg.body_quat,
        anchor=leg.anchor,
        lower=leg.lower,
        upper=leg.upper,
        velocity_limit=leg.velocity_limit,
        foot=leg.foot,
        foot_radius=0.01,
        knee_sign=1.0,
    )
    with pytest.raises(RobotModelError, match="'RH'.*KFE axis must be parallel"):
        LegChain(axis=bad_axis, name="RH", **kwargs)
    with pytest.raises(
        InvalidArgumentError, match=r"body_quat must have shape \(3, 4\), got \(3, 3\)"
    ):
        LegChain(axis=leg.axis, **{**kwargs, "body_quat": np.zeros((3, 3))})
    with pytest.raises(RobotModelError, match="4 legs"):
        Quadruped(robot.legs[:3])
    with pytest.raises(InvalidArgumentError, match=r"q must have shape \(12,\)"):
        robot.foot_positions(np.zeros(11))
    with pytest.raises(InvalidArgumentError, match="finite"):
        leg.ik([np.nan, 0.0, 0.0])
    with pytest.raises(InvalidArgumentError, match="quaternion"):
        robot.foot_positions(np.zeros(12), np.zeros(3), np.zeros(4))
    with pytest.raises(InvalidArgumentError, match="link index 3"):
        leg.point_jacobian(np.zeros(3), 3, np.zeros(3))
