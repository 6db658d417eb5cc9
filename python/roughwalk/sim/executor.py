"""The :class:`Executor`: plan, optimise and walk, with reflexes and re-planning (Zucker 2011, §6).

The pipeline, in simulated time:

* the initial plan and the first footstep's trajectory are made before the
  clock starts (the trials allowed planning time before a run);
* "after the first footstep, trajectory optimization occurs in parallel with
  execution. As the current step is being executed, the next step gets
  optimized and appended to the FIFO buffer": when footstep k starts
  playing, footstep k+1 is generated and its measured wall time w (times
  :attr:`ExecutorConfig.compute_time_scale`) is charged from that instant;
  if w is longer than footstep k, the robot holds the end of k and waits, and
  the wait counts;
* every control tick the leg integrators correct the trunk, the joint
  controller turns the commanded angles into servo commands, and the reflex
  monitor compares the measured state with the plan;
* a reflex clears the buffer, puts all four feet down and settles
  (:func:`~roughwalk.sim.recovery.recovery_segment`), then re-plans from the
  feet where they stand with the anytime planner's budget (2 s); the robot
  stands still for the planning's wall time and then walks on.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from roughwalk.errors import PlanningError
from roughwalk.planning.foothold_safety import resting_centres, steep_footholds
from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.sim.config import SimConfig
from roughwalk.sim.cop_stabilizer import CopStabilizer
from roughwalk.sim.foothold_snap import footholds_toward, replant_targets
from roughwalk.sim.footstep_source import (
    CRAWL_ORDER,
    FootstepSource,
    PlanAttempt,
    PlanStart,
    nominal_feet_xy,
)
from roughwalk.sim.joint_controller import JointController
from roughwalk.sim.leg_integrator import LegIntegrator
from roughwalk.sim.lift_gate import LiftGate
from roughwalk.sim.outcome import Outcome, OutcomeMonitor
from roughwalk.sim.recovery import (
    EDGE_REACH_M,
    blend_segment,
    hold_segment,
    near_ground,
    off_edge,
    pose_segment,
    recently_loaded,
    recovery_segment,
    replant_segments,
    settled,
    sliding_leg,
    standing_feet,
)
from roughwalk.sim.reflexes import ReflexMonitor
from roughwalk.sim.run_log import RunLog
from roughwalk.sim.runner import Runner
from roughwalk.sim.time_breakdown import time_breakdown
from roughwalk.sim.touchdown_adapter import TouchdownAdapter
from roughwalk.sim.trajectory_buffer import DesiredState, Segment, TrajectoryBuffer
from roughwalk.sim.world import World
from roughwalk.trajectories.euler import matrix_to_rpy
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator, PreparedPlan
from roughwalk.trajectories.step_sequence import plan_fields

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.sim.disturbances import Disturbance
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.terrain.terrain import Terrain
    from roughwalk.trajectories.config import TrajectoryConfig
    from roughwalk.trajectories.footstep_trajectory import FootstepTrajectory

__all__ = ["Executor", "ProgressCallback"]

ProgressCallback = Callable[[float, float, str], None]
"""Called every simulated tenth of a second with (sim time [s], progress 0–1, mode)."""

_SETTLE_BEFORE_S = 0.3
# How long [s] the recovery's hold is extended at a time while the robot
# still rocks, and the vertical force [N] of a foot that bears load.
_SETTLE_TICK_S = 0.02
_LOADED_N = 1.0
_SLIDE_STEP_MIN_M = 0.005
"""A slid foot's "replant" target nearer than this [m] (across) restarts the recovery instead."""
_SLIDE_LOADED_WINDOW_S = 0.05
"""A foot that bore load within this [s] counts as bearing for ``reflex.recovery_slide_bearing``
below 3: on board AE RH bore 10–25 N with a tick of nothing every 30 ms."""
# How far [m] a foot may have settled from its planned foothold for a re-plan
# to start from the planned one.
_NEAR_PLAN_M = 0.025

_RECENTRE_TRIES = 12
"""Most plans one recentring step asks the planner for (``reflex.recentre_steps``)."""

_RECENTRE_TARGETS = 3
"""Most footholds tried per foot in one recentring step, nearest its nominal place first."""


def nudged_stances(
    feet: np.ndarray, largest_m: float, first_leg: int | None = None
) -> Iterator[np.ndarray]:
    """Stances (4, 3) [m] with one foot of ``feet`` moved, nearest first.

    Each foot in turn (``first_leg`` first: it lifts first, so its start
    matters least), 1 cm at a time up to ``largest_m``, in eight
    directions: the candidates a re-plan starts from when the stance where
    the feet stand has no pose certificate.
    """
    n = int(np.floor(largest_m / 0.01 + 1e-9))
    angles = np.arange(8) * (np.pi / 4)
    legs = sorted(range(4), key=lambda leg: leg != first_leg)
    for r in 0.01 * np.arange(1, n + 1):
        for leg in legs:
            for a in angles:
                moved = np.array(feet, dtype=float, copy=True)
                moved[leg, :2] += r * np.array([np.cos(a), np.sin(a)])
                yield moved


def later_legs(leg: int) -> list[int]:
    """The other legs (canonical indices) in walking order after ``leg``."""
    order = [LEG_NAMES.index(name) for name in CRAWL_ORDER]
    k = order.index(leg)
    return order[k + 1 :] + order[:k]


class _Plan:
    """One plan being executed: its steps' legs and the trajectory iterator.

    ``prepared`` is None for a plan with no step (its start was already at
    the goal): nothing to walk.
    """

    def __init__(
        self, attempt: PlanAttempt, prepared: PreparedPlan | None, steps: Iterator[Any]
    ) -> None:
        self.attempt = attempt
        self.prepared = prepared
        self.steps = steps
        self.legs = [s.leg for s in prepared.sequence.steps] if prepared is not None else []
        self.exhausted = False


class Executor:
    """Walks a robot to a goal in a MuJoCo world.

    Parameters
    ----------
    robot, terrain:
        The robot and the true terrain (what the physics uses).
    source:
        Where plans come from (:mod:`roughwalk.sim.footstep_source`).
    config:
        Simulation settings (:class:`SimConfig`).
    planner_terrain:
        The terrain the planner and the trajectory optimiser see (default
        ``terrain``; a map-error disturbance makes it differ).
    trajectory_config:
        Settings of trajectory generation.
    disturbances:
        Pushes, friction drops (:mod:`roughwalk.sim.disturbances`).
    progress:
        A :data:`ProgressCallback`.
    sdf:
        A prebuilt signed distance field of ``planner_terrain``.
    """

    def __init__(
        self,
        robot: Robot,
        terrain: Terrain,
        source: FootstepSource,
        *,
        config: SimConfig | None = None,
        planner_terrain: Terrain | None = None,
        trajectory_config: TrajectoryConfig | None = None,
        disturbances: Sequence[Disturbance] = (),
        progress: ProgressCallback | None = None,
        sdf: Any = None,
    ) -> None:
        self.robot = robot
        self.terrain = terrain
        self.source = source
        self.config = config if config is not None else SimConfig()
        self.planner_terrain = planner_terrain if planner_terrain is not None else terrain
        self.world = World(robot, terrain, self.config.world)
        self.runner = Runner(self.world)
        self.controller = JointController(self.world, self.config.controller)
        self.integrator = LegIntegrator(robot, self.config.integrator, self.world.control_dt)
        self.stabilizer = CopStabilizer(self.config.stabilizer, self.world.control_dt)
        self.touchdown = TouchdownAdapter(self.config.touchdown, self.world.control_dt)
        self.lift_gate = LiftGate(self.config.lift_gate, self.world.control_dt)
        self.reflexes = ReflexMonitor(self.config.reflex)
        self.generator = FootstepTrajectoryGenerator(
            robot, self.planner_terrain, sdf=sdf, config=trajectory_config
        )
        self.buffer = TrajectoryBuffer()
        self.disturbances = list(disturbances)
        self.progress = progress
        self.plans: list[Any] = []
        self.log = RunLog()
        self._plan: _Plan | None = None
        self._step_index = 0
        self._leg_joints = np.asarray(robot.canonical_index).reshape(4, 3)
        # When the recovery's hold stops waiting for the robot to settle [s].
        self._settle_deadline: float | None = None
        self._goal = np.zeros(2)
        # Legs re-planted in this recovery, and the cells too steep to re-plant on.
        self._replanted: set[int] = set()
        self._steep: np.ndarray | None = None
        # Slides caught in this recovery, since when one lasts, the recovery's footholds.
        self._slides = 0
        self._slide_since: float | None = None
        self._recovery_footholds = np.zeros((4, 3))
        # Steps toward the nominal stance taken in this recovery (``reflex.recentre_steps``).
        self._recentred = 0
        # When each foot last bore load [s] (``reflex.loaded_window_s``).
        self._last_loaded = np.full(4, -np.inf)

    # ---- planning -------------------------------------------------------------------

    def _make_plan(
        self, start: PlanStart, goal: np.ndarray, budget: float
    ) -> tuple[_Plan | None, PlanAttempt, float]:
        """Plan and make the first footstep's trajectory: (plan, attempt, wall time [s])."""
        began = time.perf_counter()
        attempt = self.source.plan(start, goal, budget)
        if not attempt.ok:
            return None, attempt, time.perf_counter() - began
        try:
            if len(plan_fields(attempt.plan)["footsteps"]) <= 4:
                # The start was inside the planner's goal radius: the plan is
                # the stance alone, and there is nothing left to walk.
                self.plans.append(attempt.plan)
                plan = _Plan(attempt, None, iter(()))
                return plan, attempt, time.perf_counter() - began
            prepared = self.generator.prepare(attempt.plan)
        except PlanningError as e:
            failed = PlanAttempt(
                None,
                "INVALID",
                f"the plan cannot be executed: {e}",
                attempt.wall_s,
                relaxed=attempt.relaxed,
            )
            return None, failed, time.perf_counter() - began
        self.plans.append(attempt.plan)
        plan = _Plan(attempt, prepared, self.generator.iter_steps(prepared))
        return plan, attempt, time.perf_counter() - began

    def _next_step(self, plan: _Plan) -> tuple[FootstepTrajectory | None, float]:
        """Generate the plan's next footstep; returns it (None at the end) and the wall time [s]."""
        began = time.perf_counter()
        try:
            traj = next(plan.steps)
        except StopIteration:
            plan.exhausted = True
            return None, time.perf_counter() - began
        return traj, time.perf_counter() - began

    def _charge(self, wall_s: float) -> float:
        return wall_s * self.config.executor.compute_time_scale

    # ---- the run --------------------------------------------------------------------

    def run(self, start: tuple[float, float, float], goal: Sequence[float]) -> Outcome:
        """Walk from the trunk pose ``start`` (x [m], y [m], yaw [rad]) to ``goal`` (x, y) [m]."""
        cfg = self.config
        goal_xy = np.asarray(goal, dtype=float)[:2]
        self._goal = goal_xy
        log = self.log
        log.meta.update(
            robot=self.robot.name,
            terrain=self.terrain.spec,
            planner_terrain=self.planner_terrain.spec,
            start=list(start),
            goal=goal_xy.tolist(),
            physics_hz=cfg.world.physics_hz,
            control_hz=cfg.world.control_hz,
            joint_names=list(self.robot.joint_names),
            nq=int(self.world.model.nq),
            source=self.source.name,
            disturbances=[d.describe() for d in self.disturbances],
        )
        plan, attempt, wall = self._make_plan(
            PlanStart(pose=(float(start[0]), float(start[1]), float(start[2]))),
            goal_xy,
            cfg.executor.initial_plan_s,
        )
        log.event(
            0.0,
            "plan",
            status=attempt.status,
            wall_s=wall,
            source=self.source.name,
            relaxed=attempt.relaxed,
        )
        first = self._next_step(plan)[0] if plan is not None else None
        if plan is None or first is None:
            if plan is None:
                reason = attempt.reason
            elif plan.prepared is None:
                reason = "the start is already at the goal"
            else:
                reason = "the plan has no footsteps"
            centroid = self._stance_centroid(start)
            monitor = OutcomeMonitor(goal_xy, centroid, cfg.outcome)
            return monitor.finish(0.0, failure=f"no plan: {reason}")
        self._plan = plan
        segment = Segment.from_footstep(first)
        measured = self.runner.reset(segment.q[0], segment.base_pos[0], segment.base_quat[0])
        monitor = OutcomeMonitor(goal_xy, measured.feet_centroid, cfg.outcome)
        # The robot settles on its feet before the clock starts.
        self.buffer.append(hold_segment(segment.sample(0.0), _SETTLE_BEFORE_S, 0.0, kind="hold"))
        self.buffer.append(segment.with_ready_at(0.0))
        return self._loop(measured, monitor, goal_xy)

    def _stance_centroid(self, start: Sequence[float]) -> np.ndarray:
        return np.asarray(start, dtype=float)[:2]

    def _loop(self, measured: MeasuredState, monitor: OutcomeMonitor, goal: np.ndarray) -> Outcome:
        cfg = self.config
        dt = self.world.control_dt
        log = self.log
        reflexes = replans = steps_done = 0
        wait_s = replan_s = 0.0
        failure: str | None = None
        mode = "walk"
        replan_until = -np.inf
        next_progress = 0.0
        distance = max(float(np.linalg.norm(goal - monitor.start_centroid)), 1e-9)
        limit = cfg.outcome.time_limit_s
        while True:
            now = measured.time
            desired, waiting, started = self.buffer.advance(now)
            current = self.buffer.current
            if started and current is not None and current.kind == "step":
                monitor.start_clock(self.buffer.started_at)
                if self._step_index:
                    steps_done += 1
                self._step_index = current.step
                log.event(
                    now,
                    "step",
                    step=current.step,
                    leg=current.info.get("leg"),
                    valid=current.info.get("valid"),
                    fitted_s=current.info.get("fitted_s"),
                    stretch_s=current.info.get("stretch_s"),
                )
                self._schedule_next(now)
            if desired is None:
                break
            if current is None and not self.buffer.queued:
                if mode == "recovery" and not self._settled(measured, now):
                    # Still rocking: hold a little longer before lifting a foot.
                    self.buffer.append(hold_segment(desired, _SETTLE_TICK_S, now, "recovery"))
                elif mode == "recovery" and self._at_goal(monitor, measured):
                    # Recovered on four feet inside the goal radius: the run is done.
                    log.event(now, "settled_at_goal")
                    break
                elif mode == "recovery" and self._replant(measured, now):
                    pass  # a foot steps off a face onto a foothold, then the robot settles
                elif mode == "recovery":
                    # Settled on four feet: re-plan from where they stand (§6, §4.5).
                    replans += 1
                    ok, charged = self._replan(measured, desired, goal, now)
                    replan_until = now + charged
                    if not ok:
                        reason = log.events[-1].get("reason") or ""
                        if self._recentre(measured, goal, now, charged):
                            # A foot steps toward its nominal place; then the
                            # robot settles and re-plans again.
                            continue
                        failure = "re-planning failed: " + reason
                        break
                    mode = "replan"
                elif self._plan is not None and self._plan.exhausted:
                    break
            if mode == "replan" and now >= replan_until - 1e-9:
                mode = "walk"
            if mode in ("walk", "wait"):
                mode = "wait" if waiting else "walk"
            gated = False
            if mode == "walk" and current is not None and desired is not None:
                tau = now - self.buffer.started_at
                gated = self.lift_gate.hold(current, tau, desired, measured)
                if gated:
                    # A foot that stays down does not bear yet: the plan's clock
                    # stops at the lift-off and the joint targets stand still.
                    self.buffer.delay(dt)
                    desired = replace(desired, qd=np.zeros_like(desired.qd))
                elif self.lift_gate.released_s > 0:
                    log.event(
                        now,
                        "lift_gate",
                        held_s=self.lift_gate.released_s,
                        legs=[LEG_NAMES[i] for i in self.lift_gate.short],
                    )
            if mode == "wait" and monitor.first_motion is not None:
                wait_s += dt
            if mode == "replan":
                replan_s += dt
            # The trunk's target moved by the CoP stabiliser's shift: what the
            # integrators hold and the reflexes judge.
            steered = self.stabilizer.update(desired, measured)
            self._last_loaded[measured.foot_forces[:, 2] > _LOADED_N] = now
            slid = self._recovery_slide(measured, desired, now) if mode == "recovery" else None
            if slid is not None:
                log.event(now, "recovery_slide", leg=LEG_NAMES[slid], foot=measured.feet[slid])
                desired = self._catch_slide(measured, desired, now, slid)
                steered = desired
            if mode in ("walk", "wait") and monitor.first_motion is not None:
                trigger = self.reflexes.check(steered, measured)
                if trigger is not None:
                    reflexes += 1
                    log.event(
                        now,
                        "reflex",
                        trigger=trigger.kind,
                        value=trigger.value,
                        threshold=trigger.threshold,
                        leg=trigger.leg,
                        detail=trigger.describe(),
                    )
                    if reflexes > cfg.reflex.max_reflexes:
                        failure = f"gave up after {cfg.reflex.max_reflexes} reflexes"
                        break
                    desired = self._start_recovery(measured, desired, now)
                    steered = desired
                    mode = "recovery"
            offset = self.stabilizer.feet_offset(desired) + self.touchdown.update(desired, measured)
            q_cmd = self.integrator.update(steered, measured, offset)
            if desired.kind == "recovery":
                q_cmd = self._catch(q_cmd, desired, measured)
            command = self.controller.command(q_cmd, desired, measured)
            for disturbance in self.disturbances:
                disturbance.apply(self.world, now, monitor.first_motion, log)
            qpos = self.world.data.qpos.copy()
            log.record(
                qpos,
                measured,
                desired,
                self.runner.target if self.runner.target is not None else q_cmd,
                self.integrator.delta,
                self.controller.stiffness,
                # A reflex fired on a held tick ends the hold: the tick is the recovery's.
                "gate" if gated and mode == "walk" else mode,
            )
            measured = self.runner.step(command)
            monitor.update(measured, desired)
            if monitor.fell:
                log.event(measured.time, "fall", reason=monitor.fall_reason)
                break
            if monitor.reached_at is not None and not log.events_of("goal"):
                log.event(monitor.reached_at, "goal")
            if measured.time > limit:
                failure = f"time limit: {limit:.0f} s of simulated time"
                break
            if self.progress is not None and measured.time >= next_progress:
                centroid = measured.feet_centroid[:2]
                done = 1.0 - float(np.linalg.norm(goal - centroid)) / distance
                self.progress(measured.time, min(max(done, 0.0), 1.0), mode)
                next_progress = measured.time + 0.1
        end = measured.time
        if self._plan is not None and self._plan.exhausted and failure is None and not monitor.fell:
            steps_done += 1
        log.record(
            self.world.data.qpos.copy(),
            measured,
            None,
            np.asarray(measured.q),
            self.integrator.delta,
            self.controller.stiffness,
            "done",
        )
        outcome = monitor.finish(
            end,
            reflexes=reflexes,
            replans=replans,
            wait_s=wait_s,
            replan_s=replan_s,
            steps=steps_done,
            relaxed_plans=sum(
                1 for e in self.log.events if e["kind"] in ("plan", "replan") and e.get("relaxed")
            ),
            failure=failure,
            extra={
                "max_actuator_force_ratio": float(
                    np.max(self.runner.max_actuator_force / self.world.torque_limit)
                ),
                "max_joint_speed_ratio": self.runner.max_speed_ratio,
                "first_motion_s": monitor.first_motion,
                "reached_at_s": monitor.reached_at,
                "end_s": end,
            },
        )
        # Where the clock went (the speed's time: first motion to the goal or the end).
        clock_start = monitor.first_motion if monitor.first_motion is not None else end
        breakdown = time_breakdown(log, clock_start, clock_start + outcome.time_s)
        outcome.extra["time_breakdown"] = breakdown.summary()
        log.meta["footstep_times"] = [asdict(f) for f in breakdown.footsteps]
        log.event(end, "end", success=outcome.success, reason=outcome.reason)
        log.meta["outcome"] = outcome.to_dict()
        return outcome

    def _at_goal(self, monitor: OutcomeMonitor, measured: MeasuredState) -> bool:
        """Whether a recovered robot may stop: it reached the goal and its feet are still there.

        With ``reflex.end_at_goal``: the goal was reached (``monitor.reached_at``)
        and the feet's centroid is within ``outcome.goal_radius_m`` of it.
        """
        if not self.config.reflex.end_at_goal or monitor.reached_at is None:
            return False
        centroid = measured.feet_centroid[:2]
        return bool(np.linalg.norm(centroid - monitor.goal) <= self.config.outcome.goal_radius_m)

    def _schedule_next(self, now: float) -> None:
        """Footstep k started: optimise k+1 now, ready after its charged wall time."""
        plan = self._plan
        if plan is None or plan.exhausted:
            return
        traj, wall = self._next_step(plan)
        if traj is None:
            return
        if (
            self.config.executor.refuse_colliding_m > 0
            and not traj.report.collision_free
            and self._replan_around(traj, now, wall)
        ):
            return
        ready = now + self._charge(wall)
        self.buffer.append(Segment.from_footstep(traj, ready_at=ready))
        self.log.event(
            now,
            "optimized",
            step=int(traj.step),
            wall_s=wall,
            ready_at=ready,
            valid=bool(traj.valid),
            attempts=int(traj.report.attempts),
            duration_s=float(traj.report.duration_s),
        )

    def _replan_around(self, colliding: FootstepTrajectory, now: float, wall: float) -> bool:
        """Re-plan instead of walking a footstep the generator could not make collision-free.

        From the stance the current footstep ends in, with the colliding
        step's foothold refused within ``executor.refuse_colliding_m``
        (§6's re-planning, before the error rather than after it: on the
        gap, RF's shank came to rest on the trench's rim and a reflex cost
        1.1 s). The new plan's first footstep follows the current one
        after a blend. Returns whether a plan came; if not, the step is
        walked as it is. Its wall time, ``wall`` [s] before it, is charged.
        """
        current = self.buffer.current
        if current is None or current.kind != "step":
            return False
        end = current.last()
        leg = LEG_NAMES.index(colliding.leg)
        x, y = (float(v) for v in colliding.feet[-1, leg, :2])
        radius = self.config.executor.refuse_colliding_m
        start = PlanStart(feet=end.feet.copy(), next_leg=leg, refused=((leg, x, y, radius),))
        budget = self.config.reflex.replan_budget_s
        plan, attempt, plan_wall = self._make_plan(start, self._goal, budget)
        first, step_wall = self._next_step(plan) if plan is not None else (None, 0.0)
        wall += plan_wall + step_wall
        self.log.event(
            now,
            "refused",
            step=int(colliding.step),
            leg=colliding.leg,
            foothold=[x, y],
            status=attempt.status,
            wall_s=wall,
            reason=attempt.reason if plan is None else "",
            valid=bool(first.valid) if first is not None else None,
        )
        if plan is None or first is None:
            return False
        self._plan = plan
        ready = now + self._charge(wall)
        segment = Segment.from_footstep(first, ready_at=ready)
        self.buffer.append(blend_segment(self.robot, end, segment.sample(0.0), 0.2, ready))
        self.buffer.append(segment)
        return True

    def _next_leg(self, desired: DesiredState) -> int | None:
        """The leg to move first after a reflex: the swing leg if not yet landed, else the next."""
        plan = self._plan
        if plan is None or self._step_index < 1:
            return None
        k = self._step_index - 1
        leg = plan.legs[k] if k < len(plan.legs) else None
        if leg is not None and not desired.support[leg]:
            return int(leg)
        return int(plan.legs[k + 1]) if k + 1 < len(plan.legs) else leg

    def _start_recovery(
        self,
        measured: MeasuredState,
        desired: DesiredState,
        now: float,
        slid: int | None = None,
    ) -> DesiredState:
        """Clear the buffer and queue the reflex's motion; returns the desired state to use now.

        ``slid``: a foot that slid during the recovery under way (see
        ``reflex.recovery_slide_m``): the recovery starts again from where
        the robot is, with that foot put down again like a lifted one.
        """
        cfg = self.config.reflex
        current = self.buffer.current
        planned = np.array(current.last().feet if current is not None else desired.feet)
        self._settle_deadline = None
        if slid is None:
            self._reflex_next_leg = self._next_leg(desired)
            self._replanted = set()
            self._slides = 0
            self._recentred = 0
            self._reflex_planned_feet = np.array(planned, dtype=float)
        # A foot that bore load a few ticks ago and still stands counts as loaded.
        in_contact = recently_loaded(self._last_loaded, now, 0.0) | (
            recently_loaded(self._last_loaded, now, cfg.loaded_window_s)
            & near_ground(self.robot, self.terrain_for_recovery, measured.feet)
        )
        bearing = (
            in_contact
            | standing_feet(
                self.robot, self.terrain_for_recovery, measured, desired.support, _LOADED_N
            )
            if cfg.standing_bear
            else in_contact
        )
        if slid is not None and cfg.recovery_slide_response in ("hold", "replant"):
            # The slid foot keeps bearing where it now is; the recovery starts
            # over from the measured stance, the trunk centred over it.
            bearing[slid] = True
            in_contact[slid] = True
        elif slid is not None:
            in_contact[slid] = bearing[slid] = False
            planned[slid] = self._replant_target(measured, slid)
        self._slide_since = None
        self._plan = None
        self._drop_motion()
        segments, footholds = recovery_segment(
            self.robot,
            self.terrain_for_recovery,
            measured,
            planned,
            in_contact,
            cfg.lower_s,
            cfg.settle_s,
            now,
            capture_max_m=cfg.capture_max_m,
            bearing=bearing,
            catch_nearer=cfg.catch_nearer,
        )
        for s in segments:
            self.buffer.append(s)
        self._recovery_footholds = footholds
        self.log.event(now, "recovery", footholds=footholds, feet_down=in_contact)
        state, _, _ = self.buffer.advance(now)
        assert state is not None
        return state

    def _catch_slide(
        self, measured: MeasuredState, desired: DesiredState, now: float, slid: int
    ) -> DesiredState:
        """The motion after foot ``slid`` slid during a recovery; the desired state to use now.

        ``reflex.recovery_slide_response`` "lower" and "hold" start the
        recovery over (:meth:`_start_recovery`); "replant" shifts the trunk
        over the other three feet, steps the slid foot onto its re-plant
        target (:func:`~roughwalk.sim.recovery.replant_segments`) and centres
        the trunk again, or starts the recovery over as "hold" where the
        other three cannot hold the trunk or the target is within
        :data:`_SLIDE_STEP_MIN_M` of the foot (logs seed 1: feet re-seated
        in place twice, the walk diverged and fell).
        """
        cfg = self.config.reflex
        if cfg.recovery_slide_response != "replant":
            return self._start_recovery(measured, desired, now, slid=slid)
        target = self._slide_target(measured, slid)
        if float(np.linalg.norm(target[:2] - measured.feet[slid, :2])) < _SLIDE_STEP_MIN_M:
            # Nowhere better to step: re-seating it in place only shifts the trunk.
            return self._start_recovery(measured, desired, now, slid=slid)
        segments = self._replant_motion(measured, slid, target, now)
        if segments is None:
            return self._start_recovery(measured, desired, now, slid=slid)
        self._slide_since = None
        self._settle_deadline = None
        self._drop_motion()
        for segment in segments:
            self.buffer.append(segment)
        footholds = np.array(measured.feet, dtype=float)
        footholds[slid] = target
        self._recovery_footholds = footholds
        self.log.event(now, "replant", leg=LEG_NAMES[slid], foot=measured.feet[slid], target=target)
        state, _, _ = self.buffer.advance(now)
        assert state is not None
        return state

    def _drop_motion(self) -> None:
        """Forget the queued motion and every per-leg and reflex state built on it."""
        self.buffer.clear()
        self.integrator.reset()
        self.stabilizer.reset()
        self.touchdown.reset()
        self.lift_gate.reset()
        self.reflexes.reset()

    def _replant_motion(
        self, measured: MeasuredState, leg: int, target: np.ndarray, now: float
    ) -> list[Segment] | None:
        """:func:`~roughwalk.sim.recovery.replant_segments` with ``reflex``'s timing and margin."""
        cfg = self.config.reflex
        return replant_segments(
            self.robot,
            measured,
            leg,
            target,
            cfg.replant_s,
            cfg.settle_s,
            now,
            cfg.replant_margin_m,
        )

    def _slide_target(self, measured: MeasuredState, leg: int) -> np.ndarray:
        """Where a foot that slid steps with ``recovery_slide_response`` "replant".

        The nearest gentle foothold (:meth:`_replant_target`, with
        ``reflex.replant_max_slope``); else on along the slide, off the face
        onto the first flat ground within
        :data:`~roughwalk.sim.recovery.EDGE_REACH_M`
        (:func:`~roughwalk.sim.recovery.off_edge`), resting on it, if the
        stance there has a pose certificate (as :meth:`_replant_target`'s).
        """
        foot = np.array(measured.feet[leg], dtype=float)
        target = self._replant_target(measured, leg)
        if np.linalg.norm(target - foot) > 1e-9:
            return target
        way = foot - self._recovery_footholds[leg]
        ahead = foot + way * (EDGE_REACH_M / max(float(np.linalg.norm(way[:2])), 1e-9))
        r = self.robot.foot_radius
        moved = off_edge(self.terrain_for_recovery, foot, ahead, r, EDGE_REACH_M)
        target = resting_centres(self.terrain_for_recovery, moved[None, :2], r)[0]
        # As every re-plant (``reflex.replant_certified``): only where the stance
        # has a pose certificate; else where it is, which starts the recovery over.
        return target if self._replant_certified(measured, leg, target) else foot

    def _replant_target(self, measured: MeasuredState, leg: int) -> np.ndarray:
        """Where a foot that slid goes down again: the nearest gentle foothold, or where it is.

        The foothold as ``reflex.replant_max_slope`` finds one (when that is
        on and the source has a planner), else the foot's own position.
        """
        foot = np.array(measured.feet[leg], dtype=float)
        for moved, target in self._replant_targets(measured):
            if moved == leg and self._replant_certified(measured, leg, target):
                return np.asarray(target, dtype=float)
        return foot

    def _replant_certified(self, measured: MeasuredState, leg: int, target: np.ndarray) -> bool:
        """Whether the stance a re-plant makes (``leg`` at ``target`` [m]) has a pose certificate.

        See ``reflex.replant_certified``: asked of the source's planner as
        the re-plan after it will ask (from the measured trunk with
        ``reflex.replan_from_trunk``, the leg due to lift first). True when
        the check is off or the source cannot certify.
        """
        certifies = getattr(self.source, "certifies", None)
        if not self.config.reflex.replant_certified or certifies is None:
            return True
        feet = np.array(measured.feet, dtype=float)
        feet[leg] = target
        trunk = (measured.base_pos.copy(), measured.base_quat.copy())
        start = PlanStart(
            feet=feet,
            next_leg=getattr(self, "_reflex_next_leg", None),
            trunk=trunk if self.config.reflex.replan_from_trunk else None,
        )
        return bool(certifies(start, self._goal))

    def _replant_targets(
        self, measured: MeasuredState, min_m: float = 0.0
    ) -> list[tuple[int, np.ndarray]]:
        """(leg, foothold) for each foot re-planting would move ``min_m`` [m] or more; [] when off.

        :func:`~roughwalk.sim.foothold_snap.replant_targets` with
        :meth:`_replant_planner`'s planner and too-steep cells.
        """
        found = self._replant_planner()
        if found is None:
            return []
        planner, steep = found
        terrain, r = self.terrain_for_recovery, self.robot.foot_radius
        snap = self.config.reflex.replant_snap_m
        return replant_targets(planner, terrain, measured.feet, r, snap, steep, min_m)

    def _replant_planner(self) -> tuple[Any, np.ndarray] | None:
        """The footstep planner re-planting uses and the too-steep cells; None when it is off.

        Off unless ``reflex.replant_max_slope`` is below 90° and
        ``reflex.replant_snap_m`` positive, and the source has a planner.
        The too-steep cells' mask is built on first use.
        """
        cfg = self.config.reflex
        planner = getattr(self.source, "planner", None)
        if cfg.replant_max_slope >= 0.5 * np.pi or cfg.replant_snap_m <= 0 or planner is None:
            return None
        if self._steep is None:
            self._steep = steep_footholds(
                self.terrain_for_recovery, self.robot.foot_radius, cfg.replant_max_slope
            )
        return planner, self._steep

    def _recovery_slide(
        self, measured: MeasuredState, desired: DesiredState, now: float
    ) -> int | None:
        """The foot to put down again if one slides during the recovery, else None.

        See ``reflex.recovery_slide_m``: a foot the recovery holds on its
        foothold (desired there and supporting) more than that from it
        for ``reflex.persist_s``, while the other three bear load.
        """
        cfg = self.config.reflex
        if cfg.recovery_slide_m <= 0 or self._slides >= cfg.recovery_slides:
            return None
        leg = sliding_leg(
            measured,
            desired,
            self._recovery_footholds,
            cfg.recovery_slide_m,
            _LOADED_N,
            cfg.recovery_slide_bearing,
            # Chattering feet (a rock face) bear every few ticks.
            recently_loaded(self._last_loaded, now, _SLIDE_LOADED_WINDOW_S)
            if cfg.recovery_slide_bearing < 3
            else None,
            cfg.recovery_slide_drop_m,
        )
        if leg is None:
            self._slide_since = None
            return None
        if self._slide_since is None:
            self._slide_since = now
        if now - self._slide_since < cfg.persist_s - 1e-12:
            return None
        self._slides += 1
        return leg

    def _replant(self, measured: MeasuredState, now: float) -> bool:
        """Queue a settled robot's step off a face onto a foothold; whether one was queued.

        See ``reflex.replant_max_slope``: the first leg (canonical order) not
        yet re-planted in this recovery whose foot stands on a face or off
        the footholds, if the other three can hold the trunk.
        """
        cfg = self.config.reflex
        for leg, target in self._replant_targets(measured, cfg.replant_min_m):
            if leg in self._replanted:
                continue
            self._replanted.add(leg)
            segments = self._replant_motion(measured, leg, target, now)
            if segments is None:
                continue
            if not self._replant_certified(measured, leg, target):
                self.log.event(
                    now,
                    "replant_refused",
                    leg=LEG_NAMES[leg],
                    foot=measured.feet[leg],
                    target=target,
                    reason="no pose certificate for the stance it makes",
                )
                continue
            self._settle_deadline = None
            for segment in segments:
                self.buffer.append(segment)
            self.log.event(
                now, "replant", leg=LEG_NAMES[leg], foot=measured.feet[leg], target=target
            )
            return True
        return False

    def _recentre(
        self, measured: MeasuredState, goal: np.ndarray, now: float, charged: float = 0.0
    ) -> bool:
        """Queue a step of a foot toward its nominal place after a failed re-plan; whether queued.

        See ``reflex.recentre_steps``: the feet farthest from their nominal
        places under the measured trunk (its position and heading) first,
        each to the nearest foothold toward that place
        (:func:`~roughwalk.sim.foothold_snap.footholds_toward`) that the
        other three can hold the trunk for and from which the source's
        planner finds a plan (from the measured trunk, the leg due to lift
        first, as the re-plan asks; the plan is asked again by that re-plan);
        :data:`_RECENTRE_TARGETS` footholds a foot, :data:`_RECENTRE_TRIES` plans at most.
        The robot first stands for the failed re-plan's ``charged`` time [s]
        and the charged wall time of these plans, then steps (the stand and
        the step count as the reflex's time, the recovery's).
        """
        cfg = self.config.reflex
        planner = getattr(self.source, "planner", None)
        if self._recentred >= cfg.recentre_steps or planner is None:
            return False
        rot = quat_to_matrix(measured.base_quat)
        heading = float(np.arctan2(rot[1, 0], rot[0, 0]))
        x, y = (float(v) for v in measured.base_pos[:2])
        nominal = nominal_feet_xy(self.robot, (x, y, heading))
        away = np.linalg.norm(np.asarray(measured.feet, dtype=float)[:, :2] - nominal, axis=1)
        # As the re-plan asks (``reflex.replan_from_trunk``): certified from the measured trunk.
        trunk = (
            (measured.base_pos.copy(), measured.base_quat.copy()) if cfg.replan_from_trunk else None
        )
        # The leg the re-plan after the step lifts first, as it will ask.
        due = getattr(self, "_reflex_next_leg", None)
        tries = 0
        began = time.perf_counter()
        for leg in np.argsort(-away, kind="stable"):
            leg = int(leg)
            targets = footholds_toward(
                planner,
                self.terrain_for_recovery,
                measured.feet[leg],
                nominal[leg],
                cfg.recentre_radius_m,
                self.robot.foot_radius,
                front=leg < 2,
            )
            for target in targets[:_RECENTRE_TARGETS]:
                if tries >= _RECENTRE_TRIES:
                    return False
                segments = self._replant_motion(measured, leg, target, now)
                if segments is None:
                    continue
                feet = np.array(measured.feet, dtype=float)
                feet[leg] = target
                tries += 1
                start = PlanStart(feet=feet, next_leg=due, trunk=trunk)
                attempt = self.source.plan(start, goal, cfg.replan_budget_s)
                if not attempt.ok:
                    continue
                self._recentred += 1
                self._settle_deadline = None
                wait = charged + self._charge(time.perf_counter() - began)
                if wait > 0:
                    self.buffer.append(
                        hold_segment(self._standing(measured), wait, now, "recovery")
                    )
                for segment in segments:
                    self.buffer.append(segment)
                self.log.event(
                    now,
                    "recentre",
                    leg=LEG_NAMES[leg],
                    foot=measured.feet[leg],
                    target=target,
                    nominal=nominal[leg],
                    plans_asked=tries,
                    charged_s=wait,
                )
                return True
        return False

    def _settled(self, measured: MeasuredState, now: float) -> bool:
        """Whether the recovered robot stands still on four feet, or has held long enough.

        The recovery's hold is timed (``reflex.settle_s``), but a push can
        leave the trunk rocking from its left feet to its right ones after
        it; a re-plan whose first step lifts a foot then tips the robot
        over and fires the next reflex. So the hold goes on, up to
        ``reflex.settle_max_s`` more, until the trunk turns slower than
        ``reflex.settled_rate_rad_s`` with ``reflex.settled_loaded_feet``
        feet bearing load.
        """
        cfg = self.config.reflex
        if self._settle_deadline is None:
            self._settle_deadline = now + cfg.settle_max_s
        if now >= self._settle_deadline - 1e-9:
            return True
        return settled(measured, cfg.settled_rate_rad_s, cfg.settled_loaded_feet, _LOADED_N)

    def _catch(
        self, q_cmd: np.ndarray, desired: DesiredState, measured: MeasuredState
    ) -> np.ndarray:
        """Aim the feet the reflex puts down at their world footholds, from the measured trunk.

        So they land where planned however the trunk is tipping.
        """
        lifted = ~desired.support
        if not np.any(lifted):
            return q_cmd
        q, _ = self.robot.inverse_kinematics(desired.feet, measured.base_pos, measured.base_quat)
        joints = self._leg_joints[lifted].ravel()
        out = q_cmd.copy()
        out[joints] = q[joints]
        return out

    def _standing(self, measured: MeasuredState) -> DesiredState:
        """The measured trunk pose over the measured feet, all four down, as a desired state."""
        rpy = matrix_to_rpy(measured.rotation)
        segment = pose_segment(
            self.robot,
            np.repeat(measured.base_pos[None], 2, axis=0),
            np.repeat(rpy[None], 2, axis=0),
            np.repeat(measured.feet[None], 2, axis=0),
            np.ones(4, dtype=bool),
            1e-3,
            "hold",
            measured.time,
        )
        return segment.last()

    @property
    def terrain_for_recovery(self) -> Terrain:
        """The robot puts its feet down on the terrain it believes in (the planner's)."""
        return self.planner_terrain

    def _replan(
        self, measured: MeasuredState, holding: DesiredState, goal: np.ndarray, now: float
    ) -> tuple[bool, float]:
        """Re-plan from the feet where they stand; queue a blend and the new plan's first step.

        Returns whether a plan came, and the simulated time [s] charged.
        """
        reflex = self.config.reflex
        budget = reflex.replan_budget_s
        trunk = (measured.base_pos.copy(), measured.base_quat.copy())
        start = PlanStart(
            feet=measured.feet.copy(),
            next_leg=getattr(self, "_reflex_next_leg", None),
            trunk=trunk if reflex.replan_from_trunk else None,
        )
        plan, attempt, wall = self._make_plan(start, goal, budget)
        start_from = "measured"
        if plan is None and reflex.replan_from_trunk and start.next_leg is not None:
            # The leg due to lift may be the one no stance can keep where it
            # stands (a shin against a rock): let another step first.
            for leg in later_legs(start.next_leg):
                tried_start = PlanStart(feet=start.feet, next_leg=leg, trunk=start.trunk)
                tried_plan, tried, wall2 = self._make_plan(tried_start, goal, budget)
                wall += wall2
                if tried_plan is not None:
                    plan, attempt, start = tried_plan, tried, tried_start
                    start_from = f"measured, {LEG_NAMES[leg]} first"
                    break
        # No start where the feet stand: no certificate, or (from the measured
        # trunk, whose certificate may keep only the start clearance) no step
        # out of it. Then the planned footholds, then the nudged stances.
        refused = plan is None and (
            "pose certificate" in attempt.reason
            or (start.trunk is not None and attempt.status == "infeasible")
        )
        planned = getattr(self, "_reflex_planned_feet", None)
        if (
            refused
            and planned is not None
            and float(np.max(np.linalg.norm((measured.feet - planned)[:, :2], axis=1)))
            <= _NEAR_PLAN_M
        ):
            # Feet settled just off their planned footholds (a rock's edge) where
            # no certificate exists: plan from the footholds the plan had,
            # which did; the integrators absorb the difference.
            start = PlanStart(feet=planned.copy(), next_leg=start.next_leg)
            plan, attempt, wall2 = self._make_plan(start, goal, budget)
            wall += wall2
            start_from = "planned"
        nudge = self.config.reflex.replan_nudge_m
        if plan is None and (refused or "pose certificate" in attempt.reason) and nudge > 0:
            # No certificate where the feet stand nor where they were headed
            # (board Y, sloped rocks seed 1: a foot out of reach): plan from
            # the nearest stance with one foot moved that has one. (That run's
            # first re-plan starts from RF moved 1 cm; its second finds no
            # stance within 5 cm, nor at the recovery's own footholds.)
            start_from = f"none within {100 * nudge:.0f} cm"
            due = start.next_leg
            # With replan_nudge_any_leg each nudged stance may start with any
            # leg, as the measured one may (replan_from_trunk): the stance a
            # slid foot leaves can be certified while the leg due to lift has
            # no step out of it (board AE, bench large rocks seed 4).
            firsts = (
                [due, *later_legs(due)]
                if self.config.reflex.replan_nudge_any_leg and due is not None
                else [due]
            )
            candidates = (
                (feet, first_leg)
                for feet in nudged_stances(measured.feet, nudge, due)
                for first_leg in firsts
            )
            for feet, first_leg in candidates:
                start = PlanStart(feet=feet, next_leg=first_leg)
                plan, tried, wall2 = self._make_plan(start, goal, budget)
                wall += wall2
                # With one leg to try, a stance certified with no plan ends the search.
                if plan is not None or (
                    len(firsts) == 1 and "pose certificate" not in tried.reason
                ):
                    attempt = tried
                    moved = np.linalg.norm((feet - measured.feet)[:, :2], axis=1)
                    leg = int(np.argmax(moved))
                    start_from = f"nudged {LEG_NAMES[leg]} {100 * moved[leg]:.0f} cm"
                    if first_leg is not None and first_leg != due:
                        start_from += f", {LEG_NAMES[first_leg]} first"
                    break
        first = None
        if plan is not None:
            first, wall2 = self._next_step(plan)
            wall += wall2
        charged = self._charge(wall)
        next_leg = start.next_leg
        self.log.event(
            now,
            "replan",
            status=attempt.status,
            wall_s=wall,
            charged_s=charged,
            next_leg=LEG_NAMES[next_leg] if next_leg is not None else None,
            start=start_from,
            relaxed=attempt.relaxed,
            start_clearance_m=attempt.start_clearance_m if plan is not None else None,
            reason=attempt.reason if plan is None else "",
        )
        if plan is None:
            return False, charged
        self._plan = plan
        self._step_index = 0
        if first is None:
            plan.exhausted = True
            return True, charged
        segment = Segment.from_footstep(first)
        ready = now + charged
        # The recovery's pose is not always reached (a foot slid, the trunk
        # twisted): hold and blend from where the robot stands, as the plan
        # starts from its measured feet, or the first tick of the blend is
        # already an orientation error and fires a reflex.
        holding = self._standing(measured)
        # The integrators and the CoP shift corrected the recovery's pose; the
        # new one is where the robot stands, so their corrections start anew
        # (kept, they would move the feet off the measured stance at once).
        self.integrator.reset()
        self.stabilizer.reset()
        self.touchdown.reset()
        self.buffer.append(hold_segment(holding, max(charged, 1e-3), now, kind="hold"))
        self.buffer.append(blend_segment(self.robot, holding, segment.sample(0.0), 0.2, ready))
        self.buffer.append(segment.with_ready_at(ready))
        return True, charged
