"""Read a quadruped's kinematic and inertial description from a compiled MuJoCo model.

MuJoCo itself compiles the file (defaults, classes, ``childclass``, angle units,
``fromto``, ``ref`` all resolved); this module then walks the compiled arrays.
Nothing is typed in per robot. The rules:

* **Base**: the body with the robot's free joint; for a fixed-base model (e.g. a
  URDF import) the one child of the world whose subtree holds joints, or the
  world itself when the compiler fused the base into it.
* **Legs**: below the base, every body that carries a joint and has no
  jointed ancestor below the base starts a leg; a model must have exactly four.
  A leg's jointed bodies must form one chain holding exactly three hinge
  joints: the first from the base is HAA (hip abduction/adduction), then HFE
  (hip flexion/extension), then KFE (knee). Bodies without joints are folded
  into the next jointed body's pose or into the link they hang from; several
  joints in one body become links with an identity pose between them; a joint's
  ``ref`` is folded into its body's pose so that the chain's angle is MuJoCo's
  ``qpos``.
* **Foot**: on the leg's last jointed body or the jointless bodies below it,
  the first found of: a colliding sphere geom, a site whose name contains
  "foot" or "toe", any sphere geom; when several qualify, the one farthest
  from the knee. The foot centre is that point; the radius is the sphere's
  (0 for a site). A leg with none of them is refused rather than guessed.
* **Which leg is which**: :mod:`roughwalk.robots.canonical_frame`.
* **Limits**: joint ranges (±inf when a joint is not limited); torque limits
  from the joint's ``actuatorfrcrange`` and the force range times gear of the
  actuators driving it (the smallest applies; +inf when nothing limits it);
  velocity limits from ``<custom><numeric name="velocity_limit:JOINT">``
  (+inf when absent; MuJoCo has no velocity limit of its own).
* **Nominal pose**: the keyframe named ``home`` (else ``stand``/``standing``,
  else the first keyframe); without keyframes, ``qpos0`` clipped to the limits.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import RobotModelError
from roughwalk.robots._rotations import axis_angle_matrix, matrix_to_quat, quat_to_matrix
from roughwalk.robots.canonical_frame import LEG_NAMES, canonical_frame
from roughwalk.robots.leg_description import LegDescription
from roughwalk.robots.reference_fk import leg_link_frames

__all__ = [
    "LegDescription",
    "CollisionGeom",
    "QuadrupedDescription",
    "describe_quadruped",
    "JOINT_ROLES",
]

JOINT_ROLES = ("HAA", "HFE", "KFE")
"""Joint roles within a leg, from the base outwards."""

_GEOM_TYPES = {
    int(mujoco.mjtGeom.mjGEOM_PLANE): "plane",
    int(mujoco.mjtGeom.mjGEOM_HFIELD): "hfield",
    int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
    int(mujoco.mjtGeom.mjGEOM_BOX): "box",
    int(mujoco.mjtGeom.mjGEOM_MESH): "mesh",
    int(mujoco.mjtGeom.mjGEOM_SDF): "sdf",
}
_JOINT_TYPES = {
    int(mujoco.mjtJoint.mjJNT_FREE): "free",
    int(mujoco.mjtJoint.mjJNT_BALL): "ball",
    int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
    int(mujoco.mjtJoint.mjJNT_HINGE): "hinge",
}
_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_FREE = int(mujoco.mjtJoint.mjJNT_FREE)
_SPHERE = int(mujoco.mjtGeom.mjGEOM_SPHERE)


def _frozen(a: NDArray[np.float64]) -> NDArray[np.float64]:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class CollisionGeom:
    """A colliding geom of the robot, placed on the link that carries it.

    ``pos``/``quat`` are in the link's frame: the canonical base frame for the
    trunk (``leg`` is None), else body ``link`` of leg ``leg`` as in
    :class:`LegDescription`. ``size`` is MuJoCo's ``geom_size`` [m] for the type
    (sphere: radius; capsule/cylinder: radius, half-length along the geom's z;
    box: half-extents; ellipsoid: semi-axes; mesh: unused).
    """

    name: str
    """The geom's name ("" when unnamed)."""
    geom_id: int
    """The geom's index in the compiled model."""
    body: str
    leg: str | None
    link: int | None
    type: str
    size: NDArray[np.float64]
    pos: NDArray[np.float64]
    quat: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class QuadrupedDescription:
    """Everything :func:`describe_quadruped` reads from a model.

    Per-leg arrays are in the canonical leg order LF, RF, LH, RH; per-joint
    arrays (``joint_*``, ``nominal_q``) in the model's joint order
    (``joint_names``). Link k of a leg is body k of its :class:`LegDescription`.
    """

    model_name: str
    base_body: str
    fixed_base: bool
    base_frame_rotation: NDArray[np.float64]
    """(3, 3) R_cb: v_canonical = R_cb · v_body for the MJCF base body's frame."""
    naming_rule: str
    """"names" or "geometry": which rule told the legs apart."""
    legs: tuple[LegDescription, ...]
    leg_joints: tuple[tuple[str, ...], ...]
    leg_bodies: tuple[tuple[str, ...], ...]
    feet: tuple[str, ...]
    """Where each foot centre came from, e.g. "geom 'LF_foot'" or "site 'FL_foot'"."""
    joint_names: tuple[str, ...]
    canonical_index: NDArray[np.int64]
    """(12,) q_canonical = q[canonical_index]."""
    joint_lower: NDArray[np.float64]
    joint_upper: NDArray[np.float64]
    velocity_limit: NDArray[np.float64]
    torque_limit: NDArray[np.float64]
    link_mass: NDArray[np.float64]
    """(4, 3) mass of each leg link, jointless bodies below it included [kg]."""
    link_com: NDArray[np.float64]
    """(4, 3, 3) centre of mass of each link in its body frame [m]."""
    link_inertia: NDArray[np.float64]
    """(4, 3, 3, 3) inertia tensor of each link about its CoM, body frame [kg·m²]."""
    base_mass: float
    base_com: NDArray[np.float64]
    """(3,) trunk CoM in the canonical base frame [m]."""
    base_inertia: NDArray[np.float64]
    """(3, 3) trunk inertia about its CoM in the canonical base frame [kg·m²]."""
    total_mass: float
    collision_geoms: tuple[CollisionGeom, ...]
    nominal_q: NDArray[np.float64]
    nominal_source: str


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, index: int) -> str:
    name = mujoco.mj_id2name(model, obj, index)
    return name if name else f"#{index}"


def _body(model: mujoco.MjModel, b: int) -> str:
    return _name(model, mujoco.mjtObj.mjOBJ_BODY, b)


def _joint(model: mujoco.MjModel, j: int) -> str:
    return _name(model, mujoco.mjtObj.mjOBJ_JOINT, j)


def _model_name(model: mujoco.MjModel) -> str:
    return bytes(model.names).split(b"\0", 1)[0].decode()


def _is_below(model: mujoco.MjModel, body: int, ancestor: int) -> bool:
    """Tell whether ``body`` is a strict descendant of ``ancestor``."""
    while body != 0:
        body = int(model.body_parentid[body])
        if body == ancestor:
            return True
    return False


def _subtree(model: mujoco.MjModel, root: int) -> list[int]:
    """``root`` and its descendants; MuJoCo numbers bodies depth-first, parents first."""
    return [b for b in range(model.nbody) if b == root or _is_below(model, b, root)]


def _relative_pose(
    model: mujoco.MjModel, ancestor: int, body: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Pose of ``body`` in ``ancestor``'s frame from the bodies' fixed offsets (joints at rest)."""
    path = []
    while body != ancestor:
        path.append(body)
        body = int(model.body_parentid[body])
    pos, rot = np.zeros(3), np.eye(3)
    for b in reversed(path):
        pos = pos + rot @ model.body_pos[b]
        rot = rot @ quat_to_matrix(model.body_quat[b])
    return pos, rot


def _find_base(model: mujoco.MjModel) -> int:
    def has_joints_below(b: int) -> bool:
        return any(
            model.jnt_type[j] != _FREE and _is_below(model, int(model.jnt_bodyid[j]), b)
            for j in range(model.njnt)
        )

    free_bodies = [
        int(model.jnt_bodyid[j]) for j in range(model.njnt) if model.jnt_type[j] == _FREE
    ]
    if free_bodies:
        candidates = [b for b in free_bodies if has_joints_below(b)]
        what = "free-joint bodies with jointed bodies below them"
    else:
        candidates = [
            b for b in range(1, model.nbody) if model.body_parentid[b] == 0 and has_joints_below(b)
        ]
        what = "children of the world with jointed bodies below them (no free joint)"
        if len(candidates) != 1 and model.njnt > 0:
            # A fixed base fused into the world (e.g. a URDF import): the world is the base.
            return 0
    if len(candidates) != 1:
        names = ", ".join(_body(model, b) for b in candidates) or "none"
        raise RobotModelError(
            f"cannot find the robot's base: found {len(candidates)} {what} ({names})"
        )
    return candidates[0]


def _leg_chains(model: mujoco.MjModel, base: int) -> list[list[int]]:
    """Return the jointed bodies of each leg, base outwards, after checking the structure."""
    jointed = [b for b in _subtree(model, base) if b != base and model.body_jntnum[b] > 0]
    first = [b for b in jointed if not any(a != b and _is_below(model, b, a) for a in jointed)]
    chains = [[b for b in jointed if b == r or _is_below(model, b, r)] for r in first]

    def hinge_count(chain: list[int]) -> int:
        return sum(
            int(model.jnt_type[j] == _HINGE)
            for b in chain
            for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b])
        )

    if len(chains) != 4:
        found = ", ".join(f"'{_body(model, c[0])}' ({hinge_count(c)} hinges)" for c in chains)
        raise RobotModelError(
            f"not a quadruped: found {len(chains)} leg-like chains below the base "
            f"'{_body(model, base)}'{': ' + found if found else ''}; expected 4 legs of 3 hinges"
        )
    for chain in chains:
        leg = _body(model, chain[0])
        for a, b in zip(chain, chain[1:], strict=False):
            if not _is_below(model, b, a):
                raise RobotModelError(
                    f"leg '{leg}' branches: bodies '{_body(model, a)}' and '{_body(model, b)}' "
                    "both carry joints but neither is below the other; a leg must be one chain"
                )
        joints = [
            j
            for b in chain
            for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b])
        ]
        for j in joints:
            if model.jnt_type[j] != _HINGE:
                raise RobotModelError(
                    f"leg '{leg}' has a {_JOINT_TYPES[int(model.jnt_type[j])]} joint "
                    f"'{_joint(model, j)}'; legs must have exactly 3 hinge joints (HAA, HFE, KFE)"
                )
        if len(joints) != 3:
            names = ", ".join(_joint(model, j) for j in joints)
            raise RobotModelError(
                f"leg '{leg}' has {len(joints)} hinge joints ({names}); expected 3 (HAA, HFE, KFE)"
            )
    return chains


def _foot(
    model: mujoco.MjModel, last_body: int, knee_anchor: NDArray[np.float64], leg: str
) -> tuple[NDArray[np.float64], float, str]:
    """Foot centre in the last jointed body's frame, its radius, and where it came from."""
    bodies = set(_subtree(model, last_body))
    tiers: list[list[tuple[NDArray[np.float64], float, str]]] = [[], [], []]
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if b not in bodies or model.geom_type[g] != _SPHERE:
            continue
        pos, rot = _relative_pose(model, last_body, b)
        point = pos + rot @ model.geom_pos[g]
        collides = model.geom_contype[g] != 0 or model.geom_conaffinity[g] != 0
        gname = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g)
        label = f"geom '{gname}'" if gname else f"geom #{g}"
        tiers[0 if collides else 2].append((point, float(model.geom_size[g][0]), label))
    for s in range(model.nsite):
        b = int(model.site_bodyid[s])
        name = _name(model, mujoco.mjtObj.mjOBJ_SITE, s)
        if b in bodies and ("foot" in name.lower() or "toe" in name.lower()):
            pos, rot = _relative_pose(model, last_body, b)
            tiers[1].append((pos + rot @ model.site_pos[s], 0.0, f"site '{name}'"))
    for tier in tiers:
        if tier:
            return max(tier, key=lambda c: float(np.linalg.norm(c[0] - knee_anchor)))
    raise RobotModelError(
        f"leg '{leg}' has no foot: no sphere geom and no site named *foot* or *toe* on body "
        f"'{_body(model, last_body)}' or below it"
    )


def _composite_inertia(
    model: mujoco.MjModel, frame_body: int, bodies: list[int]
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Return mass, CoM and inertia about the CoM of rigid ``bodies`` in ``frame_body``'s frame."""
    masses, coms, inertias = [], [], []
    for b in bodies:
        pos, rot = _relative_pose(model, frame_body, b)
        principal = rot @ quat_to_matrix(model.body_iquat[b])
        masses.append(float(model.body_mass[b]))
        coms.append(pos + rot @ model.body_ipos[b])
        inertias.append(principal @ np.diag(model.body_inertia[b]) @ principal.T)
    mass = float(sum(masses))
    if mass <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m * c for m, c in zip(masses, coms, strict=True)) / mass
    inertia = np.zeros((3, 3))
    for m, c, i in zip(masses, coms, inertias, strict=True):
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def _torque_limits(model: mujoco.MjModel, joints: list[int]) -> NDArray[np.float64]:
    limits = np.full(len(joints), np.inf)
    for i, j in enumerate(joints):
        if model.jnt_actfrclimited[j]:
            limits[i] = np.max(np.abs(model.jnt_actfrcrange[j]))
    for a in range(model.nu):
        if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        j = int(model.actuator_trnid[a][0])
        if j not in joints:
            continue
        gear = abs(float(model.actuator_gear[a][0]))
        if model.actuator_forcelimited[a]:
            force = float(np.max(np.abs(model.actuator_forcerange[a])))
        elif (
            model.actuator_ctrllimited[a]
            and model.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED
            and model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_NONE
        ):
            # A plain motor: force = gain · ctrl, bounded by the control range.
            force = abs(float(model.actuator_gainprm[a][0])) * float(
                np.max(np.abs(model.actuator_ctrlrange[a]))
            )
        else:
            continue
        i = joints.index(j)
        limits[i] = min(limits[i], gear * force)
    return limits


def _nominal_q(
    model: mujoco.MjModel, joints: list[int], lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> tuple[NDArray[np.float64], str]:
    adr = model.jnt_qposadr[joints]
    if model.nkey > 0:
        names = [_name(model, mujoco.mjtObj.mjOBJ_KEY, k) for k in range(model.nkey)]
        key = next((names.index(n) for n in ("home", "stand", "standing") if n in names), 0)
        return np.array(model.key_qpos[key][adr], dtype=float), f"keyframe '{names[key]}'"
    return np.clip(model.qpos0[adr], lower, upper), "qpos0 clipped to the joint limits"


def _knee_sign(leg: LegDescription, q: NDArray[np.float64]) -> float:
    """Sign of the knee angle ψ at q (see :attr:`LegDescription.knee_sign`); +1 when straight."""
    positions, rotations = leg_link_frames(leg, q)
    hfe = positions[1] + rotations[1] @ leg.anchor[1]
    axis = rotations[1] @ leg.axis[1]
    kfe = positions[2] + rotations[2] @ leg.anchor[2]
    foot = positions[2] + rotations[2] @ leg.foot
    psi = float(np.cross(kfe - hfe, foot - kfe) @ axis)
    return -1.0 if psi < 0 else 1.0


def describe_quadruped(model: mujoco.MjModel) -> QuadrupedDescription:
    """Read the quadruped in a compiled MuJoCo model (rules in the module docstring).

    Raises :class:`RobotModelError` naming what was found when the model is not a
    quadruped with three hinge joints per leg and a foot on each leg.
    """
    base = _find_base(model)
    extra = [
        _joint(model, j)
        for j in range(model.body_jntadr[base], model.body_jntadr[base] + model.body_jntnum[base])
        if model.jnt_type[j] != _FREE
    ]
    if extra:
        raise RobotModelError(
            f"the base '{_body(model, base)}' carries joints other than a free joint: {extra}"
        )
    chains = _leg_chains(model, base)

    raw = []  # per leg, in the model's order: joints, chain pieces, hip, names
    for chain in chains:
        joints = [
            j
            for b in chain
            for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b])
        ]
        pieces = []
        previous = base
        for j in joints:
            b = int(model.jnt_bodyid[j])
            if b == previous:
                pos, rot = np.zeros(3), np.eye(3)
            else:
                pos, rot = _relative_pose(model, previous, b)
            axis = model.jnt_axis[j] / np.linalg.norm(model.jnt_axis[j])
            anchor = np.array(model.jnt_pos[j], dtype=float)
            ref = float(model.qpos0[model.jnt_qposadr[j]])
            if ref != 0.0:
                # MuJoCo turns the body by (qpos − ref); fold −ref into the body pose.
                turn = axis_angle_matrix(axis, -ref)
                pos = pos + rot @ (anchor - turn @ anchor)
                rot = rot @ turn
            pieces.append((pos, rot, anchor, axis))
            previous = b
        hip = pieces[0][0] + pieces[0][1] @ pieces[0][2]
        names = [_body(model, b) for b in chain] + [_joint(model, j) for j in joints]
        raw.append((joints, pieces, hip, names, chain))

    _, world_rot = _relative_pose(model, 0, base)
    r_cb, labels, rule = canonical_frame(
        np.array([r[2] for r in raw]), [r[3] for r in raw], world_rot
    )
    order = [labels.index(name) for name in LEG_NAMES]

    leg_joint_ids = [j for r in raw for j in r[0]]
    joint_ids = sorted(leg_joint_ids)
    lower = np.array(
        [model.jnt_range[j][0] if model.jnt_limited[j] else -np.inf for j in joint_ids]
    )
    upper = np.array([model.jnt_range[j][1] if model.jnt_limited[j] else np.inf for j in joint_ids])
    velocity = np.full(len(joint_ids), np.inf)
    for i, j in enumerate(joint_ids):
        numeric = mujoco.mj_name2id(
            model, mujoco.mjtObj.mjOBJ_NUMERIC, f"velocity_limit:{_joint(model, j)}"
        )
        if numeric >= 0:
            velocity[i] = float(model.numeric_data[model.numeric_adr[numeric]])
    nominal_q, nominal_source = _nominal_q(model, joint_ids, lower, upper)

    # Which link every body of the robot rides on: the trunk (None) or (leg, k).
    link_of: dict[int, tuple[int, int] | None] = {}
    for b in _subtree(model, base):
        carrier = b
        while carrier != base and model.body_jntnum[carrier] == 0:
            carrier = int(model.body_parentid[carrier])
        if carrier == base:
            link_of[b] = None
        else:
            leg_i = next(i for i, r in enumerate(raw) if carrier in r[4])
            last_joint = model.body_jntadr[carrier] + model.body_jntnum[carrier] - 1
            link_of[b] = (leg_i, raw[leg_i][0].index(last_joint))

    legs, link_mass, link_com, link_inertia, feet = [], [], [], [], []
    for i in order:
        joints, pieces, _, _, _ = raw[i]
        body_pos = np.array([p[0] for p in pieces])
        body_rot = [p[1] for p in pieces]
        body_pos[0] = r_cb @ body_pos[0]
        body_rot[0] = r_cb @ body_rot[0]
        idx = [joint_ids.index(j) for j in joints]
        last = int(model.jnt_bodyid[joints[2]])
        foot, radius, source = _foot(model, last, pieces[2][2], labels[i])
        leg = LegDescription(
            body_pos=_frozen(body_pos),
            body_quat=_frozen(np.array([matrix_to_quat(r) for r in body_rot])),
            anchor=_frozen(np.array([p[2] for p in pieces])),
            axis=_frozen(np.array([p[3] for p in pieces])),
            lower=_frozen(lower[idx]),
            upper=_frozen(upper[idx]),
            velocity_limit=_frozen(velocity[idx]),
            foot=_frozen(foot),
            foot_radius=radius,
            knee_sign=1.0,
        )
        legs.append(replace(leg, knee_sign=_knee_sign(leg, nominal_q[idx])))
        feet.append(source)
        masses, coms, inertias = [], [], []
        for n, j in enumerate(joints):
            b = int(model.jnt_bodyid[j])
            riders = [c for c, link in link_of.items() if link == (i, n)]
            mass, com, inertia = _composite_inertia(model, b, riders)
            masses.append(mass)
            coms.append(com)
            inertias.append(inertia)
        link_mass.append(masses)
        link_com.append(coms)
        link_inertia.append(inertias)

    trunk = [b for b, link in link_of.items() if link is None]
    base_mass, base_com, base_inertia = _composite_inertia(model, base, trunk)

    leg_index = {orig: new for new, orig in enumerate(order)}
    geoms = []
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if b not in link_of or (model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0):
            continue
        link = link_of[b]
        leg_name: str | None = None
        link_index: int | None = None
        if link is None:
            frame_body = base
        else:
            frame_body = int(model.jnt_bodyid[raw[link[0]][0][link[1]]])
            leg_name, link_index = LEG_NAMES[leg_index[link[0]]], link[1]
        pos, rot = _relative_pose(model, frame_body, b)
        gpos = pos + rot @ model.geom_pos[g]
        grot = rot @ quat_to_matrix(model.geom_quat[g])
        if link is None:
            gpos, grot = r_cb @ gpos, r_cb @ grot
        geoms.append(
            CollisionGeom(
                name=mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "",
                geom_id=g,
                body=_body(model, b),
                leg=leg_name,
                link=link_index,
                type=_GEOM_TYPES.get(int(model.geom_type[g]), str(int(model.geom_type[g]))),
                size=_frozen(model.geom_size[g]),
                pos=_frozen(gpos),
                quat=_frozen(matrix_to_quat(grot)),
            )
        )

    canonical_index = np.array([joint_ids.index(j) for i in order for j in raw[i][0]])
    canonical_index.flags.writeable = False
    return QuadrupedDescription(
        model_name=_model_name(model),
        base_body=_body(model, base),
        fixed_base=not any(
            model.jnt_type[j] == _FREE and model.jnt_bodyid[j] == base for j in range(model.njnt)
        ),
        base_frame_rotation=_frozen(r_cb),
        naming_rule=rule,
        legs=tuple(legs),
        leg_joints=tuple(tuple(_joint(model, j) for j in raw[i][0]) for i in order),
        leg_bodies=tuple(tuple(_body(model, b) for b in raw[i][4]) for i in order),
        feet=tuple(feet),
        joint_names=tuple(_joint(model, j) for j in joint_ids),
        canonical_index=canonical_index,
        joint_lower=_frozen(lower),
        joint_upper=_frozen(upper),
        velocity_limit=_frozen(velocity),
        torque_limit=_frozen(_torque_limits(model, joint_ids)),
        link_mass=_frozen(np.array(link_mass)),
        link_com=_frozen(np.array(link_com)),
        link_inertia=_frozen(np.array(link_inertia)),
        base_mass=base_mass,
        base_com=_frozen(r_cb @ base_com),
        base_inertia=_frozen(r_cb @ base_inertia @ r_cb.T),
        total_mass=float(np.sum(model.body_mass[_subtree(model, base)])),
        collision_geoms=tuple(geoms),
        nominal_q=_frozen(nominal_q),
        nominal_source=nominal_source,
    )
