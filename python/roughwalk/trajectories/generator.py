"""From footsteps to full-body trajectories, one footstep at a time (Zucker 2011, §5).

For each footstep: estimate its timing from the joint velocity limits (with
``timing.measured_speed``, then shorten it until the initial trajectory's
fastest joints reach that share of their limits), build
the initial trajectory (ZMP preview over a window of the next footsteps,
certificate splines, swing spline, IK) and, where its swing already outruns
a joint's velocity limit, lengthen it by that excess at once; run CHOMP as
coordinate descent (trunk, then swing leg) until the trajectory is valid or
the iterations run out, check it at the control rate, and if it still
collides or breaks a velocity limit, lengthen the step, regenerate and
restart. The first attempt
uses the shortcut ZMP (footnote 2) where it is safe, and the restarts fall
back to the certificate. A step that stays infeasible is marked and handed on
("in our system we chose instead to optimistically execute these
known-infeasible trajectories", §5.3).
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.body_keyframes import BodyKeyframe
from roughwalk.trajectories.body_pass import BACKENDS, BodyPass
from roughwalk.trajectories.chomp import Chomp, ChompStatus
from roughwalk.trajectories.config import TrajectoryConfig
from roughwalk.trajectories.costs.obstacle import ObstacleCost
from roughwalk.trajectories.euler import rpy_to_matrix
from roughwalk.trajectories.footstep_trajectory import (
    FootstepTrajectory,
    phase_speed_ratios,
    resample_footstep,
    swing_com_margins,
    swing_speed_ratio,
)
from roughwalk.trajectories.initial_trajectory import (
    FootstepState,
    StartState,
    build_initial_trajectory,
)
from roughwalk.trajectories.step_report import capsule_clearances
from roughwalk.trajectories.step_sequence import StepSequence
from roughwalk.trajectories.swing_pass import SwingPass
from roughwalk.trajectories.swing_spline import SwingSpline
from roughwalk.trajectories.timing import StepTiming, step_timing
from roughwalk.trajectories.whole_body import WholeBody
from roughwalk.trajectories.zmp_preview import ZmpPreviewController
from roughwalk.trajectories.zmp_reference import (
    ZmpReference,
    closest_point_in_triangle,
    shortcut_anchor,
)

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.terrain import Terrain

__all__ = ["FootstepTrajectoryGenerator", "OptimizationOutcome", "PreparedPlan"]

EXIT_MARGIN_FACTOR = 2.0
"""Where each swing leaves the ZMP, in multiples of the support term's margin inside
its triangle: the preview controller lags its reference, and the ZMP must still be
inside when the foot lands."""


RETIME_MARGIN = 1.02
"""A swing whose initial trajectory breaks a velocity limit by the factor r is
lengthened by r times this before CHOMP: the trunk's preview motion does not
scale exactly with the step's duration."""

RETIME_LIMIT = 3
"""Most re-timings of one initial trajectory before CHOMP is run on it anyway."""

COM_LIMIT = 4
"""Most rebuilds of one initial trajectory that keep its CoM inside the swing's
triangle (``zmp.com_margin``)."""

COM_SHIFT_FACTOR = 1.25
"""Each rebuild for a CoM short of its margin at lift-off lengthens the shift by this."""

SHIFT_SAMPLES = 21
"""Trunk poses along a shift at which the supporting legs' IK is solved to time it:
near the edge of a leg's reach its joints turn several times faster per metre
of trunk motion than on average, so the ends alone under-time the shift."""


@dataclass(frozen=True)
class PreparedPlan:
    """A plan read for generation.

    Its steps, nominal timings (§5.2), the shortcut pose of each step or None
    (footnote 2), the ZMP anchors in use, and the start.
    """

    sequence: StepSequence
    timings: list[StepTiming]
    shortcuts: list[BodyKeyframe | None]
    anchors: NDArray[np.float64]
    start: StartState
    nominal: list[StepTiming] | None = None
    """The nominal timings where ``timings`` are fitted ones (``timing.measured_speed``)."""

    def nominal_timing(self, k: int) -> StepTiming:
        """Step k's nominal timing (§5.2), before any fitting."""
        return (self.nominal if self.nominal is not None else self.timings)[k]


class OptimizationOutcome:
    """How CHOMP went on one attempt: iterations used and the final status."""

    def __init__(self, iterations: int, status: ChompStatus) -> None:
        self.iterations = iterations
        self.status = status


class FootstepTrajectoryGenerator:
    """Makes :class:`FootstepTrajectory` objects for the footsteps of plans on one terrain.

    Parameters
    ----------
    robot:
        The robot.
    terrain:
        The terrain (for the swing spline's terrain scan and, unless ``sdf``
        is given, to build the signed distance field).
    sdf:
        A prebuilt :class:`~roughwalk.terrain.SignedDistanceField` of ``terrain``.
    config:
        Settings (default :class:`TrajectoryConfig`).
    backend:
        Who evaluates CHOMP's passes: ``"auto"`` (the Rust core whenever the
        SDF is the compiled one), ``"rust"`` or ``"python"`` (the numpy reference).
    """

    def __init__(
        self,
        robot: Robot,
        terrain: Terrain | None,
        *,
        sdf: Any = None,
        config: TrajectoryConfig | None = None,
        backend: str = "auto",
    ) -> None:
        self.config = config if config is not None else TrajectoryConfig()
        if sdf is None and terrain is None:
            raise InvalidArgumentError("a terrain or its signed distance field is needed")
        self.robot = robot
        self.terrain = terrain if terrain is not None else sdf.terrain
        self._sdf = sdf
        self.wb = WholeBody(robot, point_spacing=self.config.chomp.point_spacing)
        self.dt = 1.0 / self.config.chomp.rate_hz
        if backend not in BACKENDS:
            raise InvalidArgumentError(
                f"unknown CHOMP pass backend {backend!r}; known: {', '.join(BACKENDS)}"
            )
        self.backend = backend
        self._controllers: dict[int, ZmpPreviewController] = {}

    @property
    def sdf(self) -> Any:
        """The terrain's signed distance field (built on first use)."""
        if self._sdf is None:
            self._sdf = self.terrain.sdf(self.config.sdf_resolution)
        return self._sdf

    # ---- pieces -------------------------------------------------------------------

    def sequence(self, plan: Any) -> StepSequence:
        """Read a plan (see :func:`~roughwalk.trajectories.step_sequence.plan_fields`)."""
        if isinstance(plan, StepSequence):
            return plan
        return StepSequence.from_plan(
            plan,
            self.wb,
            self.config.zmp.support_margin,
            terrain=self.terrain,
            foot_centre=self.config.foot_centre,
        )

    @property
    def min_support_share(self) -> float:
        """``zmp.min_support_load`` as a share of the robot's weight."""
        z = self.config.zmp
        return z.min_support_load / (self.wb.mass * z.gravity)

    def controller(self, com_height: float) -> ZmpPreviewController:
        """The preview controller for a CoM height [m] (cached per millimetre)."""
        key = max(int(round(com_height * 1000)), 1)
        if key not in self._controllers:
            z = self.config.zmp
            self._controllers[key] = ZmpPreviewController(
                key / 1000.0,
                self.dt,
                tracking_weight=z.tracking_weight,
                jerk_weight=z.jerk_weight,
                gravity=z.gravity,
            )
        return self._controllers[key]

    def nominal_timings(
        self,
        seq: StepSequence,
        travels: Sequence[float] | None = None,
        anchors: NDArray[np.float64] | None = None,
    ) -> list[StepTiming]:
        """Each footstep's timing before any restart (§5.2), in whole CHOMP samples.

        ``travels`` (S,) [m]: how far each step's shift moves the ZMP
        (:meth:`zmp_travels`), for the shift's floor; None: ``min_shift_s``.
        ``anchors`` as in :class:`PreparedPlan`: with ``timing.swing_trunk``
        "moving", where each swing carries the ZMP (:meth:`zmp_exit`).
        """
        out = []
        previous = seq.initial_pose
        for k, step in enumerate(seq.steps):
            pose = step.swing_pose
            shift = self._shift_path(previous, pose, step.stance_before)
            spline = SwingSpline.plan(
                step.start,
                step.target,
                1.0,
                self.config.swing,
                self.terrain,
                self.robot.foot_radius,
                leg_angles=pose.leg_angles(self.wb, step.leg),
                velocity_limit=self.wb.velocity_limit[step.leg],
                leg_feet=pose.leg_feet(self.wb, step.leg),
                joint_range=(self.wb.lower[step.leg], self.wb.upper[step.leg]),
            )
            path = spline.position(np.linspace(0.0, 1.0, 41))
            trunks = {
                "still": ("still",),
                "landing": ("landing",),
                "shorter": ("still", "landing"),
                "moving": ("still", "landing", "moving"),
            }[self.config.timing.swing_trunk]
            carry = np.zeros(2)
            if anchors is not None and k + 2 < len(anchors):
                carry = self.zmp_exit(step.support_triangle, anchors[k + 2]) - anchors[k + 1]
            timings = []
            for trunk in trunks:
                legs_b = self._swing_legs_in_body(pose, step.end_pose, path, step.leg, trunk, carry)
                q, _ = self.wb.inverse_kinematics(legs_b)
                timings.append(
                    step_timing(
                        shift,
                        q[:, step.leg],
                        self.wb.velocity_limit,
                        self.config.timing,
                        step.leg,
                        settle=k == len(seq.steps) - 1,
                        zmp_travel=None if travels is None else travels[k],
                        from_rest=k == 0,
                    )
                )
            timing = min(timings, key=lambda t: t.swing_s)
            out.append(timing.quantized(self.dt))
            previous = pose
        return out

    def _shift_path(
        self,
        previous: BodyKeyframe,
        pose: BodyKeyframe,
        feet: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """Joint angles (SHIFT_SAMPLES, 4, 3) [rad] along a shift, held on ``feet`` (4, 3) [m].

        The trunk moves in a straight line (position and roll–pitch–yaw)
        from ``previous`` to ``pose``, uniform in trunk progress, so
        :func:`min_profile_time` sees the peak joint rate per metre of the
        shift, not only its mean (the ends).
        """
        s = np.linspace(0.0, 1.0, SHIFT_SAMPLES)[:, None]
        base = (1.0 - s) * previous.base_pos + s * pose.base_pos
        rpy = (1.0 - s) * previous.rpy + s * pose.rpy
        rot = rpy_to_matrix(rpy)
        legs_b = np.einsum(
            "kij,kli->klj", rot, np.asarray(feet, dtype=float)[None] - base[:, None, :]
        )
        q, _ = self.wb.inverse_kinematics(legs_b)
        return np.asarray(q, dtype=float)

    def _swing_legs_in_body(
        self,
        pose: BodyKeyframe,
        end_pose: BodyKeyframe,
        path: NDArray[np.float64],
        leg: int,
        trunk: str,
        carry: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """The four feet (K, 4, 3) in the trunk frame along a swing foot path (K, 3) [m].

        ``trunk`` "still": the trunk holds the swing pose. "landing": its
        height and tilt go on to the landing certificate's (``end_pose``) as
        the initial trajectory's do (a smoothstep over the swing), its x–y
        held (the ZMP preview moves it less than the certificates differ).
        "moving": as "landing", and its x–y moves on by ``carry`` (2,) [m]
        to where the swing's ZMP reference goes (its exit, three quarters
        into the swing): a foot swinging forward under a trunk that moves
        forward turns its joints less.
        The supporting feet's rows are only for the IK.
        """
        k = len(path)
        base = np.repeat(pose.base_pos[None], k, axis=0)
        rotation = np.repeat(pose.rotation[None], k, axis=0)
        if trunk == "moving" and carry is not None:
            u = np.clip(np.linspace(0.0, 1.0, k) / 0.75, 0.0, 1.0)
            base[:, :2] += (u * u * (3.0 - 2.0 * u))[:, None] * np.asarray(carry)[None, :2]
        if trunk in ("landing", "moving"):
            u = np.linspace(0.0, 1.0, k)
            u = u * u * (3.0 - 2.0 * u)
            base[:, 2] += u * (end_pose.base_pos[2] - pose.base_pos[2])
            turn = (end_pose.rpy - pose.rpy + np.pi) % (2.0 * np.pi) - np.pi
            rotation = rpy_to_matrix(pose.rpy[None] + u[:, None] * turn[None])
        feet = np.repeat(pose.feet[None], k, axis=0)
        feet[:, leg] = path
        return np.einsum("kfi,kij->kfj", feet - base[:, None, :], rotation)

    def zmp_exit(
        self, triangle: NDArray[np.float64], toward: NDArray[np.float64], inset: float = 0.0
    ) -> NDArray[np.float64]:
        """Where a swing on the support ``triangle`` leaves the ZMP, heading for ``toward`` (2,).

        As far toward the next anchor as its triangle allows with twice the
        margin the support term asks for: with the support term's own
        margin, the ZMP ended up to 1.6 mm outside the triangle just before
        touchdown on LittleDog board AD, where the trunk is held and CHOMP
        cannot pull it back. ``inset`` [m] moves it that much farther in
        (``zmp.com_margin``).
        """
        margin = EXIT_MARGIN_FACTOR * self.config.chomp.zmp_margin + inset
        return closest_point_in_triangle(toward, triangle, margin, self.min_support_share)

    def zmp_travels(self, seq: StepSequence, anchors: NDArray[np.float64]) -> list[float]:
        """How far [m] each step's shift moves the ZMP: from the last swing's exit to its anchor.

        ``anchors`` as in :class:`PreparedPlan` (the start, then one per step).
        """
        out = [float(np.linalg.norm(anchors[1] - anchors[0]))]
        steps = seq.steps
        for k in range(1, len(steps)):
            left = self.zmp_exit(steps[k - 1].support_triangle, anchors[k + 1])
            out.append(float(np.linalg.norm(anchors[k + 1] - left)))
        return out

    def shortcut_poses(self, seq: StepSequence) -> list[BodyKeyframe | None]:
        """Footnote 2: per step, the shortcut swing pose, or None where no shorter or unsafe."""
        if not self.config.zmp.shortcut:
            return [None] * len(seq)
        anchors = seq.anchors()
        out: list[BodyKeyframe | None] = []
        cm = self.wb.collision
        need = self.config.validity.min_clearance
        for k, step in enumerate(seq.steps):
            a = anchors[k + 1]
            p = shortcut_anchor(
                anchors[k],
                a,
                anchors[k + 2],
                step.support_triangle,
                self.config.zmp.support_margin,
                min_share=self.min_support_share,
            )
            if float(np.linalg.norm(p - a)) < 1e-4:
                out.append(None)
                continue
            pose = step.swing_pose.translated(self.wb, np.array([p[0] - a[0], p[1] - a[1], 0.0]))
            d = capsule_clearances(
                self.wb,
                self.sdf,
                pose.q[None],
                pose.base_pos[None],
                pose.rotation[None],
            )[0]
            safe = bool(np.all(pose.reachable)) and bool(np.all(d[~cm.is_foot] >= need))
            out.append(pose if safe else None)
        return out

    # ---- one footstep ---------------------------------------------------------------

    def optimize(self, state: FootstepState) -> OptimizationOutcome:
        """CHOMP on one footstep: trunk, then swing leg, until valid or out of iterations."""
        cfg = self.config.chomp
        validity = self.config.validity
        obstacle = ObstacleCost(
            self.sdf, self.wb.points.radius, cfg.obstacle_epsilon, cfg.obstacle_weight, cfg.gradient
        )
        body_reference = state.body[1:-1].copy()
        swing_reference = state.q[state.lift_off + 1 : state.touchdown, state.step.leg].copy()
        total = 0
        status = ChompStatus.ITERATION_LIMIT
        while True:
            body = BodyPass(
                self.wb,
                state,
                obstacle,
                cfg,
                validity,
                self.config.zmp.gravity,
                body_reference,
                backend=self.backend,
            )
            chomp = Chomp(
                body.smoothness,
                body.evaluate,
                step_size=cfg.step_size,
                max_step=cfg.max_step,
                line_search=cfg.line_search,
            )
            # A zero budget still evaluates: the initial trajectory may be valid as it is.
            res = chomp.optimize(
                state.body[1:-1], min(cfg.body_iterations, cfg.max_iterations - total)
            )
            total += res.iterations
            body.apply(res.xi)
            if res.status == ChompStatus.VALID:
                return OptimizationOutcome(total, ChompStatus.VALID)
            budget = min(cfg.swing_iterations, cfg.max_iterations - total)
            if budget <= 0:
                break
            rest_feasible = body.feasible_without_leg(state.step.leg)
            # The swing pass stops once its leg is feasible even where the rest
            # is not: it cannot repair the trunk or the stance legs, and running
            # out its budget there (a supporting foot lost on the LittleDog AD
            # crawl fall-back) only delayed the next trunk pass.
            swing = SwingPass(
                self.wb,
                state,
                self.sdf,
                cfg,
                validity,
                rest_feasible=True,
                reference=swing_reference,
                backend=self.backend,
            )
            chomp = Chomp(
                swing.smoothness,
                swing.evaluate,
                step_size=cfg.step_size,
                max_step=cfg.max_step,
                line_search=cfg.line_search,
                project=swing.project,
            )
            res2 = chomp.optimize(swing.initial, budget)
            total += res2.iterations
            swing.apply(res2.xi)
            if res2.status == ChompStatus.VALID and rest_feasible:
                return OptimizationOutcome(total, ChompStatus.VALID)
            if res.iterations == 0 and res2.iterations == 0:
                status = ChompStatus.CONVERGED
                break
            if total >= cfg.max_iterations:
                break
        return OptimizationOutcome(total, status)

    def _window(
        self,
        prepared: PreparedPlan,
        k: int,
        start: StartState,
        timing: StepTiming,
        anchor: NDArray[np.float64],
        exit_inset: float = 0.0,
    ) -> tuple[NDArray[np.float64], int]:
        """ZMP reference samples over the preview window from step k, and its length N.

        ``exit_inset`` [m] moves step k's own swing exit that much farther
        inside its triangle (``zmp.com_margin``); the later steps' are as planned.
        """
        n_steps = len(prepared.sequence)
        anchors = prepared.anchors
        last = min(k + self.config.zmp.preview_steps, n_steps)
        window = [timing] + prepared.timings[k + 1 : last]
        points = [start.zmp_anchor, anchor, *anchors[k + 2 : last + 1]]
        if last == n_steps:
            points.append(anchors[n_steps + 1])
        # Each swing moves the ZMP toward the next anchor (zmp_exit).
        steps = prepared.sequence.steps
        exits = [
            self.zmp_exit(
                steps[k + j].support_triangle, points[j + 2], exit_inset if j == 0 else 0.0
            )
            if j + 2 < len(points)
            else points[j + 1]
            for j in range(len(window))
        ]
        ref = ZmpReference.through_anchors(np.array(points), window, start.time, np.array(exits))
        total = sum(t.duration_s for t in window)
        m = int(round(total / self.dt))
        samples = ref.sample(start.time + self.dt * np.arange(m + 1))
        return samples, m

    def prepare(self, plan: Any) -> PreparedPlan:
        """Read a plan and do the per-plan work: timings, shortcut poses, ZMP anchors."""
        seq = self.sequence(plan)
        shortcuts = self.shortcut_poses(seq)
        anchors = seq.anchors()
        for k, pose in enumerate(shortcuts):
            if pose is not None:
                anchors[k + 1] = pose.com[:2]
        timings = self.nominal_timings(seq, self.zmp_travels(seq, anchors), anchors)
        init = seq.initial_pose
        start = StartState(
            time=0.0,
            base_pos=init.base_pos,
            rpy=init.rpy,
            com_state=np.array([init.com[:2], [0.0, 0.0], [0.0, 0.0]]),
            com_offset=init.com_offset,
            zmp_anchor=init.com[:2].copy(),
        )
        prepared = PreparedPlan(seq, timings, shortcuts, anchors, start)
        if self.config.timing.measured_speed > 0:
            prepared = replace(prepared, timings=self.fitted_timings(prepared), nominal=timings)
        return prepared

    def initial_state(
        self,
        prepared: PreparedPlan,
        k: int,
        start: StartState,
        use_shortcut: bool = False,
        scale: float = 1.0,
        base: StepTiming | None = None,
        exit_inset: float = 0.0,
    ) -> FootstepState:
        """The initial trajectory of step k (0-based) from ``start`` (§5.2), before CHOMP.

        ``use_shortcut`` takes the footnote-2 pose where there is one;
        ``scale`` lengthens the step (a restart); ``base`` is the step's
        timing before that (default its nominal one, ``prepared.timings[k]``).
        """
        step = prepared.sequence.steps[k]
        shortcut = prepared.shortcuts[k]
        pose = shortcut if use_shortcut and shortcut is not None else step.swing_pose
        anchor = pose.com[:2].copy()
        timing = (base if base is not None else prepared.timings[k]).scaled(scale)
        # The certificate's anchor (a restart after the shortcut) can lie
        # farther from where the last swing left the ZMP than the plan's.
        travel = float(np.linalg.norm(anchor - start.zmp_anchor))
        floor = self.config.timing.shift_floor(travel)
        if self.config.timing.shift_travel_m > 0 and timing.shift_s < floor:
            timing = replace(timing, shift_s=floor)
        timing = timing.quantized(self.dt)
        reference, horizon = self._window(prepared, k, start, timing, anchor, exit_inset)
        support_z = float(np.mean(step.support_triangle[:, 2]))
        state = build_initial_trajectory(
            self.wb,
            step,
            start,
            pose,
            timing,
            self.dt,
            self.controller(float(pose.com[2]) - support_z),
            reference,
            horizon,
            self.config.swing,
            self.terrain,
            end_pose=step.end_pose,
            used_shortcut=use_shortcut and shortcut is not None,
        )
        radius = self.wb.collision.radius[
            self.wb.collision.is_foot & (self.wb.collision.leg == step.leg)
        ]
        d, _ = self.sdf.query_spheres(np.array([step.start, step.target]), np.full(2, radius[0]))
        state.contact_clearance = min(float(np.min(d)), 0.0)
        return state

    def _retimed(
        self,
        prepared: PreparedPlan,
        k: int,
        start: StartState,
        use_shortcut: bool,
        scale: float,
        stretch: float,
        base: StepTiming | None = None,
    ) -> tuple[FootstepState, float]:
        """The initial trajectory of step k, lengthened until its swing keeps the velocity limits.

        The nominal timing (§5.2) sees the swing leg under a still trunk (or
        one that only changes height and tilt, ``timing.swing_trunk``); the
        preview controller moves the trunk during the swing, and the swing leg
        can then outrun a joint's limit by up to ~20 % (LittleDog boards A, C,
        Y). CHOMP's joint-speed term rarely recovers that, and the restart
        (§5.3) came only after its whole iteration budget, twice. Measuring the
        swing's peak joint speed on the initial trajectory and stretching the
        step by the excess costs one more initial trajectory instead.
        ``base``: the step's timing before ``scale`` and the stretch (default
        its nominal one). Returns the state and the stretch factor (≥ 1)
        later attempts keep.
        """
        cfg = self.config
        nominal = base if base is not None else prepared.timings[k]
        state = self.initial_state(
            prepared, k, start, use_shortcut, 1.0, self._stretched(nominal, scale, stretch)
        )
        for _ in range(RETIME_LIMIT):
            ratio = swing_speed_ratio(state, self.wb, cfg.control_rate_hz)
            if ratio <= 1.0:
                break
            longer = stretch * ratio * RETIME_MARGIN
            timing = self._stretched(nominal, scale, longer)
            if timing.shift_s + timing.swing_s > cfg.timing.max_step_s:
                break
            stretch = longer
            state = self.initial_state(
                prepared, k, start, use_shortcut, 1.0, self._stretched(nominal, scale, stretch)
            )
        return self._com_kept(prepared, k, start, use_shortcut, state), stretch

    def _com_kept(
        self,
        prepared: PreparedPlan,
        k: int,
        start: StartState,
        use_shortcut: bool,
        state: FootstepState,
    ) -> FootstepState:
        """Step k's initial trajectory rebuilt until its CoM keeps ``zmp.com_margin`` in its swing.

        A CoM short of the margin at lift-off lengthens the shift by
        :data:`COM_SHIFT_FACTOR` (it had not yet come into the triangle); one
        short later in the swing moves the swing's ZMP exit in by the
        shortfall (it led the ZMP toward the next anchor). At most
        :data:`COM_LIMIT` rebuilds; of those whose swing keeps the joint
        speed limits, the one whose CoM comes least near the edge is
        returned (``state`` itself when it already keeps the margin or no
        rebuild does better).
        """
        cfg = self.config
        need = cfg.zmp.com_margin
        if need <= 0:
            return state
        margins = swing_com_margins(state)
        if float(margins.min()) >= need:
            return state
        best, best_low = state, float(margins.min())
        timing, inset = state.timing, 0.0
        for _ in range(COM_LIMIT):
            changed = False
            if margins[0] < need:
                longer = replace(timing, shift_s=timing.shift_s * COM_SHIFT_FACTOR)
                if longer.shift_s + longer.swing_s <= cfg.timing.max_step_s:
                    timing, changed = longer, True
            low = float(margins.min())
            if low < need and low < float(margins[0]):
                inset += need - low
                changed = True
            if not changed:
                break
            state = self.initial_state(prepared, k, start, use_shortcut, 1.0, timing, inset)
            before, margins = low, swing_com_margins(state)
            # A rebuild whose swing breaks a joint's speed limit is not kept.
            fast = swing_speed_ratio(state, self.wb, cfg.control_rate_hz) > 1.0
            if not fast and float(margins.min()) > best_low:
                best, best_low = state, float(margins.min())
            # The plan's last step has no exit to move: nothing more to gain.
            if best_low >= need or abs(float(margins.min()) - before) < 1e-9:
                break
        return best

    def _stretched(self, timing: StepTiming, scale: float, stretch: float) -> StepTiming:
        """``timing`` scaled by a restart's ``scale`` and the re-timing's ``stretch``.

        With ``timing.stretch_shift`` (the default) both phases take both
        factors, multiplied as before the option existed (``scale * stretch``,
        so that runs repeat bit for bit); without it the shift takes ``scale``
        alone.
        """
        if self.config.timing.stretch_shift:
            return timing.scaled(scale * stretch)
        return replace(timing, swing_s=timing.swing_s * stretch).scaled(scale)

    def fitted_timing(
        self, prepared: PreparedPlan, k: int, start: StartState, use_shortcut: bool
    ) -> tuple[StepTiming, FootstepState | None]:
        """Step k's timing shortened until its fastest joints reach ``timing.measured_speed``.

        The nominal timing (§5.2) is an estimate made before the trunk's
        path is known: the swing under a still or simply moving trunk, the
        shift along a straight trunk path between certificates, on which a
        supporting leg can pass the edge of its reach. On the LittleDog demo
        course its steps reach only 0.72–0.91 of the limits in the swing and
        0.02–0.17 in the shift (some shifts of 0.26–0.38 s). Each phase is
        measured on the initial trajectory (:func:`phase_speed_ratios`:
        every joint) and scaled by measured / target, never below its floors
        (``min_swing_s``; the shift's :meth:`~TimingConfig.shift_floor` and
        ``first_shift_s``), never above the nominal timing; the trunk's
        preview motion changes with the durations, so this repeats up to
        :data:`RETIME_LIMIT` times. Returns the timing and the initial
        trajectory built with it (None where nothing was measured: the
        option is off).
        """
        cfg = self.config.timing
        timing = prepared.nominal_timing(k)
        if cfg.measured_speed <= 0:
            return timing, None
        step = prepared.sequence.steps[k]
        shortcut = prepared.shortcuts[k]
        pose = shortcut if use_shortcut and shortcut is not None else step.swing_pose
        travel = float(np.linalg.norm(pose.com[:2] - start.zmp_anchor))
        shift_floor = cfg.shift_floor(travel)
        if k == 0:
            shift_floor = max(shift_floor, cfg.first_shift_s)
        state = self.initial_state(prepared, k, start, use_shortcut, 1.0, timing)
        for _ in range(RETIME_LIMIT):
            shift_ratio, swing_ratio = phase_speed_ratios(
                state, self.wb, self.config.control_rate_hz
            )
            fitted = replace(
                timing,
                shift_s=min(
                    timing.shift_s,
                    max(shift_floor, timing.shift_s * shift_ratio / cfg.measured_speed),
                ),
                swing_s=min(
                    timing.swing_s,
                    max(cfg.min_swing_s, timing.swing_s * swing_ratio / cfg.measured_speed),
                ),
            ).quantized(self.dt)
            if fitted == timing.quantized(self.dt):
                break
            timing = fitted
            state = self.initial_state(prepared, k, start, use_shortcut, 1.0, timing)
        return timing, state

    def fitted_timings(self, prepared: PreparedPlan) -> list[StepTiming]:
        """Every step's :meth:`fitted_timing`, chaining the initial trajectories (no CHOMP).

        The preview window of step k plans the trunk for the next steps'
        timings: with their nominal ones it moves the trunk for a slow next
        shift, and a fitted shift 0.3 s shorter then carried the ZMP out of
        the support polygon (the demo course's step 19). A first pass over
        the plan with the fitted timings of the steps before gives each
        window the shorter timings it will meet.
        """
        timings = list(prepared.timings)
        draft = replace(prepared, timings=timings)
        start = prepared.start
        for k in range(len(prepared.sequence)):
            use_shortcut = prepared.shortcuts[k] is not None
            timings[k], state = self.fitted_timing(draft, k, start, use_shortcut)
            if state is None:
                state = self.initial_state(draft, k, start, use_shortcut, 1.0, timings[k])
            start = next_start(state)
        return timings

    def _worth_restarting(
        self,
        result: FootstepTrajectory,
        previous: FootstepTrajectory | None,
        was_shortcut: bool,
        longest_stretch: float,
    ) -> bool:
        """Whether another attempt may help (§5.3 restarts on collisions and velocity limits).

        After the shortcut the certificate is always tried. A longer step is
        tried only while the last one collided or broke a velocity limit, and
        made progress on that over the attempt before (clearance up by 0.5 mm
        or the velocity margin up), so hopeless steps are handed on early;
        never when the samples CHOMP cannot move were at fault, nor for a
        joint speed more than ``longest_stretch`` (what the remaining restarts
        can lengthen the step by) times its limit: that is a jump (an IK
        branch switching where a supporting foot is lost), not a speed, and
        no duration brings it under the limit.
        """
        r = result.report
        if was_shortcut:
            return True
        if r.chomp_status == ChompStatus.FIXED_INFEASIBLE.value:
            return False
        if r.collision_free and r.velocity_limits_ok:
            return False
        if r.collision_free:
            qd = self.robot.to_canonical(result.qd).reshape(-1, 12)
            peak = float(np.max(np.abs(qd) / self.wb.velocity_limit.reshape(12)))
            if peak > longest_stretch:
                return False
        if previous is None or previous.report.used_shortcut:
            return True
        p = previous.report
        clear_now = min(r.min_clearance_m, r.swing_foot_clearance_m)
        clear_before = min(p.min_clearance_m, p.swing_foot_clearance_m)
        return bool(
            clear_now > clear_before + 5e-4
            or (not r.velocity_limits_ok and r.velocity_margin_rad_s > p.velocity_margin_rad_s)
        )

    def _attempts(
        self,
        prepared: PreparedPlan,
        k: int,
        start: StartState,
        base: StepTiming,
        began: float,
    ) -> tuple[FootstepTrajectory, FootstepState]:
        """Step k's attempts from the timing ``base``; the last attempt's result and state.

        The shortcut first where it exists, then the certificate, then longer
        steps (§5.3).
        """
        cfg = self.config
        factor = cfg.chomp.restart_duration_factor
        plans: list[tuple[bool, float]] = []
        if prepared.shortcuts[k] is not None:
            plans.append((True, 1.0))
        while len(plans) < cfg.chomp.max_restarts + 1:
            n_cert = sum(1 for s, _ in plans if not s)
            plans.append((False, factor**n_cert))
        result: FootstepTrajectory | None = None
        previous: FootstepTrajectory | None = None
        state: FootstepState | None = None
        stretch = 1.0
        for attempt, (use_shortcut, scale) in enumerate(plans, start=1):
            timing = self._stretched(base, scale, stretch)
            if timing.shift_s + timing.swing_s > cfg.timing.max_step_s and attempt > 1:
                break
            state, stretch = self._retimed(prepared, k, start, use_shortcut, scale, stretch, base)
            initial = capsule_clearances(
                self.wb, self.sdf, state.q, state.body[:, :3], state.rotation
            )
            body_clear = initial[:, ~self.wb.collision.is_foot]
            initial_min = float(body_clear.min())
            fixed = [0, state.lift_off, state.touchdown, state.n_samples - 1]
            if not (
                np.all(state.reached[fixed] | ~state.support[fixed])
                and body_clear[fixed].min() >= cfg.validity.min_clearance
            ):
                # No update can move these samples: hand the step on untouched.
                outcome = OptimizationOutcome(0, ChompStatus.FIXED_INFEASIBLE)
            else:
                outcome = self.optimize(state)
            result = resample_footstep(
                state,
                self.wb,
                self.sdf,
                cfg,
                optimize_ms=(time.perf_counter() - began) * 1000.0,
                attempts=attempt,
                iterations=outcome.iterations,
                initial_min_clearance=initial_min,
                chomp_status=outcome.status.value,
            )
            later = [s for _, s in plans[attempt:]]
            longest = min(
                max(later, default=scale) / scale,
                cfg.timing.max_step_s / (timing.shift_s + timing.swing_s),
            )
            if result.valid or not self._worth_restarting(result, previous, use_shortcut, longest):
                break
            previous = result
        assert result is not None and state is not None
        return result, state

    def iter_steps(self, plan: Any) -> Iterator[FootstepTrajectory]:
        """Yield the footsteps' trajectories in order, each as soon as it is ready.

        A step whose timing :meth:`fitted_timing` shortened and which ends
        invalid is made again with its nominal timing (the shorter shift can
        carry the ZMP out of the support polygon, the faster swing into
        the terrain); the first valid of the two is taken, else the nominal one.
        """
        prepared = plan if isinstance(plan, PreparedPlan) else self.prepare(plan)
        start = prepared.start
        for k in range(len(prepared.sequence)):
            began = time.perf_counter()
            first = prepared.shortcuts[k] is not None
            fitted, _ = self.fitted_timing(prepared, k, start, first)
            result, state = self._attempts(prepared, k, start, fitted, began)
            nominal = prepared.nominal_timing(k).quantized(self.dt)
            if not result.valid and fitted != nominal:
                result, state = self._attempts(prepared, k, start, nominal, began)
            fitted_q = fitted.quantized(self.dt)
            fitted_report = replace(
                result.report, fitted_shift_s=fitted_q.shift_s, fitted_swing_s=fitted_q.swing_s
            )
            yield replace(result, report=fitted_report)
            start = next_start(state)


def next_start(state: FootstepState) -> StartState:
    """Where the footstep after ``state`` starts: its last sample and ZMP anchor.

    The next shift starts where this step left the ZMP reference.
    """
    return StartState(
        time=float(state.times[-1]),
        base_pos=state.body[-1, :3].copy(),
        rpy=state.body[-1, 3:].copy(),
        com_state=state.preview.final_state,
        com_offset=state.com_offset[-1].copy(),
        zmp_anchor=np.asarray(state.zmp_reference[-1], dtype=float).copy(),
    )
