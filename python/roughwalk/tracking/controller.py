"""The :class:`WholeBodyController`: at 400 Hz, measured state → QP → joint torques.

Each tick it reads the state from MuJoCo, updates the contact state machine,
builds the tasks from the reference and solves the whole-body QP with
MuJoCo's floating-base quantities: the mass matrix (``mj_fullM``), the bias
forces (``qfrc_bias`` less the passive joint forces) and the feet's point
Jacobians and their time derivatives (``mj_jac``, ``mj_jacDot``).

Beyond the plan. The optimiser's motion is not always the robot's: its
range-of-motion box reaches past ANYmal C's legs and its terrain is smoothed.
So the tracked base is lowered where planned stance feet are out of reach
(:mod:`roughwalk.tracking.reach`, applied by :func:`roughwalk.track`), the
knees and HAA joints are kept in range by bounds on q̈ (a stretched leg must
not snap through to the other knee branch), and swing feet follow the
controller's own rise-move-descend paths over the real terrain to footholds
moved off step edges (:mod:`roughwalk.tracking.swing`).

Torque actuation. ANYmal C's MJCF, like the World it is loaded into, drives
its joints with position servos (``<position kp=...>``). A whole-body
controller commands torques, so :func:`tracking_world` turns each leg
actuator of its own compiled model into a motor (gain 1, no bias, control
range = the servo's force range): the torque limits stay MuJoCo's, always in
force, and the model file stays untouched. ``qfrc_applied`` would have
bypassed those limits.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.config import WorldConfig
from roughwalk.sim.measured_state import MeasuredState, measure
from roughwalk.sim.world import World
from roughwalk.tracking.config import TrackingConfig
from roughwalk.tracking.contact_state import ContactEstimate, ContactStateMachine, LegContact
from roughwalk.tracking.reach import LegReach
from roughwalk.tracking.swing import SwingPlanner, SwingTrajectory
from roughwalk.tracking.tasks import LeastSquaresTask, force_task, motion_task, regularisation
from roughwalk.tracking.whole_body_qp import QPSolution, WholeBodyQP

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.terrain import Terrain
    from roughwalk.tracking.reference import Reference, ReferenceSample

__all__ = ["WholeBodyController", "ControlTick", "tracking_world", "rotation_error"]

_Z = np.array([0.0, 0.0, 1.0])


def tracking_world(robot: Robot, terrain: Terrain, config: TrackingConfig | None = None) -> World:
    """A :class:`~roughwalk.sim.world.World` whose leg actuators take torques [N·m]."""
    cfg = config if config is not None else TrackingConfig()
    world = World(robot, terrain, WorldConfig(physics_hz=cfg.physics_hz, control_hz=cfg.control_hz))
    m = world.model
    for a, limit in zip(world.actuator_of_joint, world.torque_limit, strict=True):
        m.actuator_gaintype[a] = mujoco.mjtGain.mjGAIN_FIXED
        m.actuator_gainprm[a, :] = 0.0
        m.actuator_gainprm[a, 0] = 1.0
        m.actuator_biastype[a] = mujoco.mjtBias.mjBIAS_NONE
        m.actuator_biasprm[a, :] = 0.0
        if np.isfinite(limit):
            m.actuator_ctrllimited[a] = 1
            m.actuator_ctrlrange[a] = (-limit, limit)
    world.data.ctrl[:] = 0.0
    return world


def _full_mass_matrix(m: mujoco.MjModel, d: mujoco.MjData, out: NDArray[np.float64]) -> None:
    # MuJoCo 3.x takes the sparse qM; 4.x takes the data itself.
    if hasattr(d, "qM"):
        mujoco.mj_fullM(m, out, d.qM)
    else:
        mujoco.mj_fullM(m, d, out)


def _capped(v: NDArray[np.float64], limit: float) -> NDArray[np.float64]:
    """``v`` scaled down to norm ``limit`` when longer."""
    size = float(np.linalg.norm(v))
    return v * (limit / size) if size > limit else v


def rotation_error(r_ref: NDArray[np.float64], r: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation vector [rad] (world axes) that turns R into R_ref: log(R_ref Rᵀ)."""
    e = r_ref @ r.T
    cos = np.clip((np.trace(e) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(cos))
    axis = np.array([e[2, 1] - e[1, 2], e[0, 2] - e[2, 0], e[1, 0] - e[0, 1]])
    if angle < 1e-9:
        return 0.5 * axis
    if np.pi - angle < 1e-6:
        # Near π the antisymmetric part vanishes; take the axis from the symmetric part.
        w, v = np.linalg.eigh(0.5 * (e + e.T))
        return angle * v[:, int(np.argmax(w))]
    return angle * axis / (2.0 * np.sin(angle))


@dataclass(frozen=True)
class ControlTick:
    """What one control tick saw and decided.

    Attributes
    ----------
    state:
        The measured state.
    reference:
        The planned state at this tick.
    contact:
        The contact state machine's estimate.
    solution:
        The QP's solution (``success`` False: the previous torques were kept).
    torques:
        (12,) torques sent to the actuators [N·m], joint_names order.
    qp_forces:
        (4, 3) contact forces the QP chose [N] (zero for feet not in stance).
    solve_time_s:
        Wall time [s] of the whole tick (state, tasks, QP).
    cpu_time_s:
        CPU time [s] of the tick (its thread's; load-independent, unlike the wall time).
    """

    state: MeasuredState
    reference: ReferenceSample
    contact: ContactEstimate
    solution: QPSolution
    torques: NDArray[np.float64]
    qp_forces: NDArray[np.float64]
    solve_time_s: float
    cpu_time_s: float = 0.0


class WholeBodyController:
    """Tracks a :class:`~roughwalk.tracking.reference.Reference` with torques from a QP.

    Parameters
    ----------
    world:
        A torque-driven world (:func:`tracking_world`).
    reference:
        The motion to track.
    config:
        Gains, weights and thresholds (:class:`~roughwalk.tracking.config.TrackingConfig`).
    """

    def __init__(
        self, world: World, reference: Reference, config: TrackingConfig | None = None
    ) -> None:
        self.world = world
        self.reference = reference
        self.config = config if config is not None else TrackingConfig()
        cfg = self.config
        self.qp = WholeBodyQP(
            world.joint_dof,
            world.torque_limit,
            cfg.friction,
            cfg.min_normal_force_n,
            cfg.max_normal_force_n,
            cfg.qp_solver,
            cfg.qp_max_iter,
        )
        self.contact = ContactStateMachine(cfg.contact)
        m = world.model
        self.nv = int(m.nv)
        self._foot_geoms = np.asarray(world.roles.foot, dtype=np.int64)
        self.foot_body = np.asarray(m.geom_bodyid[self._foot_geoms], dtype=np.int64)
        self.foot_radius = float(world.robot.foot_radius)
        self.torques = np.zeros(len(world.joint_dof))
        self.qp_failures = 0
        self.qp_stalls = 0
        self.qp_relaxed = 0
        self._mass = np.zeros((self.nv, self.nv))
        self._jacp = np.zeros((3, self.nv))
        self._jacdot = np.zeros((3, self.nv))
        self._scratch = mujoco.MjData(m)
        reach = LegReach(world.robot, cfg.min_knee_bend_rad)
        lower, upper = reach.joint_range(cfg.min_knee_bend_rad, cfg.max_knee_bend_rad)
        self._joint_lower, self._joint_upper = lower, upper
        self.swing_planner = (
            SwingPlanner(world.terrain, self.foot_radius, cfg.swing_clearance_m)
            if cfg.terrain_swings
            else None
        )
        self._swings: list[SwingTrajectory | None] = [None] * 4

    # ---- one tick -------------------------------------------------------------------

    def step(self, t: float) -> ControlTick:
        """Read the state, solve the QP for reference time ``t`` [s], set the torques."""
        started = time.perf_counter()
        started_cpu = time.thread_time()
        world = self.world
        m, d = world.model, world.data
        # mj_step leaves positions one physics step ahead of the kinematics it
        # computed; bring everything to the current state before reading it.
        mujoco.mj_forward(m, d)
        state = measure(world)
        # measure() gives the trunk's centre-of-mass velocity; the tasks need
        # the base frame origin's, which is the free joint's q̇[0:3].
        state = replace(state, base_vel=d.qvel[0:3].copy())
        ref = self.reference(t)
        points = state.feet - self.foot_radius * _Z
        jac, bias = self._foot_jacobians(points)
        foot_vel = np.einsum("lij,j->li", jac, d.qvel)
        estimate = self.contact.update(
            t,
            ref.contact,
            ref.swing_progress,
            state.foot_forces[:, 2],
            np.linalg.norm(foot_vel[:, :2], axis=1),
            self._feet_on_ground() if self.config.contact.ground_contact else None,
        )
        stance = np.flatnonzero(estimate.stance)
        _full_mass_matrix(m, d, self._mass)
        h = d.qfrc_bias - d.qfrc_passive
        layout = self.qp.layout(self.nv, len(stance))
        tasks = self._tasks(layout, state, ref, estimate, stance, points, foot_vel, jac, bias)
        jc = jac[stance].reshape(-1, self.nv)
        hard = bias[stance].ravel() if self.config.hard_contacts else None
        friction = (
            np.where(estimate.slipping[stance], self.config.gains.slip_friction_scale, 1.0)
            * self.config.friction
        )
        solution = self.qp.solve(
            self._mass,
            h,
            jc,
            tasks,
            contact_bias=hard,
            friction=friction,
            qacc_bounds=self._qacc_bounds(),
        )
        qp_forces = np.zeros((4, 3))
        if solution.success:
            self.qp_relaxed += int(solution.relaxed)
            self.torques = solution.tau
            qp_forces[stance] = solution.forces
        else:
            self.qp_failures += 1
            self.qp_stalls += int(solution.stalled)
        d.ctrl[world.actuator_of_joint] = self.torques
        return ControlTick(
            state,
            ref,
            estimate,
            solution,
            self.torques.copy(),
            qp_forces,
            time.perf_counter() - started,
            time.thread_time() - started_cpu,
        )

    def _swing_for(
        self,
        leg: int,
        ref: ReferenceSample,
        foot: NDArray[np.float64],
        shift: NDArray[np.float64],
    ) -> SwingTrajectory | None:
        """The leg's own swing (made at lift-off), or None to follow the planned splines."""
        if self.swing_planner is None or ref.swing_end is None:
            return None
        end = float(ref.swing_end[leg])
        current = self._swings[leg]
        if not np.isfinite(end):
            # Planned stance: a late foot keeps the swing it had.
            return current
        if current is None or current.t1 != end:
            target = self._foothold(self.reference(end).feet_pos[leg], shift)
            current = self.swing_planner.swing(foot, target, ref.t, end)
            self._swings[leg] = current
        return current

    def _foothold(
        self, planned: NDArray[np.float64], shift: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The swing target [m] for the ``planned`` (3,) foothold corrected by ``shift``."""
        assert self.swing_planner is not None
        if self.config.swing_keep_level:
            target = self.swing_planner.foothold(planned, shift)
        else:
            target = self.swing_planner.foothold(planned + shift)
        target[2] -= self.config.touchdown_depth_m
        return target

    def _feet_on_ground(self) -> NDArray[np.bool_]:
        """(4,) the foot geom has a contact with the terrain (any force, even none)."""
        d, roles = self.world.data, self.world.roles
        on = np.zeros(4, dtype=bool)
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            other = g2 if g1 == roles.terrain else g1 if g2 == roles.terrain else -1
            if other >= 0:
                on |= self._foot_geoms == other
        return on

    def _qacc_bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(nv,) q̈ bounds keeping q + q̇h + ½q̈h² within the joints' kept range."""
        world, d = self.world, self.world.data
        h = self.config.joint_limit_horizon_s
        q = d.qpos[world.joint_qpos]
        ahead = q + d.qvel[world.joint_dof] * h
        lower = np.full(self.nv, -np.inf)
        upper = np.full(self.nv, np.inf)
        with np.errstate(invalid="ignore"):
            lower[world.joint_dof] = 2.0 * (self._joint_lower - ahead) / (h * h)
            upper[world.joint_dof] = 2.0 * (self._joint_upper - ahead) / (h * h)
        return lower, upper

    def _com_jacobian(
        self,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Whole-body CoM Jacobian (3, nv), J̇q̇ [m/s²] (by a 1 µs step), CoM [m] and its velocity."""
        m, d = self.world.model, self.world.data
        jac = np.zeros((3, self.nv))
        mujoco.mj_jacSubtreeCom(m, d, jac, self.world.base_body)
        s = self._scratch
        s.qpos[:] = d.qpos
        eps = 1e-6
        mujoco.mj_integratePos(m, s.qpos, d.qvel, eps)
        mujoco.mj_kinematics(m, s)
        mujoco.mj_comPos(m, s)
        ahead = np.zeros((3, self.nv))
        mujoco.mj_jacSubtreeCom(m, s, ahead, self.world.base_body)
        bias = (ahead - jac) @ d.qvel / eps
        com = d.subtree_com[self.world.base_body].copy()
        return jac, bias, com, jac @ d.qvel

    def _foot_jacobians(
        self, points: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(4, 3, nv) point Jacobians of the feet's lowest points and (4, 3) J̇q̇ [m/s²]."""
        m, d = self.world.model, self.world.data
        jac = np.zeros((4, 3, self.nv))
        bias = np.zeros((4, 3))
        for leg in range(4):
            body = int(self.foot_body[leg])
            mujoco.mj_jac(m, d, self._jacp, None, points[leg], body)
            mujoco.mj_jacDot(m, d, self._jacdot, None, points[leg], body)
            jac[leg] = self._jacp
            bias[leg] = self._jacdot @ d.qvel
        return jac, bias

    def _tasks(
        self,
        layout: object,
        state: MeasuredState,
        ref: ReferenceSample,
        estimate: ContactEstimate,
        stance: NDArray[np.int64],
        points: NDArray[np.float64],
        foot_vel: NDArray[np.float64],
        jac: NDArray[np.float64],
        bias: NDArray[np.float64],
    ) -> list[LeastSquaresTask]:
        from roughwalk.tracking.tasks import QPLayout

        assert isinstance(layout, QPLayout)
        cfg, g, w = self.config, self.config.gains, self.config.weights
        d = self.world.data
        # Melon 2020 §V: track the optimised base pose and twist (feedforward
        # acceleration + PD), the swing feet, and the planned contact forces.
        a_lin = ref.base_acc + _capped(
            g.base_kp * (ref.base_pos - state.base_pos)
            + g.base_kd * (ref.base_vel - state.base_vel),
            g.max_base_feedback,
        )
        r = state.rotation
        a_ang = ref.base_angacc + _capped(
            g.orientation_kp * rotation_error(ref.base_rot, r)
            + g.orientation_kd * (ref.base_angvel - state.base_angvel),
            g.max_orientation_feedback,
        )
        # The free joint's q̈[0:3] is the base origin's world acceleration and
        # q̈[3:6] the body-frame angular acceleration, so R q̈[3:6] = ω̇ (world).
        j_lin = np.zeros((3, self.nv))
        j_lin[:, 0:3] = np.eye(3)
        bias_lin = np.zeros(3)
        if (
            cfg.track_com
            and ref.com_pos is not None
            and ref.com_vel is not None
            and ref.com_acc is not None
        ):
            # The single-rigid-body plan's linear dynamics, m c̈ = Σf + m g, hold
            # exactly for the whole robot's centre of mass (not for the trunk,
            # which swinging legs push around): track the planned c itself.
            j_lin, bias_lin, com, com_vel = self._com_jacobian()
            a_lin = ref.com_acc + _capped(
                g.base_kp * (ref.com_pos - com) + g.base_kd * (ref.com_vel - com_vel),
                g.max_base_feedback,
            )
        trunk = quat_to_matrix(d.qpos[3:7])
        j_ang = np.zeros((3, self.nv))
        j_ang[:, 3:6] = trunk
        tasks: list[LeastSquaresTask] = []
        if len(stance):
            # In flight nothing but gravity moves the base: a base task would
            # only whirl the legs to turn the trunk by reaction.
            tasks += [
                motion_task("base_linear", layout, j_lin, bias_lin, a_lin, w.base_linear),
                motion_task("base_angular", layout, j_ang, np.zeros(3), a_ang, w.base_angular),
            ]
        elif w.flight_base_angular > 0:
            tasks.append(
                motion_task(
                    "base_angular", layout, j_ang, np.zeros(3), a_ang, w.flight_base_angular
                )
            )
        c = cfg.contact
        # Raibert/capture-point foothold correction, blended in over the swing.
        shift = g.foothold_velocity_gain * (state.base_vel - ref.base_vel) + (
            g.foothold_position_gain * (state.base_pos - ref.base_pos)
        )
        shift[2] = 0.0
        norm = float(np.linalg.norm(shift))
        if norm > g.max_foothold_shift_m:
            shift *= g.max_foothold_shift_m / norm
        for leg in range(4):
            s = estimate.states[leg]
            if s.bears_load:
                weight = w.stance_foot * (g.slip_gain_scale if estimate.slipping[leg] else 1.0)
                tasks.append(
                    motion_task(
                        f"stance_foot {leg}", layout, jac[leg], bias[leg], np.zeros(3), weight
                    )
                )
                continue
            target, target_vel, target_acc = ref.feet_pos[leg], ref.feet_vel[leg], ref.feet_acc[leg]
            swing = self._swing_for(leg, ref, points[leg], shift)
            if s == LegContact.SWING and swing is not None:
                target, target_vel, target_acc = swing(ref.t)
            elif s == LegContact.SWING:
                blend = float(np.clip(ref.swing_progress[leg], 0.0, 1.0))
                target = target + blend * shift
            if s == LegContact.LATE_TOUCHDOWN:
                # Keep reaching down until the ground is found (or too deep).
                target = swing.target if swing is not None else target + shift
                depth = min(c.search_speed_m_s * estimate.late_since[leg], c.search_depth_m)
                target = target - depth * _Z
                target_vel = -c.search_speed_m_s * _Z if depth < c.search_depth_m else np.zeros(3)
                target_acc = np.zeros(3)
            a_foot = target_acc + _capped(
                g.swing_kp * (target - points[leg]) + g.swing_kd * (target_vel - foot_vel[leg]),
                g.max_swing_feedback,
            )
            tasks.append(
                motion_task(f"swing_foot {leg}", layout, jac[leg], bias[leg], a_foot, w.swing_foot)
            )
        for i, leg in enumerate(stance):
            tasks.append(force_task(layout, i, ref.forces[leg], w.force, name=f"force {leg}"))
        tasks.extend(regularisation(layout, w.joint_acceleration, w.torque))
        return tasks
