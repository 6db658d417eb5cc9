"""The :class:`World`: a robot's MJCF and a terrain's height field in one MuJoCo model.

The robot's own file is loaded with ``mujoco.MjSpec`` and the terrain is
added to its world body, so every actuator, force range, default class and
keyframe of the robot stays as written: the torque limits are MuJoCo's
``forcerange`` on the position servos, always in force.

Terrain geometry. A 2.5-D terrain becomes an ``<hfield>``
(:meth:`~roughwalk.terrain.Terrain.to_mujoco_hfield`). MuJoCo collides
meshes as their convex hulls, so a terrain loaded from a general mesh cannot
collide as that mesh: its upper envelope (the terrain's height field, which
is also what the planner sees) is the collision surface, and the mesh itself
is added as a visual-only geom so the pictures show it.

Contacts. The feet get :class:`~roughwalk.sim.config.ContactConfig`'s
friction, ``solref`` and ``solimp`` (they carry ``priority`` over the
terrain, so their parameters decide foot contacts); every other robot geom
keeps its own and meets the terrain with MuJoCo's defaults.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import RobotModelError, TerrainError
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.sim.config import WorldConfig

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.terrain import Terrain

__all__ = ["World", "GeomRoles", "TERRAIN_GEOM"]

TERRAIN_GEOM = "terrain"
_INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
}

_CONES = {
    "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL,
    "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC,
}


@dataclass(frozen=True)
class GeomRoles:
    """What each geom of the compiled model is, for reading contacts.

    ``leg`` (ngeom,) is the canonical leg (0–3) a geom belongs to, −1 for the
    trunk and −2 for the world; ``foot`` (4,) the foot geom of each leg;
    ``terrain`` the terrain's geom id; ``trunk`` the trunk's colliding geoms.
    """

    leg: NDArray[np.int64]
    foot: NDArray[np.int64]
    terrain: int
    trunk: NDArray[np.int64]

    def on_robot(self, geom: int) -> bool:
        """Whether ``geom`` belongs to the robot (its trunk or a leg), not the world."""
        return bool(self.leg[geom] >= -1)


def _foot_geom_name(robot: Robot, leg: int) -> str:
    described = robot.description.feet[leg]
    if described.startswith("geom '") and described.endswith("'"):
        return described[len("geom '") : -1]
    raise RobotModelError(
        f"robot '{robot.name}': leg {LEG_NAMES[leg]}'s foot is {described}; the simulator needs "
        "a colliding foot geom to read contact forces"
    )


class World:
    """A compiled MuJoCo model of ``robot`` standing on ``terrain``, with its data.

    Parameters
    ----------
    robot:
        The robot (its MJCF file is loaded again, unchanged).
    terrain:
        The terrain (its filled heights are the collision surface).
    config:
        Rates, contacts and integrator (:class:`WorldConfig`).
    """

    def __init__(self, robot: Robot, terrain: Terrain, config: WorldConfig | None = None) -> None:
        self.robot = robot
        self.terrain = terrain
        self.config = config if config is not None else WorldConfig()
        self.spec = self._build_spec()
        try:
            self.model = self.spec.compile()
        except ValueError as e:
            raise RobotModelError(
                f"MuJoCo cannot compile robot '{robot.name}' on terrain '{terrain.name}': {e}"
            ) from None
        self.data = mujoco.MjData(self.model)
        self.roles = self._roles()
        names = robot.joint_names
        self.actuator_of_joint = np.array([self._actuator_for(n) for n in names], dtype=np.int64)
        self.joint_dof = np.array(
            [self.model.jnt_dofadr[self.model.joint(n).id] for n in names], dtype=np.int64
        )
        self.joint_qpos = np.array(
            [self.model.jnt_qposadr[self.model.joint(n).id] for n in names], dtype=np.int64
        )
        self.base_body = int(self.model.body(robot.base_body).id)
        self.kp = np.array(self.model.actuator_gainprm[self.actuator_of_joint, 0])
        self.kv = -np.array(self.model.actuator_biasprm[self.actuator_of_joint, 2])
        self.torque_limit = np.where(
            self.model.actuator_forcelimited[self.actuator_of_joint].astype(bool),
            self.model.actuator_forcerange[self.actuator_of_joint, 1],
            np.inf,
        )
        self.ctrl_lower = np.array(self.model.actuator_ctrlrange[self.actuator_of_joint, 0])
        self.ctrl_upper = np.array(self.model.actuator_ctrlrange[self.actuator_of_joint, 1])
        limited = self.model.actuator_ctrllimited[self.actuator_of_joint].astype(bool)
        self.ctrl_lower[~limited] = -np.inf
        self.ctrl_upper[~limited] = np.inf

    # ---- building -----------------------------------------------------------------

    def _build_spec(self) -> mujoco.MjSpec:
        cfg = self.config
        contact = cfg.contact
        spec = mujoco.MjSpec.from_file(str(self.robot.mjcf_path))
        spec.option.timestep = 1.0 / cfg.physics_hz
        spec.option.integrator = _INTEGRATORS[cfg.integrator]
        # None keeps the robot file's own (ANYmal C's sets an elliptic cone, impratio 100).
        if contact.cone is not None:
            spec.option.cone = _CONES[contact.cone]
        if contact.impratio is not None:
            spec.option.impratio = contact.impratio
        spec.visual.global_.offwidth = max(spec.visual.global_.offwidth, 1280)
        spec.visual.global_.offheight = max(spec.visual.global_.offheight, 720)
        hf = self.terrain.to_mujoco_hfield(cfg.hfield_base)
        nrow, ncol = hf.elevation.shape
        if nrow < 2 or ncol < 2:
            raise TerrainError(
                f"terrain '{self.terrain.name}' is too small for MuJoCo: {nrow}×{ncol}"
            )
        field = spec.add_hfield()
        field.name = TERRAIN_GEOM
        field.nrow, field.ncol = nrow, ncol
        field.size = list(hf.size)
        field.userdata = hf.elevation.ravel().tolist()
        tex = spec.add_texture()
        tex.name = "terrain_grid"
        tex.type = mujoco.mjtTexture.mjTEXTURE_2D
        tex.builtin = mujoco.mjtBuiltin.mjBUILTIN_CHECKER
        tex.width = tex.height = 256
        tex.rgb1 = [0.62, 0.55, 0.45]
        tex.rgb2 = [0.55, 0.48, 0.40]
        mat = spec.add_material()
        mat.name = "terrain"
        mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "terrain_grid"
        mat.texrepeat = [hf.size[0] / 0.05, hf.size[1] / 0.05]
        mat.texuniform = False
        geom = spec.worldbody.add_geom()
        geom.name = TERRAIN_GEOM
        geom.type = mujoco.mjtGeom.mjGEOM_HFIELD
        geom.hfieldname = TERRAIN_GEOM
        geom.pos = list(hf.center)
        geom.material = "terrain"
        geom.friction = [contact.friction, contact.torsional_friction, contact.rolling_friction]
        geom.condim = contact.condim
        geom.solref = [contact.timeconst, contact.dampratio]
        geom.solimp = list(contact.solimp)
        if self.terrain.mesh is not None:
            self._add_visual_mesh(spec)
        for leg in range(4):
            foot = spec.geom(_foot_geom_name(self.robot, leg))
            foot.friction = [contact.friction, contact.torsional_friction, contact.rolling_friction]
            foot.condim = contact.condim
            foot.solref = [contact.timeconst, contact.dampratio]
            foot.solimp = list(contact.solimp)
        sky = spec.add_texture()
        sky.name = "sky"
        sky.type = mujoco.mjtTexture.mjTEXTURE_SKYBOX
        sky.builtin = mujoco.mjtBuiltin.mjBUILTIN_GRADIENT
        sky.width = sky.height = 256
        sky.rgb1 = [0.55, 0.7, 0.85]
        sky.rgb2 = [0.95, 0.97, 1.0]
        light = spec.worldbody.add_light()
        light.pos = [0.0, 0.0, 3.0]
        light.dir = [0.2, 0.3, -1.0]
        light.castshadow = True
        return spec

    def _add_visual_mesh(self, spec: mujoco.MjSpec) -> None:
        mesh = self.terrain.mesh
        assert mesh is not None
        asset = spec.add_mesh()
        asset.name = "terrain_mesh"
        asset.uservert = np.asarray(mesh.vertices, dtype=float).ravel().tolist()
        asset.userface = np.asarray(mesh.faces, dtype=np.int64).ravel().tolist()
        geom = spec.worldbody.add_geom()
        geom.name = "terrain_mesh"
        geom.type = mujoco.mjtGeom.mjGEOM_MESH
        geom.meshname = "terrain_mesh"
        geom.contype = geom.conaffinity = 0
        geom.group = 1
        geom.rgba = [0.6, 0.55, 0.5, 1.0]

    def _actuator_for(self, joint: str) -> int:
        jid = self.model.joint(joint).id
        hits = [
            a
            for a in range(self.model.nu)
            if self.model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
            and self.model.actuator_trnid[a, 0] == jid
        ]
        if not hits:
            raise RobotModelError(
                f"robot '{self.robot.name}': joint '{joint}' has no actuator; the simulator "
                "drives every leg joint through the model's own actuators"
            )
        a = hits[0]
        if not (
            self.model.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED
            and self.model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE
            and self.model.actuator_gainprm[a, 0] > 0
            and abs(self.model.actuator_biasprm[a, 1] + self.model.actuator_gainprm[a, 0]) < 1e-9
        ):
            raise RobotModelError(
                f"robot '{self.robot.name}': actuator of joint '{joint}' is not a position "
                "servo (<position kp=...>); the simulator needs position servos"
            )
        return a

    def _roles(self) -> GeomRoles:
        m = self.model
        body_leg = np.full(m.nbody, -2, dtype=np.int64)
        base = m.body(self.robot.base_body).id
        for b in range(1, m.nbody):
            # Walk up to the first body that is a leg link or the trunk.
            c = b
            while c != 0:
                name = m.body(c).name
                leg = next(
                    (
                        i
                        for i, bodies in enumerate(self.robot.description.leg_bodies)
                        if name in bodies
                    ),
                    None,
                )
                if leg is not None:
                    body_leg[b] = leg
                    break
                if c == base:
                    body_leg[b] = -1
                    break
                c = int(m.body_parentid[c])
        leg = body_leg[m.geom_bodyid]
        colliding = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        foot = np.array([m.geom(_foot_geom_name(self.robot, i)).id for i in range(4)])
        trunk = np.flatnonzero((leg == -1) & colliding)
        return GeomRoles(leg, foot, int(m.geom(TERRAIN_GEOM).id), trunk)

    # ---- use ----------------------------------------------------------------------

    @property
    def physics_dt(self) -> float:
        """Physics step [s]."""
        return float(self.model.opt.timestep)

    @property
    def control_dt(self) -> float:
        """Control period [s]: :attr:`substeps` physics steps."""
        return self.physics_dt * self.config.substeps

    def reset(
        self,
        q: NDArray[np.float64],
        base_pos: NDArray[np.float64],
        base_quat: NDArray[np.float64],
    ) -> None:
        """Put the robot at joint angles q (12,) [rad] and base pose, at rest, servos holding q."""
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = self.robot.qpos(q, base_pos, base_quat)
        self.data.qvel[:] = 0.0
        self.data.ctrl[self.actuator_of_joint] = np.clip(q, self.ctrl_lower, self.ctrl_upper)
        mujoco.mj_forward(self.model, self.data)

    def set_friction(self, mu: float) -> None:
        """Change the sliding friction of the feet and the terrain to ``mu`` (a friction drop)."""
        for g in (*self.roles.foot, self.roles.terrain):
            self.model.geom_friction[g, 0] = mu
