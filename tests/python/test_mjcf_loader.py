"""The MJCF quadruped loader on synthetic models built here, checked against MuJoCo.

Each synthetic robot is described in its canonical frame (x forward, y left,
z up) and then written into MJCF with a chosen body-frame rotation, leg order,
naming, random body orientations and joint anchors, jointless bodies in the
chain, joint ``ref`` offsets, feet as geoms or sites. The loader must recover
the canonical frame and legs, and its kinematics must equal MuJoCo's.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
import pytest

from roughwalk import RobotModelError, load_robot
from roughwalk.robots import Robot, leg_label, reference_fk
from roughwalk.robots._rotations import matrix_to_quat, quat_to_matrix

LEGS = ("LF", "RF", "LH", "RH")
SIGN = {"LF": (1, 1), "RF": (1, -1), "LH": (-1, 1), "RH": (-1, -1)}  # (front, left)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return quat_to_matrix(q / np.linalg.norm(q))


def fmt(values: np.ndarray | list[float]) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


@dataclass
class Synthetic:
    """Options of a synthetic quadruped (defaults: a plain, well-named robot)."""

    leg_order: tuple[str, ...] = LEGS
    prefix: dict[str, str] = field(default_factory=lambda: {leg: leg for leg in LEGS})
    joint_names: tuple[str, str, str] = ("HAA", "HFE", "KFE")
    body_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))  # R_bc
    base_quat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    foot: str = "geom"  # "geom" | "site" | "none"
    twist: bool = False  # random body orientations and anchors
    mount: bool = False  # a jointless body between the base and the hip
    foot_body: bool = False  # the foot on a jointless body below the shank
    merge_hip: bool = False  # HAA and HFE on one body
    ref: float = 0.0  # joint ref of every hinge
    fixed_base: bool = False
    drop_leg: str | None = None
    drop_joint: str | None = None  # leg whose KFE is removed
    slide_leg: str | None = None  # leg whose KFE is a slide joint
    skew_knee: bool = False  # KFE axis not parallel to HFE's: no analytic IK
    head: str = ""  # extra XML inside the base body
    actuators: str = ""
    seed: int = 0


def synthetic_xml(opt: Synthetic) -> str:
    """MJCF text of the synthetic quadruped."""
    rng = np.random.default_rng(opt.seed)
    r_bc = opt.body_rotation
    legs_xml = []
    for leg in opt.leg_order:
        if leg == opt.drop_leg:
            continue
        fx, ly = SIGN[leg]
        p = opt.prefix[leg]
        # Canonical geometry: joint locations, axes, foot.
        joints = [
            np.array([0.2 * fx, 0.1 * ly, 0.0]),
            np.array([0.2 * fx, 0.15 * ly, 0.0]),
            np.array([0.2 * fx, 0.16 * ly, -0.2]),
        ]
        axes = [np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, -1.0 * ly, 0])]
        if opt.skew_knee:
            axes[2] = np.array([0.6, -0.8 * ly, 0.0])
        foot = np.array([0.2 * fx + 0.03 * fx, 0.16 * ly, -0.41])
        joints = [r_bc @ j for j in joints]
        axes = [r_bc @ a for a in axes]
        foot = r_bc @ foot

        def rot() -> np.ndarray:
            return random_rotation(rng) if opt.twist else np.eye(3)

        def anchor() -> np.ndarray:
            return rng.uniform(-0.03, 0.03, 3) if opt.twist else np.zeros(3)

        def inertial() -> str:
            return (
                f'<inertial mass="{rng.uniform(0.2, 1.0)!r}" '
                f'pos="{fmt(rng.uniform(-0.02, 0.02, 3))}" '
                f'diaginertia="{fmt(rng.uniform(1e-3, 2e-3, 3))}"/>'
            )

        parent_rot, parent_pos = np.eye(3), np.zeros(3)
        xml_open = []
        if opt.mount:
            m_rot, m_pos = rot(), rng.uniform(-0.05, 0.05, 3)
            xml_open.append(
                f'<body name="{p}_mount" pos="{fmt(m_pos)}" quat="{fmt(matrix_to_quat(m_rot))}">'
                + inertial()
            )
            parent_rot, parent_pos = m_rot, m_pos
        kinds = ["hinge", "hinge", "slide" if leg == opt.slide_leg else "hinge"]
        roles = list(opt.joint_names)
        n_joints = 2 if leg == opt.drop_joint else 3
        body_names = ["hip", "thigh", "shank"]
        k = 0
        while k < n_joints:
            group = [k, k + 1] if (opt.merge_hip and k == 0) else [k]
            w = rot()  # the body's orientation in the base frame
            a = anchor()
            origin = joints[k] - w @ a
            local_pos = parent_rot.T @ (origin - parent_pos)
            local_rot = parent_rot.T @ w
            body = (
                f'<body name="{p}_{body_names[k]}" pos="{fmt(local_pos)}" '
                f'quat="{fmt(matrix_to_quat(local_rot))}">' + inertial()
            )
            for j in group:
                jpos = a if j == k else w.T @ (joints[j] - origin)
                body += (
                    f'<joint name="{p}_{roles[j]}" type="{kinds[j]}" pos="{fmt(jpos)}" '
                    f'axis="{fmt(w.T @ axes[j])}" range="-2.5 2.5" ref="{opt.ref!r}"/>'
                )
            half_way = w.T @ (foot - origin) * 0.5
            body += f'<geom type="capsule" size="0.01" fromto="0 0 0 {fmt(half_way)}"/>'
            xml_open.append(body)
            parent_rot, parent_pos = w, origin
            k += len(group)
        local_foot = parent_rot.T @ (foot - parent_pos)
        if opt.foot_body:
            f_rot = rot()
            xml_open.append(
                f'<body name="{p}_foot_link" pos="{fmt(local_foot)}" '
                f'quat="{fmt(matrix_to_quat(f_rot))}">' + inertial()
            )
            local_foot = np.zeros(3)
        if opt.foot == "geom":
            xml_open.append(
                f'<geom name="{p}_foot" type="sphere" size="0.02" pos="{fmt(local_foot)}"/>'
            )
        elif opt.foot == "site":
            xml_open.append(f'<site name="{p}_foot" pos="{fmt(local_foot)}" size="0.01"/>')
        n_bodies = sum(1 for s in xml_open if s.startswith("<body"))
        legs_xml.append("".join(xml_open) + "</body>" * n_bodies)
    free = "" if opt.fixed_base else '<freejoint name="root"/>'
    return f"""<mujoco model="synthetic">
  <compiler angle="radian"/>
  <worldbody>
    <body name="trunk" pos="0 0 0.5" quat="{fmt(opt.base_quat)}">
      {free}
      <inertial mass="5" pos="{fmt(rng.uniform(-0.02, 0.02, 3))}" diaginertia="0.1 0.2 0.25"/>
      <geom type="box" size="{fmt(np.abs(r_bc @ [0.25, 0.1, 0.05]))}"/>
      {opt.head}
      {"".join(legs_xml)}
    </body>
  </worldbody>
  {opt.actuators}
</mujoco>"""


def load_synthetic(opt: Synthetic, tmp_path: Path) -> Robot:
    path = tmp_path / f"synthetic_{opt.seed}.xml"
    path.write_text(synthetic_xml(opt))
    return load_robot(path)


def mujoco_feet(robot: Robot, opt: Synthetic, q: np.ndarray, qpos_base: np.ndarray | None):
    """World foot centres by MuJoCo (canonical leg order) and the canonical base pose."""
    model = robot.mj_model()
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    if qpos_base is not None:
        data.qpos[:7] = qpos_base
    for name, value in zip(robot.joint_names, q, strict=True):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    mujoco.mj_kinematics(model, data)
    feet = []
    for leg in LEGS:
        name = f"{opt.prefix[leg]}_foot"
        if opt.foot == "geom":
            feet.append(data.geom_xpos[model.geom(name).id])
        elif opt.foot_body:
            feet.append(data.xpos[model.body(name + "_link").id])
        else:
            feet.append(data.site_xpos[model.site(name).id])
    base = model.body("trunk").id
    # The expected canonical frame comes from the construction, not from the loader.
    rot_wc = data.xmat[base].reshape(3, 3) @ opt.body_rotation
    return np.array(feet), data.xpos[base].copy(), matrix_to_quat(rot_wc), data


def random_q(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(np.maximum(robot.joint_lower, -3), np.minimum(robot.joint_upper, 3))


def random_free_pose(rng: np.random.Generator) -> np.ndarray:
    quat = rng.normal(size=4)
    return np.concatenate([rng.uniform(-1, 1, 3), quat / np.linalg.norm(quat)])


Y_FORWARD = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # R_bc: x_c -> y_b
CASES = {
    "plain": Synthetic(),
    "twisted": Synthetic(twist=True, mount=True, seed=1),
    "unitree_names_shuffled": Synthetic(
        leg_order=("RH", "LF", "LH", "RF"),
        prefix={"LF": "FL", "RF": "FR", "LH": "RL", "RH": "RR"},
        joint_names=("hip_joint", "thigh_joint", "calf_joint"),
        twist=True,
        seed=2,
    ),
    "y_forward_named": Synthetic(
        body_rotation=Y_FORWARD,
        prefix={"LF": "front_left", "RF": "front_right", "LH": "rear_left", "RH": "rear_right"},
        twist=True,
        seed=3,
    ),
    # No telling names: the loader must use the hips and the spawn orientation,
    # which turns the y-forward body so that it faces the world's +x.
    "y_forward_by_geometry": Synthetic(
        body_rotation=Y_FORWARD,
        base_quat=tuple(matrix_to_quat(Y_FORWARD.T)),
        prefix={"LF": "leg_a", "RF": "leg_b", "LH": "leg_c", "RH": "leg_d"},
        leg_order=("LH", "RF", "RH", "LF"),
        seed=4,
    ),
    "site_feet_on_foot_bodies": Synthetic(foot="site", foot_body=True, twist=True, seed=5),
    "merged_hip_and_ref": Synthetic(merge_hip=True, ref=0.3, twist=True, mount=True, seed=6),
    "fixed_base": Synthetic(fixed_base=True, twist=True, seed=7),
    "headed": Synthetic(
        head='<body name="head" pos="0.3 0 0.1"><geom type="sphere" size="0.05"/>'
        '<site name="camera_site"/></body>',
        seed=8,
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_forward_kinematics_equals_mujoco(case: str, tmp_path: Path) -> None:
    opt = CASES[case]
    robot = load_synthetic(opt, tmp_path)
    rng = np.random.default_rng(11)
    np.testing.assert_allclose(robot.base_frame_rotation, opt.body_rotation.T, atol=1e-12)
    for _ in range(20):
        q = random_q(robot, rng)
        pose = None if opt.fixed_base else random_free_pose(rng)
        expected, base_pos, base_quat, _ = mujoco_feet(robot, opt, q, pose)
        ours = robot.foot_positions(q, base_pos, base_quat)
        np.testing.assert_allclose(ours, expected, atol=1e-9)
        qc = robot.to_canonical(q)
        numpy_ref = reference_fk.foot_positions(robot.leg_descriptions, qc, base_pos, base_quat)
        np.testing.assert_allclose(numpy_ref, expected, atol=1e-9)


@pytest.mark.parametrize("case", sorted(CASES))
def test_legs_and_joints_are_named_canonically(case: str, tmp_path: Path) -> None:
    opt = CASES[case]
    robot = load_synthetic(opt, tmp_path)
    assert robot.legs == LEGS
    for leg, joints in zip(LEGS, robot.leg_joint_names, strict=True):
        assert joints == tuple(f"{opt.prefix[leg]}_{r}" for r in opt.joint_names)
    # joint_names keeps the file's order; canonical_index picks the legs apart.
    model = robot.mj_model()
    file_order = [model.joint(j).name for j in range(model.njnt) if model.jnt_type[j] == 3]
    assert list(robot.joint_names) == file_order
    canonical = [robot.joint_names[i] for i in robot.canonical_index]
    assert canonical == [j for joints in robot.leg_joint_names for j in joints]
    q = np.arange(12.0)
    np.testing.assert_array_equal(robot.from_canonical(robot.to_canonical(q)), q)
    expected_rule = "geometry" if case == "y_forward_by_geometry" else "names"
    assert robot.description.naming_rule == expected_rule
    # Hips come out where the construction put them.
    for leg, hip in zip(LEGS, robot.hip_positions, strict=True):
        fx, ly = SIGN[leg]
        np.testing.assert_allclose(hip, [0.2 * fx, 0.1 * ly, 0.0], atol=1e-12)


@pytest.mark.parametrize("case", sorted(CASES))
def test_inverse_kinematics_inverts_forward_kinematics(case: str, tmp_path: Path) -> None:
    robot = load_synthetic(CASES[case], tmp_path)
    rng = np.random.default_rng(4)
    for _ in range(10):
        q = rng.uniform(-1.5, 1.5, 12)
        pose = random_free_pose(rng)
        feet = robot.foot_positions(q, pose[:3], pose[3:])
        q_ik, reachable = robot.inverse_kinematics(feet, pose[:3], pose[3:])
        assert reachable.all()
        assert np.all(q_ik >= robot.joint_lower) and np.all(q_ik <= robot.joint_upper)
        np.testing.assert_allclose(robot.foot_positions(q_ik, pose[:3], pose[3:]), feet, atol=1e-9)


def test_legs_without_analytic_ik_structure_keep_forward_kinematics(tmp_path: Path) -> None:
    opt = Synthetic(skew_knee=True, twist=True, seed=12)
    robot = load_synthetic(opt, tmp_path)
    rng = np.random.default_rng(0)
    q = random_q(robot, rng)
    pose = random_free_pose(rng)
    expected, base_pos, base_quat, _ = mujoco_feet(robot, opt, q, pose)
    np.testing.assert_allclose(robot.foot_positions(q, base_pos, base_quat), expected, atol=1e-9)
    with pytest.raises(RobotModelError, match="synthetic"):
        robot.inverse_kinematics(expected, base_pos, base_quat)


def test_qpos_and_base_pose_round_trip_through_mujoco(tmp_path: Path) -> None:
    opt = CASES["y_forward_by_geometry"]
    robot = load_synthetic(opt, tmp_path)
    rng = np.random.default_rng(3)
    model = robot.mj_model()
    data = mujoco.MjData(model)
    for _ in range(10):
        q = random_q(robot, rng)
        pose = random_free_pose(rng)
        data.qpos[:] = robot.qpos(q, pose[:3], pose[3:])
        mujoco.mj_kinematics(model, data)
        feet = np.array([data.geom_xpos[model.geom(f"{opt.prefix[leg]}_foot").id] for leg in LEGS])
        np.testing.assert_allclose(feet, robot.foot_positions(q, pose[:3], pose[3:]), atol=1e-9)
        pos, quat = robot.base_pose_from_qpos(data.qpos)
        np.testing.assert_allclose(pos, pose[:3], atol=1e-12)
        assert abs(abs(quat @ pose[3:]) - 1.0) < 1e-12
        np.testing.assert_allclose(robot.joint_angles_from_qpos(data.qpos), q, atol=0)


def test_site_foot_has_zero_radius_and_geom_foot_its_sphere(tmp_path: Path) -> None:
    site = load_synthetic(CASES["site_feet_on_foot_bodies"], tmp_path)
    geom = load_synthetic(CASES["plain"], tmp_path)
    assert site.foot_radius == 0.0
    assert all(src.startswith("site ") for src in site.description.feet)
    assert geom.foot_radius == pytest.approx(0.02)
    assert geom.description.feet[0] == "geom 'LF_foot'"


def test_center_of_mass_and_inertias_equal_mujoco(tmp_path: Path) -> None:
    opt = CASES["twisted"]
    robot = load_synthetic(opt, tmp_path)
    model = robot.mj_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(5)
    assert robot.mass == pytest.approx(float(model.body_mass.sum()), rel=1e-12)
    for _ in range(5):
        q = random_q(robot, rng)
        pose = random_free_pose(rng)
        data.qpos[:] = robot.qpos(q, pose[:3], pose[3:])
        mujoco.mj_forward(model, data)
        com = robot.center_of_mass(q, pose[:3], pose[3:])
        np.testing.assert_allclose(com, data.subtree_com[model.body("trunk").id], atol=1e-9)
    # Trunk composite (trunk + jointless mounts) inertia about its CoM, from MuJoCo's world data.
    trunk = [model.body("trunk").id] + [model.body(f"{leg}_mount").id for leg in LEGS]
    masses = model.body_mass[trunk]
    coms = data.xipos[trunk]
    com = masses @ coms / masses.sum()
    inertia = np.zeros((3, 3))
    for b, m, c in zip(trunk, masses, coms, strict=True):
        r = data.ximat[b].reshape(3, 3)
        d = c - com
        inertia += r @ np.diag(model.body_inertia[b]) @ r.T + m * (
            d @ d * np.eye(3) - np.outer(d, d)
        )
    rot_wc = quat_to_matrix(pose[3:])
    np.testing.assert_allclose(robot.base_mass, masses.sum(), rtol=1e-12)
    np.testing.assert_allclose(rot_wc @ robot.base_com + pose[:3], com, atol=1e-9)
    np.testing.assert_allclose(rot_wc @ robot.base_inertia @ rot_wc.T, inertia, atol=1e-12)


def test_collision_geoms_sit_on_their_links(tmp_path: Path) -> None:
    opt = CASES["merged_hip_and_ref"]
    robot = load_synthetic(opt, tmp_path)
    model = robot.mj_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(9)
    q = random_q(robot, rng)
    pose = random_free_pose(rng)
    data.qpos[:] = robot.qpos(q, pose[:3], pose[3:])
    mujoco.mj_kinematics(model, data)
    rot_wc = quat_to_matrix(pose[3:])
    qc = robot.to_canonical(q).reshape(4, 3)
    assert len(robot.collision_geoms) == model.ngeom
    for g in robot.collision_geoms:
        if g.leg is None:
            pos, rot = np.zeros(3), np.eye(3)
        else:
            i = LEGS.index(g.leg)
            positions, rotations = reference_fk.leg_link_frames(robot.leg_descriptions[i], qc[i])
            assert g.link is not None
            pos, rot = positions[g.link], rotations[g.link]
        world_pos = pose[:3] + rot_wc @ (pos + rot @ g.pos)
        world_rot = rot_wc @ rot @ quat_to_matrix(g.quat)
        np.testing.assert_allclose(world_pos, data.geom_xpos[g.geom_id], atol=1e-9)
        np.testing.assert_allclose(world_rot, data.geom_xmat[g.geom_id].reshape(3, 3), atol=1e-9)


def test_limits_from_actuators_and_custom_numerics(tmp_path: Path) -> None:
    actuators = """
  <actuator>
    <motor joint="LF_HAA" gear="2" ctrlrange="-3 3"/>
    <position joint="LF_HFE" kp="10" forcerange="-5 5"/>
    <position joint="LF_KFE" kp="10"/>
  </actuator>
  <custom><numeric name="velocity_limit:LF_KFE" data="9"/></custom>"""
    opt = Synthetic(actuators=actuators)
    xml = synthetic_xml(opt).replace(
        '<joint name="RF_HAA"', '<joint name="RF_HAA" actuatorfrcrange="-4 4"'
    )
    path = tmp_path / "limits.xml"
    path.write_text(xml)
    robot = load_robot(path)
    limits = dict(zip(robot.joint_names, robot.joint_torque_limit, strict=True))
    assert limits["LF_HAA"] == 6.0  # gear × |ctrl|
    assert limits["LF_HFE"] == 5.0
    assert limits["LF_KFE"] == np.inf  # an unclamped position servo
    assert limits["RF_HAA"] == 4.0
    speeds = dict(zip(robot.joint_names, robot.joint_velocity_limit, strict=True))
    assert speeds["LF_KFE"] == 9.0
    assert speeds["LF_HAA"] == np.inf
    np.testing.assert_array_equal(robot.joint_lower, -2.5)


def test_nominal_pose_from_keyframe_or_clipped_qpos0(tmp_path: Path) -> None:
    plain = load_synthetic(Synthetic(ref=3.0), tmp_path)
    assert plain.description.nominal_source.startswith("qpos0")
    np.testing.assert_allclose(plain.nominal_q, 2.5)  # ref 3.0 clipped to the range
    xml = synthetic_xml(Synthetic()).replace(
        "</worldbody>",
        '</worldbody><keyframe><key name="crouch" qpos="0 0 0.4 1 0 0 0 '
        + " ".join(["0 0.5 -1.0"] * 4)
        + '"/></keyframe>',
    )
    path = tmp_path / "key.xml"
    path.write_text(xml)
    robot = load_robot(path)
    assert robot.description.nominal_source == "keyframe 'crouch'"
    np.testing.assert_allclose(robot.to_canonical(robot.nominal_q), [0, 0.5, -1.0] * 4)
    stance = robot.nominal_stance
    np.testing.assert_allclose(stance.feet, robot.foot_positions(robot.nominal_q))
    assert stance.base_height == pytest.approx(-stance.feet[:, 2].mean() + 0.02)


@pytest.mark.parametrize(
    ("opt", "message"),
    [
        (Synthetic(drop_leg="RH"), "found 3 leg-like chains"),
        (Synthetic(drop_joint="LH"), "leg 'LH_hip' has 2 hinge joints (LH_HAA, LH_HFE)"),
        (Synthetic(slide_leg="RF"), "leg 'RF_hip' has a slide joint 'RF_KFE'"),
        (Synthetic(foot="none"), "has no foot"),
        (
            Synthetic(
                head='<body name="neck"><joint name="nod" axis="0 1 0"/><geom size="0.03"/></body>'
            ),
            "found 5 leg-like chains",
        ),
    ],
)
def test_malformed_models_are_refused(opt: Synthetic, message: str, tmp_path: Path) -> None:
    with pytest.raises(RobotModelError) as err:
        load_synthetic(opt, tmp_path)
    assert message in str(err.value)


def test_legs_that_cannot_be_told_apart_are_refused(tmp_path: Path) -> None:
    # Names say nothing and the body faces sideways at spawn: all hips look "front".
    opt = Synthetic(prefix={"LF": "a", "RF": "b", "LH": "c", "RH": "d"}, foot="geom")
    xml = synthetic_xml(opt).replace('pos="0.2', 'pos="0.3').replace('pos="-0.2', 'pos="0.1')
    path = tmp_path / "same_side.xml"
    path.write_text(xml)
    with pytest.raises(RobotModelError, match="cannot tell the legs apart"):
        load_robot(path)


def test_bad_input_is_refused(tmp_path: Path) -> None:
    with pytest.raises(RobotModelError, match="does not exist"):
        load_robot(tmp_path / "missing.xml")
    with pytest.raises(
        RobotModelError, match=r"unknown robot 'anymel'; known: anymal_c, littledog"
    ):
        load_robot("anymel")
    not_xml = tmp_path / "broken.xml"
    not_xml.write_text("<mujoco><worldbody><body></mujoco>")
    with pytest.raises(RobotModelError, match="MuJoCo cannot load"):
        load_robot(not_xml)
    arm = tmp_path / "arm.xml"
    arm.write_text(
        '<mujoco><worldbody><body name="link"><joint axis="0 0 1"/>'
        '<geom size="0.1"/></body></worldbody></mujoco>'
    )
    with pytest.raises(RobotModelError, match="found 1 leg-like chains below the base .world."):
        load_robot(arm)


@pytest.mark.parametrize(
    ("name", "label"),
    [
        ("LF_HAA", "LF"),
        ("FL_hip", "LF"),
        ("RL_calf_joint", "LH"),
        ("RR_thigh", "RH"),
        ("rh_shank", "RH"),
        ("front_left_hip_roll", "LF"),
        ("back_right_knee", "RH"),
        ("rearLeftLeg", "LH"),
        ("FrontRight", "RF"),
        ("hind_left_foot", "LH"),
        ("leg_a", None),
        ("left_arm", None),
        ("LF_to_RF_link", None),
    ],
)
def test_leg_label_reads_common_naming_schemes(name: str, label: str | None) -> None:
    assert leg_label(name) == label
