"""The :class:`Robot`: a quadruped loaded from MJCF, with its kinematics.

Conventions, whatever the MJCF does:

* legs in the canonical order LF, RF, LH, RH (:attr:`Robot.legs`);
* the base frame x forward, y left, z up (the MJCF base body's frame turned by
  :attr:`Robot.base_frame_rotation`); base poses are this frame's pose in the
  world, quaternions (w, x, y, z);
* joint vectors q (12,) always in :attr:`Robot.joint_names` order, the MJCF's
  own joint order; :meth:`Robot.to_canonical` / :meth:`Robot.from_canonical`
  convert to and from the leg-major (LF, RF, LH, RH) × (HAA, HFE, KFE) order.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, NamedTuple

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk import _core
from roughwalk.errors import InvalidArgumentError, RobotModelError
from roughwalk.robots import reference_fk
from roughwalk.robots._rotations import matrix_to_quat, quat_multiply, quat_to_matrix
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.robots.mjcf_loader import (
    JOINT_ROLES,
    CollisionGeom,
    LegDescription,
    QuadrupedDescription,
    describe_quadruped,
)
from roughwalk.robots.registry import list_robots, robot_info

__all__ = ["Robot", "NominalStance", "load_robot"]


class NominalStance(NamedTuple):
    """Feet (4, 3) in the base frame [m] at the nominal pose, and the base height [m].

    ``base_height`` is the height of the base origin over flat ground with the
    feet at their mean depth touching it (foot radius included).
    """

    feet: NDArray[np.float64]
    base_height: float


def _vector(value: ArrayLike, shape: tuple[int, ...], what: str) -> NDArray[np.float64]:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidArgumentError(
            f"{what} must be numbers of shape {shape}, got {value!r}"
        ) from None
    if a.shape != shape:
        raise InvalidArgumentError(f"{what} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidArgumentError(f"{what} must be finite, got {a.tolist()}")
    return a


def _unit_quat(value: ArrayLike) -> NDArray[np.float64]:
    quat = _vector(value, (4,), "base_quat")
    norm = float(np.linalg.norm(quat))
    if norm < 1e-9:
        raise InvalidArgumentError(
            f"base_quat must be a nonzero quaternion (w, x, y, z), got {quat.tolist()}"
        )
    return quat / norm


def _json_number(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


class Robot:
    """A quadruped with three hinge joints per leg, read from an MJCF file.

    Build one with :func:`load_robot`. The kinematic description is extracted
    from the model by :func:`~roughwalk.robots.mjcf_loader.describe_quadruped`;
    forward and inverse kinematics run in the Rust core.
    """

    def __init__(self, name: str, mjcf_path: Path, model: mujoco.MjModel) -> None:
        self._name = name
        self._path = mjcf_path
        self._model = model
        self._d: QuadrupedDescription = describe_quadruped(model)
        self._core_quadruped: Any = None
        self._core_error: RobotModelError | None = None
        free = [
            j
            for j in range(model.njnt)
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
            and mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.jnt_bodyid[j])
            == self._d.base_body
        ]
        self._free_qposadr = int(model.jnt_qposadr[free[0]]) if free else None
        self._joint_qposadr = np.array(
            [model.jnt_qposadr[model.joint(n).id] for n in self._d.joint_names]
        )
        self._base_quat_cb = matrix_to_quat(self._d.base_frame_rotation)

    @classmethod
    def from_mjcf(cls, path: str | Path, name: str | None = None) -> Robot:
        """Load a robot from an MJCF (or URDF) file; ``name`` defaults to the model's name."""
        p = Path(path).expanduser()
        if not p.is_file():
            raise RobotModelError(f"MJCF file '{p}' does not exist")
        try:
            model = mujoco.MjModel.from_xml_path(str(p))
        except ValueError as e:
            raise RobotModelError(f"MuJoCo cannot load '{p}': {e}") from None
        try:
            robot = cls(name or "", p.resolve(), model)
        except RobotModelError as e:
            raise RobotModelError(f"{p}: {e}") from None
        if not name:
            robot._name = robot._d.model_name or p.stem
        return robot

    # ---- identity and structure -------------------------------------------------

    @property
    def name(self) -> str:
        """Registry name, or the MJCF model's name for a robot loaded by path."""
        return self._name

    @property
    def mjcf_path(self) -> Path:
        """The MJCF file this robot was loaded from (shipped ones live in the package)."""
        return self._path

    @property
    def description(self) -> QuadrupedDescription:
        """Everything read from the model (:class:`QuadrupedDescription`)."""
        return self._d

    @property
    def legs(self) -> tuple[str, ...]:
        """Leg names in the canonical order: ("LF", "RF", "LH", "RH")."""
        return LEG_NAMES

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The 12 leg joints in the MJCF's order: the order of every q."""
        return self._d.joint_names

    @property
    def leg_joint_names(self) -> tuple[tuple[str, ...], ...]:
        """Per canonical leg, its (HAA, HFE, KFE) joint names."""
        return self._d.leg_joints

    @property
    def base_body(self) -> str:
        """Name of the MJCF body that is the robot's base (trunk)."""
        return self._d.base_body

    @property
    def leg_descriptions(self) -> tuple[LegDescription, ...]:
        """Per canonical leg, its chain (:class:`LegDescription`)."""
        return self._d.legs

    @property
    def base_frame_rotation(self) -> NDArray[np.float64]:
        """(3, 3) R_cb: v_canonical = R_cb · v_mjcf_body for the MJCF base body's frame."""
        return self._d.base_frame_rotation

    @property
    def canonical_index(self) -> NDArray[np.int64]:
        """(12,) indices with q_canonical = q[canonical_index]."""
        return self._d.canonical_index

    def to_canonical(self, q: ArrayLike) -> NDArray[np.float64]:
        """Joint angles (..., 12) from :attr:`joint_names` order to canonical leg-major order."""
        return np.asarray(q, dtype=float)[..., self._d.canonical_index]

    def from_canonical(self, q: ArrayLike) -> NDArray[np.float64]:
        """Joint angles (..., 12) from canonical leg-major order to :attr:`joint_names` order."""
        qc = np.asarray(q, dtype=float)
        out = np.empty_like(qc)
        out[..., self._d.canonical_index] = qc
        return out

    # ---- physical data ------------------------------------------------------------

    @property
    def mass(self) -> float:
        """Total mass [kg]."""
        return self._d.total_mass

    @property
    def base_mass(self) -> float:
        """Mass of the trunk and everything rigidly fixed to it [kg]."""
        return self._d.base_mass

    @property
    def base_com(self) -> NDArray[np.float64]:
        """(3,) trunk centre of mass in the base frame [m]."""
        return self._d.base_com

    @property
    def base_inertia(self) -> NDArray[np.float64]:
        """(3, 3) trunk inertia about its centre of mass, base frame axes [kg·m²]."""
        return self._d.base_inertia

    @property
    def foot_radius(self) -> float:
        """Foot sphere radius [m] (the largest of the four; 0 for site feet)."""
        return max(leg.foot_radius for leg in self._d.legs)

    @property
    def joint_lower(self) -> NDArray[np.float64]:
        """(12,) lower joint limits [rad], joint_names order."""
        return self._d.joint_lower

    @property
    def joint_upper(self) -> NDArray[np.float64]:
        """(12,) upper joint limits [rad], joint_names order."""
        return self._d.joint_upper

    @property
    def joint_velocity_limit(self) -> NDArray[np.float64]:
        """(12,) joint speed limits [rad/s] (+inf when the model states none)."""
        return self._d.velocity_limit

    @property
    def joint_torque_limit(self) -> NDArray[np.float64]:
        """(12,) joint torque limits [N·m] from the actuators (+inf when unlimited)."""
        return self._d.torque_limit

    @property
    def hip_positions(self) -> NDArray[np.float64]:
        """(4, 3) HAA joint anchors in the base frame [m]."""
        return np.array(
            [
                leg.body_pos[0] + quat_to_matrix(leg.body_quat[0]) @ leg.anchor[0]
                for leg in self._d.legs
            ]
        )

    @property
    def leg_lengths(self) -> NDArray[np.float64]:
        """(4, 2) thigh and shank lengths [m]: HFE→KFE and KFE→foot, across their axes."""
        out = []
        for leg in self._d.legs:
            knee = leg.body_pos[2] + quat_to_matrix(leg.body_quat[2]) @ leg.anchor[2]
            thigh = knee - leg.anchor[1]
            shank = leg.foot - leg.anchor[2]
            thigh = thigh - (thigh @ leg.axis[1]) * leg.axis[1]
            shank = shank - (shank @ leg.axis[2]) * leg.axis[2]
            out.append([np.linalg.norm(thigh), np.linalg.norm(shank)])
        return np.array(out)

    @property
    def collision_geoms(self) -> tuple[CollisionGeom, ...]:
        """The model's colliding geoms, each placed in its link's frame."""
        return self._d.collision_geoms

    @property
    def nominal_q(self) -> NDArray[np.float64]:
        """(12,) nominal joint angles [rad], joint_names order (``description.nominal_source``)."""
        return self._d.nominal_q

    @property
    def nominal_stance(self) -> NominalStance:
        """Feet in the base frame at :attr:`nominal_q` and the nominal base height [m]."""
        feet = reference_fk.foot_positions(self._d.legs, self.to_canonical(self._d.nominal_q))
        return NominalStance(feet, float(-feet[:, 2].mean() + self.foot_radius))

    # ---- kinematics ---------------------------------------------------------------

    def _quadruped(self) -> Any:
        """Return the Rust ``Quadruped`` of this robot, or None when it cannot be built.

        It cannot be built when the compiled core predates the kinematics
        binding, or when a leg's joint axes do not have the abduction–flexion–knee
        structure the analytic IK needs; forward kinematics then runs in numpy
        and :meth:`inverse_kinematics` reports why it is unavailable.
        """
        if self._core_quadruped is None and self._core_error is None:
            leg_chain = getattr(_core, "LegChain", None)
            quadruped = getattr(_core, "Quadruped", None)
            if leg_chain is None or quadruped is None:
                self._core_error = RobotModelError(
                    "inverse kinematics needs the Rust core's Quadruped, which this build of "
                    "roughwalk._core lacks; rebuild it with `make install`"
                )
                return None
            try:
                chains = [
                    leg_chain(
                        leg.body_pos,
                        leg.body_quat,
                        leg.anchor,
                        leg.axis,
                        leg.lower,
                        leg.upper,
                        leg.velocity_limit,
                        leg.foot,
                        leg.foot_radius,
                        leg.knee_sign,
                        name=f"{self.name} {name}",
                    )
                    for name, leg in zip(LEG_NAMES, self._d.legs, strict=True)
                ]
                self._core_quadruped = quadruped(chains)
            except RobotModelError as e:
                self._core_error = e
        return self._core_quadruped

    def foot_positions(
        self,
        q: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
    ) -> NDArray[np.float64]:
        """World foot centres (4, 3) [m], canonical leg order, for joint angles q (12,) [rad].

        ``base_pos`` [m] and ``base_quat`` (w, x, y, z) place the canonical base frame.
        """
        qc = self.to_canonical(_vector(q, (12,), "q"))
        pos = _vector(base_pos, (3,), "base_pos")
        quat = _unit_quat(base_quat)
        core = self._quadruped()
        if core is None:
            return reference_fk.foot_positions(self._d.legs, qc, pos, quat)
        return np.asarray(core.foot_positions(qc, pos, quat))

    def inverse_kinematics(
        self,
        feet: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Joint angles (12,) [rad] placing the foot centres at ``feet`` (4, 3) [m, world].

        Returns ``(q, reachable)``: q in joint_names order and, per canonical leg,
        whether its target was reached within the joint limits; an unreachable
        leg gets the in-limit angles whose foot is closest to its target
        (Zucker 2011, §3.1).
        """
        targets = _vector(feet, (4, 3), "feet")
        pos = _vector(base_pos, (3,), "base_pos")
        quat = _unit_quat(base_quat)
        core = self._quadruped()
        if core is None:
            raise RobotModelError(f"robot '{self.name}': {self._core_error}")
        qc, reachable = core.inverse_kinematics(targets, pos, quat)
        return self.from_canonical(np.asarray(qc)), np.asarray(reachable, dtype=bool)

    def foot_jacobians(
        self, q: ArrayLike, base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0)
    ) -> NDArray[np.float64]:
        """Per canonical leg, ∂(world foot centre)/∂(its HAA, HFE, KFE) (4, 3, 3) [m/rad].

        ``q`` (12,) [rad] in joint_names order; ``base_quat`` (w, x, y, z)
        turns the base frame into the world. A force f [N] on leg i's foot
        asks its joints for −J[i]ᵀ f [N·m] to hold it (leg weight aside).
        """
        qc = self.to_canonical(_vector(q, (12,), "q")).reshape(4, 3)
        rot = quat_to_matrix(_unit_quat(base_quat))
        return np.array(
            [
                rot @ reference_fk.leg_foot_jacobian(leg, a)
                for leg, a in zip(self._d.legs, qc, strict=True)
            ]
        )

    def center_of_mass(
        self,
        q: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
    ) -> NDArray[np.float64]:
        """Whole-robot centre of mass (3,) in the world [m] for joint angles q (12,) [rad]."""
        qc = self.to_canonical(_vector(q, (12,), "q")).reshape(4, 3)
        pos = _vector(base_pos, (3,), "base_pos")
        rot = quat_to_matrix(_unit_quat(base_quat))
        weighted = self._d.base_mass * self._d.base_com
        for i, leg in enumerate(self._d.legs):
            positions, rotations = reference_fk.leg_link_frames(leg, qc[i])
            for k in range(3):
                com = positions[k] + rotations[k] @ self._d.link_com[i, k]
                weighted = weighted + self._d.link_mass[i, k] * com
        return pos + rot @ (weighted / self.mass)

    # ---- MuJoCo -------------------------------------------------------------------

    def mj_model(self) -> mujoco.MjModel:
        """Compile a fresh ``mujoco.MjModel`` from :attr:`mjcf_path`."""
        return mujoco.MjModel.from_xml_path(str(self._path))

    def qpos(
        self,
        q: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
    ) -> NDArray[np.float64]:
        """MuJoCo ``qpos`` (nq,) of :meth:`mj_model` for joint angles q and a canonical base pose.

        Other degrees of freedom keep ``qpos0``. A fixed-base model has no base
        pose in its qpos; ``base_pos`` and ``base_quat`` are then not used.
        """
        angles = _vector(q, (12,), "q")
        pos = _vector(base_pos, (3,), "base_pos")
        quat = _unit_quat(base_quat)
        out = np.array(self._model.qpos0, dtype=float)
        out[self._joint_qposadr] = angles
        if self._free_qposadr is not None:
            a = self._free_qposadr
            out[a : a + 3] = pos
            out[a + 3 : a + 7] = quat_multiply(quat, self._base_quat_cb)
        return out

    def base_pose_from_qpos(
        self, qpos: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Read the canonical base pose (pos [m], quat (w, x, y, z)) from a free-base ``qpos``."""
        if self._free_qposadr is None:
            raise RobotModelError(
                f"robot '{self.name}' has a fixed base: its qpos holds no base pose"
            )
        values = _vector(qpos, (self._model.nq,), "qpos")
        a = self._free_qposadr
        conj = self._base_quat_cb * np.array([1.0, -1.0, -1.0, -1.0])
        quat = quat_multiply(values[a + 3 : a + 7], conj)
        return values[a : a + 3].copy(), quat / np.linalg.norm(quat)

    def joint_angles_from_qpos(self, qpos: ArrayLike) -> NDArray[np.float64]:
        """Joint angles q (12,) [rad], joint_names order, held in a MuJoCo ``qpos``."""
        return _vector(qpos, (self._model.nq,), "qpos")[self._joint_qposadr].copy()

    # ---- reporting ----------------------------------------------------------------

    def info(self) -> dict[str, Any]:
        """Summarise the robot, JSON-ready: mass, legs, leg lengths, limits, nominal stance.

        Infinite limits appear as null.
        """
        d = self._d
        stance = self.nominal_stance
        role = {}
        for leg, joints in zip(LEG_NAMES, d.leg_joints, strict=True):
            for r, joint in zip(JOINT_ROLES, joints, strict=True):
                role[joint] = (leg, r)
        return {
            "name": self.name,
            "model_name": d.model_name,
            "mjcf_path": str(self._path),
            "base_body": d.base_body,
            "fixed_base": d.fixed_base,
            "mass": self.mass,
            "base_mass": d.base_mass,
            "foot_radius": self.foot_radius,
            "legs": list(LEG_NAMES),
            "naming_rule": d.naming_rule,
            "base_frame_rotation": d.base_frame_rotation.tolist(),
            "feet": dict(zip(LEG_NAMES, d.feet, strict=True)),
            "hip_positions": dict(zip(LEG_NAMES, self.hip_positions.tolist(), strict=True)),
            "leg_lengths": {
                leg: {"thigh": float(t), "shank": float(s)}
                for leg, (t, s) in zip(LEG_NAMES, self.leg_lengths, strict=True)
            },
            "joints": [
                {
                    "name": n,
                    "leg": role[n][0],
                    "role": role[n][1],
                    "lower": _json_number(d.joint_lower[i]),
                    "upper": _json_number(d.joint_upper[i]),
                    "velocity_limit": _json_number(d.velocity_limit[i]),
                    "torque_limit": _json_number(d.torque_limit[i]),
                }
                for i, n in enumerate(d.joint_names)
            ],
            "nominal_q": dict(zip(d.joint_names, d.nominal_q.tolist(), strict=True)),
            "nominal_source": d.nominal_source,
            "nominal_stance": {
                "feet": dict(zip(LEG_NAMES, stance.feet.tolist(), strict=True)),
                "base_height": stance.base_height,
            },
        }

    def __repr__(self) -> str:
        return f"Robot({self.name!r}, mass={self.mass:.3f} kg, mjcf_path='{self._path}')"


def load_robot(name_or_path: str | Path) -> Robot:
    """Load a registered robot by name (``"littledog"``, ``"anymal_c"``) or any MJCF file by path.

    Raises :class:`RobotModelError` for an unknown name (listing the known
    ones), a missing file, or a model that is not a quadruped with three hinge
    joints per leg (saying what was found).
    """
    registered = {r.name for r in list_robots()}
    if isinstance(name_or_path, str) and name_or_path.lower() in registered:
        info = robot_info(name_or_path)
        return Robot.from_mjcf(info.mjcf_path, info.name)
    path = Path(name_or_path).expanduser()
    text = str(name_or_path)
    looks_like_path = (
        isinstance(name_or_path, Path)
        or bool(path.suffix)
        or any(sep in text for sep in ("/", "\\"))
    )
    if path.is_file() or looks_like_path:
        return Robot.from_mjcf(path)
    known = ", ".join(sorted(registered))
    raise RobotModelError(f"unknown robot '{text}'; known: {known}")
