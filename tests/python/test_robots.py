"""The shipped robots: published facts reproduced, kinematics equal MuJoCo's, they stand."""

from __future__ import annotations

import importlib.resources
import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

import roughwalk
from roughwalk import RobotModelError, load_robot
from roughwalk.robots import Robot, list_robots, reference_fk
from roughwalk.robots._rotations import matrix_to_quat

SHIPPED = ("anymal_c", "littledog")
LEGS = ("LF", "RF", "LH", "RH")
URDF_LEGS = {"front_left": "LF", "front_right": "RF", "back_left": "LH", "back_right": "RH"}
URDF_JOINTS = {"hip_roll": "HAA", "hip_pitch": "HFE", "knee": "KFE"}


@pytest.fixture(scope="module", params=SHIPPED)
def shipped(request: pytest.FixtureRequest) -> Robot:
    return load_robot(request.param)


@pytest.fixture(scope="module")
def reference_anymal_path(shared_dir: Path) -> Path:
    return shared_dir / "reference" / "anymal_c" / "anymal_c.xml"


@pytest.fixture(scope="module")
def urdf_littledog(shared_dir: Path) -> mujoco.MjModel:
    """MIT's LittleDog.urdf through MuJoCo's URDF import, keeping every link a body."""
    text = (shared_dir / "reference" / "littledog" / "LittleDog.urdf").read_text()
    head_end = text.index(">", text.index("<robot")) + 1
    text = (
        text[:head_end]
        + '<mujoco><compiler fusestatic="false" discardvisual="true"/></mujoco>'
        + text[head_end:]
    )
    return mujoco.MjModel.from_xml_string(text)


def random_q(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(np.maximum(robot.joint_lower, -3), np.minimum(robot.joint_upper, 3))


def set_joints(model: mujoco.MjModel, data: mujoco.MjData, names, q) -> None:
    for name, value in zip(names, q, strict=True):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value


def foot_geoms(model: mujoco.MjModel) -> list[int]:
    """The sphere geoms of a model (its feet)."""
    return [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE]


# ---- registry and packaging ----------------------------------------------------------


def test_registry_lists_the_shipped_models_inside_the_package() -> None:
    assert [r.name for r in list_robots()] == list(SHIPPED)
    package_models = importlib.resources.files("roughwalk.robots") / "models"
    for info in list_robots():
        assert info.mjcf_path.is_file()
        assert (package_models / info.mjcf_path.name).is_file()
        robot = roughwalk.load_robot(info.name)
        assert robot.mjcf_path == info.mjcf_path
        assert robot.name == info.name
        assert robot.mj_model().nq == 19


def test_unknown_robot_lists_the_known_ones() -> None:
    with pytest.raises(
        RobotModelError, match=r"unknown robot 'anymel'; known: anymal_c, littledog"
    ):
        load_robot("anymel")
    with pytest.raises(RobotModelError, match="does not exist"):
        load_robot("models/no_such_robot.xml")


# ---- kinematics against MuJoCo -------------------------------------------------------


def check_fk_against_mujoco(robot: Robot, n: int = 25) -> None:
    """Random base pose (free-joint qpos) and joint angles: our feet equal MuJoCo's to 1e-9."""
    model = robot.mj_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(42)
    assert all(src.startswith("geom") for src in robot.description.feet)
    geom_of_leg = []
    for src in robot.description.feet:
        token = src.split(" ", 1)[1]
        geom_of_leg.append(
            int(token[1:]) if token.startswith("#") else model.geom(token.strip("'")).id
        )
    base = model.body(robot.base_body).id
    core = robot._quadruped()
    for _ in range(n):
        q = random_q(robot, rng)
        quat = rng.normal(size=4)
        data.qpos[:3] = rng.uniform(-2, 2, 3)
        data.qpos[3:7] = quat / np.linalg.norm(quat)
        set_joints(model, data, robot.joint_names, q)
        mujoco.mj_kinematics(model, data)
        rot_wc = data.xmat[base].reshape(3, 3) @ robot.base_frame_rotation.T
        pos, quat_c = data.xpos[base], matrix_to_quat(rot_wc)
        expected = data.geom_xpos[geom_of_leg]
        np.testing.assert_allclose(robot.foot_positions(q, pos, quat_c), expected, atol=1e-9)
        qc = robot.to_canonical(q)
        numpy_ref = reference_fk.foot_positions(robot.leg_descriptions, qc, pos, quat_c)
        np.testing.assert_allclose(numpy_ref, expected, atol=1e-9)
        if core is not None:
            np.testing.assert_allclose(core.foot_positions(qc, pos, quat_c), numpy_ref, atol=1e-12)


def test_shipped_forward_kinematics_equals_mujoco(shipped: Robot) -> None:
    check_fk_against_mujoco(shipped)


def test_third_party_anymal_forward_kinematics_equals_mujoco(reference_anymal_path: Path) -> None:
    robot = load_robot(reference_anymal_path)
    # It spawns facing −x, but its legs are named: LF sits at +x +y in its body frame.
    np.testing.assert_array_equal(robot.base_frame_rotation, np.eye(3))
    assert robot.description.naming_rule == "names"
    check_fk_against_mujoco(robot)


def test_inverse_kinematics_round_trip(shipped: Robot) -> None:
    rng = np.random.default_rng(7)
    nominal = shipped.nominal_q
    for _ in range(20):
        q = np.clip(nominal + rng.uniform(-0.3, 0.3, 12), shipped.joint_lower, shipped.joint_upper)
        base_pos = rng.uniform(-1, 1, 3)
        quat = np.array([1.0, *rng.uniform(-0.2, 0.2, 3)])
        feet = shipped.foot_positions(q, base_pos, quat)
        q_ik, reachable = shipped.inverse_kinematics(feet, base_pos, quat)
        assert reachable.all()
        np.testing.assert_allclose(shipped.foot_positions(q_ik, base_pos, quat), feet, atol=1e-9)


# ---- published facts -----------------------------------------------------------------


def test_littledog_feet_equal_the_published_urdf(urdf_littledog: mujoco.MjModel) -> None:
    robot = load_robot("littledog")
    urdf = urdf_littledog
    data = mujoco.MjData(urdf)
    ours = robot.mj_model()
    our_data = mujoco.MjData(ours)
    urdf_names = []
    for name in robot.joint_names:
        leg, role = name.split("_")
        urdf_leg = next(k for k, v in URDF_LEGS.items() if v == leg)
        urdf_names.append(next(f"{urdf_leg}_{k}" for k, v in URDF_JOINTS.items() if v == role))
    body = urdf.body("body").id
    urdf_feet = [
        next(
            g
            for g in foot_geoms(urdf)
            if urdf.body(int(urdf.geom_bodyid[g])).name == f"{urdf_leg}_lower_leg"
        )
        for urdf_leg in URDF_LEGS
    ]
    rng = np.random.default_rng(3)
    for _ in range(25):
        q = random_q(robot, rng)
        set_joints(urdf, data, urdf_names, q)
        mujoco.mj_kinematics(urdf, data)
        rot = data.xmat[body].reshape(3, 3)
        expected = (data.geom_xpos[urdf_feet] - data.xpos[body]) @ rot
        np.testing.assert_allclose(robot.foot_positions(q), expected, atol=1e-12)
        np.testing.assert_allclose(urdf.geom_size[urdf_feet, 0], 0.0103)
        # Same joint-space mass matrix: masses, CoMs and inertias agree too.
        our_data.qpos[:] = robot.qpos(q)
        mujoco.mj_forward(ours, our_data)
        mujoco.mj_forward(urdf, data)
        our_m = np.zeros((ours.nv, ours.nv))
        mujoco.mj_fullM(ours, our_data, our_m)
        ref_m = np.zeros((urdf.nv, urdf.nv))
        mujoco.mj_fullM(urdf, data, ref_m)
        dofs = [urdf.jnt_dofadr[urdf.joint(n).id] for n in urdf_names]
        # Our model adds the motors' reflected inertia (armature), which the URDF lacks.
        links_only = our_m[6:, 6:] - np.diag(ours.dof_armature[6:])
        np.testing.assert_allclose(links_only, ref_m[np.ix_(dofs, dofs)], rtol=1e-9, atol=1e-15)
    for name, urdf_name in zip(robot.joint_names, urdf_names, strict=True):
        i = robot.joint_names.index(name)
        np.testing.assert_allclose(
            [robot.joint_lower[i], robot.joint_upper[i]], urdf.jnt_range[urdf.joint(urdf_name).id]
        )
    assert robot.mass == pytest.approx(2.75, rel=0.01)
    assert robot.mass == pytest.approx(float(urdf.body_mass.sum()), rel=1e-12)
    assert robot.foot_radius == 0.0103


def test_littledog_urdf_loads_by_path_as_a_fixed_base(shared_dir: Path) -> None:
    urdf = load_robot(shared_dir / "reference" / "littledog" / "LittleDog.urdf")
    ours = load_robot("littledog")
    assert urdf.description.fixed_base
    q = random_q(ours, np.random.default_rng(1))
    q_urdf = urdf.from_canonical(ours.to_canonical(q))
    np.testing.assert_allclose(urdf.foot_positions(q_urdf), ours.foot_positions(q), atol=1e-12)


def test_anymal_reproduces_the_reference_model(reference_anymal_path: Path) -> None:
    robot = load_robot("anymal_c")
    reference = load_robot(reference_anymal_path)
    ours, ref = robot.mj_model(), reference.mj_model()
    our_data, ref_data = mujoco.MjData(ours), mujoco.MjData(ref)
    assert robot.joint_names == reference.joint_names
    rng = np.random.default_rng(5)
    for _ in range(25):
        q = random_q(robot, rng)
        # In the body frame: the reference spawns turned, so compare base-relative feet.
        np.testing.assert_allclose(robot.foot_positions(q), reference.foot_positions(q), atol=1e-6)
        our_data.qpos[:] = robot.qpos(q)
        ref_data.qpos[:] = reference.qpos(q)
        mujoco.mj_forward(ours, our_data)
        mujoco.mj_forward(ref, ref_data)
        our_m, ref_m = np.zeros((18, 18)), np.zeros((18, 18))
        mujoco.mj_fullM(ours, our_data, our_m)
        mujoco.mj_fullM(ref, ref_data, ref_m)
        np.testing.assert_allclose(our_m, ref_m, rtol=0, atol=1e-6 * np.abs(ref_m).max())
    assert robot.mass == pytest.approx(reference.mass, rel=1e-12)
    assert robot.foot_radius == reference.foot_radius == 0.03
    np.testing.assert_array_equal(robot.joint_lower, reference.joint_lower)
    np.testing.assert_array_equal(robot.joint_upper, reference.joint_upper)
    np.testing.assert_array_equal(robot.joint_torque_limit, reference.joint_torque_limit)
    np.testing.assert_array_equal(robot.joint_torque_limit, 80.0)
    # Collision shapes: the same solids in the same places at a random pose.
    np.testing.assert_equal(len(robot.collision_geoms), len(reference.collision_geoms))
    ours_solids = world_solids(ours, our_data)
    for solid in world_solids(ref, ref_data):
        assert any(
            kind == solid[0]
            and np.allclose(centre, solid[1], atol=2e-6)
            and np.allclose(shape, solid[2], atol=2e-6)
            for kind, centre, shape in ours_solids
        ), f"no counterpart for the reference's {solid[0]} at {solid[1]}"


def world_solids(
    model: mujoco.MjModel, data: mujoco.MjData
) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """Colliding geoms as (type, centre, shape) with shape independent of the local axes' naming."""
    out = []
    for g in range(model.ngeom):
        if model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0:
            continue
        rot = data.geom_xmat[g].reshape(3, 3)
        size = model.geom_size[g]
        kind = int(model.geom_type[g])
        if kind == mujoco.mjtGeom.mjGEOM_BOX:
            shape = (rot @ np.diag(size**2) @ rot.T).ravel()
        elif kind in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE):
            axis = rot[:, 2]
            shape = np.concatenate([size[:2], np.outer(axis, axis).ravel()])
        else:
            shape = size[:1]
        out.append((kind, data.geom_xpos[g].copy(), shape))
    return out


def test_published_limits(shipped: Robot) -> None:
    limits = dict(zip(shipped.joint_names, shipped.joint_velocity_limit, strict=True))
    if shipped.name == "littledog":
        # Zucker 2011, §5.2: hips 7.5 rad/s, knees 14 rad/s.
        for leg in LEGS:
            assert limits[f"{leg}_HAA"] == limits[f"{leg}_HFE"] == 7.5
            assert limits[f"{leg}_KFE"] == 14.0
    else:
        assert set(limits.values()) == {7.5}
    assert np.all(np.isfinite(shipped.joint_torque_limit))
    assert np.all(np.isfinite(shipped.joint_lower)) and np.all(np.isfinite(shipped.joint_upper))


# ---- derived quantities ----------------------------------------------------------------


def test_hips_leg_lengths_and_nominal_stance(shipped: Robot) -> None:
    expected = {
        "littledog": ([0.101, 0.03625, 0.0], [0.0751, np.hypot(0.0265, 0.0985)]),
        "anymal_c": ([0.2999, 0.104, 0.0], [0.285, np.hypot(0.08795, 0.31547)]),
    }[shipped.name]
    signs = np.array([[1, 1, 1], [1, -1, 1], [-1, 1, 1], [-1, -1, 1]])
    np.testing.assert_allclose(shipped.hip_positions, signs * expected[0], atol=1e-12)
    np.testing.assert_allclose(shipped.leg_lengths, np.tile(expected[1], (4, 1)), atol=1e-12)
    feet, height = shipped.nominal_stance
    np.testing.assert_allclose(feet, shipped.foot_positions(shipped.nominal_q))
    np.testing.assert_allclose(feet[:, 2], shipped.foot_radius - height, atol=1e-12)
    # The keyframe puts the trunk at the nominal height, feet on z = 0.
    model = shipped.mj_model()
    assert model.key("home").qpos[2] == pytest.approx(height, abs=1e-4)
    assert shipped.description.nominal_source == "keyframe 'home'"
    # Front knees bend backwards, hind knees forwards.
    assert [leg.knee_sign for leg in shipped.leg_descriptions] == [-1.0, -1.0, 1.0, 1.0]


def test_info_is_json_ready(shipped: Robot) -> None:
    info = json.loads(json.dumps(shipped.info()))
    assert info["name"] == shipped.name
    assert info["mass"] == pytest.approx(shipped.mass)
    assert [j["name"] for j in info["joints"]] == list(shipped.joint_names)
    assert info["joints"][0]["role"] == "HAA"
    assert set(info["leg_lengths"]) == set(LEGS)
    assert info["nominal_stance"]["base_height"] == pytest.approx(shipped.nominal_stance[1])
    assert Path(info["mjcf_path"]).is_file()


def test_center_of_mass_equals_mujoco(shipped: Robot) -> None:
    model = shipped.mj_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    for _ in range(5):
        q = random_q(shipped, rng)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        pos = rng.uniform(-1, 1, 3)
        data.qpos[:] = shipped.qpos(q, pos, quat)
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(
            shipped.center_of_mass(q, pos, quat), data.subtree_com[1], atol=1e-9
        )


# ---- simulation sanity ------------------------------------------------------------------


def test_stands_under_its_own_servos(shipped: Robot, tmp_path: Path) -> None:
    """On flat ground at the home keyframe, holding the nominal pose for 1 s, it stays up."""
    scene = tmp_path / "scene.xml"
    scene.write_text(
        f'<mujoco><include file="{shipped.mjcf_path}"/>'
        '<worldbody><geom name="floor" type="plane" size="5 5 0.1"/></worldbody></mujoco>'
    )
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    height = shipped.nominal_stance.base_height
    floor = model.geom("floor").id
    for _ in range(int(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    z_axis = data.xmat[model.body(shipped.base_body).id].reshape(3, 3)[:, 2]
    assert z_axis[2] > np.cos(np.radians(3))
    # ANYmal's 100 N·m/rad servos sag under 45 kg; LittleDog's barely move.
    assert data.qpos[2] > 0.9 * height
    touching = {
        model.geom(c.geom2 if c.geom1 == floor else c.geom1).name for c in data.contact[: data.ncon]
    }
    assert touching == {f"{leg}_foot" for leg in LEGS}
    assert np.all(np.abs(data.actuator_force) <= shipped.joint_torque_limit + 1e-9)
