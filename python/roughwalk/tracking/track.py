"""``roughwalk.track``: execute an optimised motion in MuJoCo and judge it (Melon et al. 2020, §V).

The robot starts at the motion's first pose (joint angles from inverse
kinematics of the planned feet), the :class:`WholeBodyController` tracks
the motion at 400 Hz and then holds the final pose for a second. Success:
the robot never falls (the trunk never touches the terrain, roll and pitch
stay under 45°) and its base ends within 10 cm of the planned final
position. An infeasible motion is a reported failure, never an exception.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from roughwalk.errors import InvalidArgumentError
from roughwalk.tracking.config import TrackingConfig
from roughwalk.tracking.controller import WholeBodyController, rotation_error, tracking_world
from roughwalk.tracking.outcome import TrackingLog, TrackingOutcome, first_leg_contact
from roughwalk.tracking.reach import LegReach, reach_aware_reference
from roughwalk.tracking.reference import Reference, load_trajectory
from roughwalk.tracking.world_terrain import terrain_covering

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.sim.world import World
    from roughwalk.terrain.terrain import Terrain
    from roughwalk.trajopt.result import TrajoptResult

__all__ = ["track", "execute_reference", "TrunkPush"]

_START_FOOT_TOLERANCE_M = 0.01
"""A planned first stance foot farther [m] from the terrain than this starts on it."""


@dataclass(frozen=True)
class TrunkPush:
    """A force ``force_n`` (3,) [N, world] on the trunk from ``at_s`` [s] for ``duration_s`` [s]."""

    force_n: tuple[float, float, float]
    at_s: float
    duration_s: float

    def active(self, t: float) -> bool:
        """Whether the push acts at time ``t`` [s]."""
        return self.at_s <= t < self.at_s + self.duration_s


def track(
    trajectory: TrajoptResult | str | Path | dict[str, Any],
    robot: Robot | str | None = None,
    terrain: Terrain | str | None = None,
    config: TrackingConfig | None = None,
    *,
    video: str | Path | None = None,
    push: TrunkPush | None = None,
) -> TrackingOutcome:
    """Execute an optimised motion on the robot in MuJoCo; report whether it was trackable.

    Parameters
    ----------
    trajectory:
        A :class:`~roughwalk.trajopt.TrajoptResult`, its ``to_dict()`` or the
        path of a ``roughwalk optimize --json`` file.
    robot, terrain:
        The robot and terrain (objects or names); by default those the result names.
    config:
        Controller and success settings (:class:`TrackingConfig`).
    video:
        Write a video of the run here (.mp4, or .gif without ffmpeg).
    push:
        An optional push on the trunk (:class:`TrunkPush`).
    """
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain

    result = load_trajectory(trajectory)
    robot_obj = _named(robot, result.robot, "robot", load_robot)
    terrain_obj = _named(terrain, result.terrain, "terrain", load_terrain)
    reference = Reference.from_result(result)
    outcome = execute_reference(reference, robot_obj, terrain_obj, config, video=video, push=push)
    from roughwalk.trajopt import friction_demand

    mu = (config if config is not None else TrackingConfig()).friction
    return replace(
        outcome,
        implied_torque=_implied_torque(result, robot_obj),
        friction_demand=friction_demand(result, mu).to_dict(),
    )


def _implied_torque(result: TrajoptResult, robot: Robot) -> dict[str, Any] | None:
    """The largest joint torque the plan's forces ask (None when the robot has no IK)."""
    from roughwalk.errors import RobotModelError
    from roughwalk.trajopt import implied_torques

    try:
        return implied_torques(result, robot).to_dict()
    except RobotModelError:
        return None


def _named(value: Any, named: str | None, what: str, loader: Any) -> Any:
    if value is None:
        if named is None:
            raise InvalidArgumentError(
                f"the trajectory names no {what}; pass {what}=... (a name or an object)"
            )
        value = named
    return loader(value) if isinstance(value, str | Path) else value


def execute_reference(
    reference: Reference,
    robot: Robot,
    terrain: Terrain,
    config: TrackingConfig | None = None,
    *,
    video: str | Path | None = None,
    push: TrunkPush | None = None,
) -> TrackingOutcome:
    """Track ``reference`` on ``robot`` over ``terrain`` and judge the run (see :func:`track`)."""
    cfg = config if config is not None else TrackingConfig()
    span = np.linspace(0.0, reference.duration, max(2, int(reference.duration * 20) + 1))
    samples = [reference(float(t)) for t in span]
    points = np.concatenate([np.vstack([s.feet_pos, s.base_pos[None]]) for s in samples])
    world = tracking_world(robot, terrain_covering(terrain, points), cfg)
    reference = reference.tabulated(cfg.control_hz)
    tracked = reference
    if cfg.reach_aware:
        reach = LegReach(robot, cfg.min_knee_bend_rad)
        tracked, _, _ = reach_aware_reference(reference, reach, smoothing_s=cfg.reach_smoothing_s)
        tracked = tracked.tabulated(cfg.control_hz)
    unreachable = _start(world, tracked)
    if unreachable:
        return _not_started(reference, unreachable)
    controller = WholeBodyController(world, tracked, cfg)
    outcome = _simulate(world, controller, reference, cfg, push)
    if video is not None and outcome.log is not None:
        from roughwalk.tracking.video import render_tracking

        outcome.video = str(render_tracking(world, outcome.log, video))
    return outcome


def _not_started(reference: Reference, reason: str) -> TrackingOutcome:
    """The outcome of a motion whose first pose the robot cannot take."""
    nan = float("nan")
    return TrackingOutcome(
        success=False,
        reason=reason,
        final_position_error_m=nan,
        max_orientation_error_rad=nan,
        mean_position_error_m=nan,
        max_position_error_m=nan,
        mean_orientation_error_rad=nan,
        fell=False,
        fall_time_s=None,
        duration_s=reference.duration,
        simulated_s=0.0,
        qp_failures=0,
        early_touchdowns=0,
        late_touchdowns=0,
        slips=0,
        mean_qp_time_ms=0.0,
    )


def _start(world: World, reference: Reference) -> str:
    """Put the robot at the reference's first pose, feet on their planned contact points.

    Returns why it cannot ("" when it can).
    """
    robot = world.robot
    first = reference(0.0)
    quat = first.base_quat
    feet = first.feet_pos.copy()
    # A plan after few solver iterations may start a stance foot centimetres
    # inside or above the terrain (the learned initialiser's first pose is not
    # exactly on it): start such feet on the terrain itself, not sunk into it
    # with the shank or dropping onto it. Millimetres off are left as planned.
    ground = world.terrain.height(feet[:, :2])
    off = first.contact & (np.abs(feet[:, 2] - ground) > _START_FOOT_TOLERANCE_M)
    feet[off, 2] = ground[off]
    centres = feet + np.array([0.0, 0.0, robot.foot_radius])
    q, reachable = robot.inverse_kinematics(centres, first.base_pos, quat)
    if not reachable.all():
        return (
            f"not started: robot '{robot.name}' cannot take the motion's first pose "
            f"(legs {np.flatnonzero(~reachable).tolist()} out of reach)"
        )
    world.reset(q, first.base_pos, quat)
    world.data.ctrl[:] = 0.0
    return ""


def _simulate(
    world: World,
    controller: WholeBodyController,
    reference: Reference,
    cfg: TrackingConfig,
    push: TrunkPush | None,
) -> TrackingOutcome:
    m, d = world.model, world.data
    dt = 1.0 / cfg.control_hz
    substeps = round(cfg.physics_hz / cfg.control_hz)
    n_ticks = int(math.ceil((reference.duration + cfg.stand_after_s) / dt - 1e-9)) + 1
    rows: dict[str, list[Any]] = {k: [] for k in TrackingLog.__dataclass_fields__}
    fell_at: float | None = None
    stalled_at: float | None = None
    reason = ""
    qp_time = 0.0
    cpu_time = 0.0
    for k in range(n_ticks):
        t = k * dt
        tick = controller.step(t)
        # Judged against the plan, whatever the controller tracks.
        s, ref = (
            tick.state,
            (reference(t) if controller.reference is not reference else tick.reference),
        )
        qp_time += tick.solve_time_s
        cpu_time += tick.cpu_time_s
        rows["t"].append(t)
        rows["base_pos"].append(s.base_pos)
        rows["base_pos_ref"].append(ref.base_pos)
        rows["orientation_error"].append(rotation_error(ref.base_rot, s.rotation))
        rows["base_angvel"].append(s.base_angvel)
        rows["base_angvel_ref"].append(ref.base_angvel)
        rows["forces"].append(s.foot_forces)
        rows["forces_ref"].append(ref.forces)
        rows["forces_qp"].append(tick.qp_forces)
        rows["contact_ref"].append(ref.contact)
        rows["stance"].append(tick.contact.stance)
        rows["torques"].append(tick.torques)
        rows["shin_contact"].append(s.shin_contact)
        rows["qpos"].append(d.qpos.copy())
        roll, pitch = s.roll_pitch
        if s.trunk_contact:
            fell_at, reason = t, f"fell: the trunk touched the terrain at t = {t:.2f} s"
        elif max(abs(roll), abs(pitch)) >= cfg.max_roll_pitch_rad:
            fell_at = t
            reason = (
                f"fell: roll {math.degrees(roll):.0f}°, pitch {math.degrees(pitch):.0f}° at "
                f"t = {t:.2f} s (limit {math.degrees(cfg.max_roll_pitch_rad):.0f}°)"
            )
        if fell_at is None and tick.solution.stalled:
            stalled_at = t
            reason = (
                f"the whole-body QP stalled at t = {t:.2f} s: {controller.config.qp_solver} "
                f"reached its iteration limit ({controller.qp.max_iter}) without a solution"
            )
        if fell_at is not None or stalled_at is not None:
            break
        if push is not None:
            d.xfrc_applied[world.base_body, :3] = push.force_n if push.active(t) else 0.0
        mujoco.mj_step(m, d, substeps)
        if not np.all(np.isfinite(d.qpos)):
            fell_at, reason = t, f"the simulation diverged at t = {t:.2f} s"
            break
    log = TrackingLog(**{k: np.asarray(v) for k, v in rows.items()})
    final = reference(reference.duration)
    final_error = float(np.linalg.norm(log.base_pos[-1] - final.base_pos))
    if fell_at is None and stalled_at is None:
        tol = cfg.final_position_tolerance_m
        ok = final_error <= tol
        reason = (
            f"{'tracked' if ok else 'missed the goal'}: the base ends "
            f"{100 * final_error:.1f} cm from the planned final position "
            f"(tolerance {100 * tol:.0f} cm)"
        )
        if controller.qp_failures:
            reason += f"; the QP failed on {controller.qp_failures} ticks"
        if controller.qp_relaxed:
            reason += (
                f"; stance feet held by tasks, not constraints, on {controller.qp_relaxed} ticks"
            )
    else:
        ok = False
    counts = controller.contact.counts
    return TrackingOutcome(
        success=bool(ok),
        reason=reason,
        final_position_error_m=final_error,
        max_orientation_error_rad=float(log.orientation_error_angle.max()),
        mean_position_error_m=float(log.position_error.mean()),
        max_position_error_m=float(log.position_error.max()),
        mean_orientation_error_rad=float(log.orientation_error_angle.mean()),
        fell=fell_at is not None,
        fall_time_s=fell_at,
        duration_s=reference.duration,
        simulated_s=float(log.t[-1]),
        qp_failures=controller.qp_failures,
        early_touchdowns=counts["early_touchdown"],
        late_touchdowns=counts["late_touchdown"],
        slips=counts["slip"],
        mean_qp_time_ms=1000.0 * qp_time / max(len(log.t), 1),
        mean_tick_cpu_ms=1000.0 * cpu_time / max(len(log.t), 1),
        first_leg_contact=first_leg_contact(log),
        log=log,
    )
