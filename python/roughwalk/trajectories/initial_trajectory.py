"""The initial whole-body trajectory of one footstep (Zucker 2011, §5.2).

The CoM comes from the ZMP preview controller, the trunk's height and
orientation (and the CoM's offset from the trunk) from splines between the
keyframe poses, the swing foot from its spline, and every leg's joint angles
from IK; all sampled at CHOMP's fixed rate. "Note that although the
trajectory satisfies the 2D dynamic stability criteria, it may be infeasible
in other respects: there could be kinematic reachability issues, or
collisions against the terrain." CHOMP corrects those next.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk import _core
from roughwalk.trajectories.body_keyframes import BodyKeyframe
from roughwalk.trajectories.body_spline import BodySpline
from roughwalk.trajectories.config import SwingConfig
from roughwalk.trajectories.euler import matrix_to_rpy, rpy_to_matrix, skew
from roughwalk.trajectories.step_sequence import StepSpec
from roughwalk.trajectories.support_polygon import convex_polygon
from roughwalk.trajectories.swing_spline import LegAngles, LegFeet, SwingSpline
from roughwalk.trajectories.timing import StepTiming
from roughwalk.trajectories.whole_body import WholeBody
from roughwalk.trajectories.zmp_preview import PreviewRun, ZmpPreviewController

if TYPE_CHECKING:
    from roughwalk.terrain.terrain import Terrain

__all__ = [
    "SETTLE",
    "SHIFT",
    "SWING",
    "FootstepState",
    "StartState",
    "build_initial_trajectory",
    "reach_by_height_and_tilt_reference",
]

SHIFT, SWING, SETTLE = 0, 1, 2


@dataclass(frozen=True)
class StartState:
    """Where a footstep starts: time [s], trunk pose, CoM state, and the ZMP anchor it holds.

    ``com_state`` (3, 2) is the preview controller's CoM position, velocity
    and acceleration per horizontal axis; ``com_offset`` (3,) [m] the CoM
    minus the trunk position the previous step ended with.
    """

    time: float
    base_pos: NDArray[np.float64]
    rpy: NDArray[np.float64]
    com_state: NDArray[np.float64]
    com_offset: NDArray[np.float64]
    zmp_anchor: NDArray[np.float64]


@dataclass
class FootstepState:
    """One footstep's trajectory at CHOMP's rate while it is built and optimised.

    Arrays have one row per sample t = 0 … T − 1, both ends included (the
    ends are fixed). ``body`` (T, 6) is (x, y, z, roll, pitch, yaw) of the
    trunk [m, rad]; ``q`` (T, 4, 3) canonical joint angles [rad]; ``feet``
    (T, 4, 3) foot targets [m] (the swing foot's spline while airborne);
    ``support`` (T, 4) which feet bear weight; ``phase`` (T,) SHIFT, SWING
    or SETTLE. ``lift_off`` and ``touchdown`` index the swing's end samples.
    """

    step: StepSpec
    timing: StepTiming
    dt: float
    times: NDArray[np.float64]
    phase: NDArray[np.int64]
    support: NDArray[np.bool_]
    feet: NDArray[np.float64]
    body: NDArray[np.float64]
    q: NDArray[np.float64]
    reached: NDArray[np.bool_]
    com_offset: NDArray[np.float64]
    com_offset_acceleration: NDArray[np.float64]
    preview: PreviewRun
    zmp_reference: NDArray[np.float64]
    com_height: float
    lift_off: int
    touchdown: int
    swing: SwingSpline
    anchor: NDArray[np.float64]
    used_shortcut: bool
    polygons: list[NDArray[np.float64]] = field(default_factory=list)
    polygon_index: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    contact_clearance: float = 0.0
    """The swing foot's clearance [m] on its footholds (start and target), ≤ 0 when
    the plan put one slightly into the terrain's field."""
    end_rates: NDArray[np.float64] = field(default_factory=lambda: np.zeros((2, 6)))
    """Trunk rates (x, y, z, roll, pitch, yaw per second) at the first and last sample:
    the CoM's from the preview controller, the rest from the keyframe spline."""
    end_accelerations: NDArray[np.float64] = field(default_factory=lambda: np.zeros((2, 6)))
    """The same for the second derivatives."""

    @property
    def n_samples(self) -> int:
        """T."""
        return int(self.times.shape[0])

    @property
    def rotation(self) -> NDArray[np.float64]:
        """(T, 3, 3) trunk orientations."""
        return rpy_to_matrix(self.body[:, 3:])

    def update_com_offset(self, wb: WholeBody) -> None:
        """Recompute the CoM's offset from the trunk (T, 3) [m, world] from the joint angles.

        With its second derivative: the swing leg's motion moves the CoM too.
        """
        off = np.einsum("tij,tj->ti", self.rotation, wb.center_of_mass(self.q))
        self.com_offset = off
        rate = np.gradient(off, self.dt, axis=0, edge_order=2)
        self.com_offset_acceleration = np.gradient(rate, self.dt, axis=0, edge_order=2)

    def solve_legs(self, wb: WholeBody, legs: NDArray[np.bool_] | None = None) -> None:
        """Re-solve IK for the feet marked in ``legs`` (T, 4) (default: the supporting ones)."""
        mask = self.support if legs is None else legs
        rot = self.rotation
        feet_b = np.einsum("tji,tlj->tli", rot, self.feet - self.body[:, None, :3])
        q, reached = wb.inverse_kinematics(feet_b)
        self.q = np.where(mask[..., None], q, self.q)
        self.reached = np.where(mask, reached, self.reached)


def _reach_by_height_and_tilt(
    wb: WholeBody, feet: NDArray[np.float64], pose: NDArray[np.float64], iterations: int = 30
) -> NDArray[np.float64] | None:
    """Trunk (x, y, z, roll, pitch, yaw) with z and tilt changed until ``feet`` (4, 3) are reached.

    The §3.2 virtual force, Δz = α·Σe_z and ω = β·Σ(f′ − x) × e, without its
    horizontal part, by the Rust core (the loop of single-stance IK solves
    cost ~1 ms a call in numpy where a foot stays out of reach).
    :func:`reach_by_height_and_tilt_reference` is the numpy reference.
    Returns None when every foot is already reached.
    """
    moved = _core.reach_by_height_and_tilt(
        wb.core, wb.hips, feet, pose[:3], rpy_to_matrix(pose[3:]), iterations
    )
    if moved is None:
        return None
    x, rot = moved
    out = np.concatenate([x, matrix_to_rpy(rot)])
    out[5] = _unwrap_to(float(out[5]), float(pose[5]))
    return out


def reach_by_height_and_tilt_reference(
    wb: WholeBody, feet: NDArray[np.float64], pose: NDArray[np.float64], iterations: int = 30
) -> NDArray[np.float64] | None:
    """:func:`_reach_by_height_and_tilt` in numpy (the tests' oracle)."""
    x = pose[:3].copy()
    rot = rpy_to_matrix(pose[3:])
    changed = False
    hips = wb.hips
    for _ in range(iterations):
        # Aim 2 mm past each foot, away from its hip, to land with some slack.
        feet_b = (feet - x) @ rot
        out = feet_b - hips
        aim_b = feet_b + 0.002 * out / np.linalg.norm(out, axis=1, keepdims=True)
        q, reached = wb.inverse_kinematics(aim_b[None])
        if reached.all():
            break
        reach = x + wb.foot_positions(q)[0] @ rot.T
        e = x + aim_b @ rot.T - reach
        x[2] += 0.5 * float(e[:, 2].sum())
        omega = 2.0 * np.cross(reach - x, e).sum(axis=0)
        rot = axis_angle(omega) @ rot
        changed = True
    if not changed:
        return None
    out = np.concatenate([x, matrix_to_rpy(rot)])
    out[5] = _unwrap_to(float(out[5]), float(pose[5]))
    return out


def axis_angle(omega: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation matrix of the rotation vector ``omega`` [rad]."""
    angle = float(np.linalg.norm(omega))
    if angle < 1e-12:
        return np.eye(3)
    k = skew(omega / angle)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def _unwrap_to(angle: float, reference: float) -> float:
    return reference + math.remainder(angle - reference, 2 * math.pi)


def moving_trunk_leg(
    wb: WholeBody, swing_pose: BodyKeyframe, trunk: NDArray[np.float64], leg: int
) -> tuple[LegAngles, LegFeet]:
    """IK and FK of leg ``leg`` under the trunk as it moves through the swing.

    ``trunk`` (m, 6): the trunk's poses (x, y, z [m], roll, pitch, yaw [rad])
    from lift-off to touchdown. The n points (angles) given to either
    function are taken in the order the foot passes them, the i-th under
    the trunk at fraction i / (n − 1) of the swing (linear between
    samples): for the ``"joint"`` time law's pace, which at the swing pose
    alone misses a target the trunk only reaches by lowering into the
    landing pose (``SwingConfig.law_trunk``). The other legs hold their
    swing-pose feet.
    """
    rows = np.asarray(trunk, dtype=float)
    held = (swing_pose.feet - swing_pose.base_pos) @ swing_pose.rotation

    def poses(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        at = np.linspace(0.0, len(rows) - 1.0, n)
        pose = np.column_stack([np.interp(at, np.arange(len(rows)), rows[:, j]) for j in range(6)])
        return pose[:, :3], rpy_to_matrix(pose[:, 3:])

    def angles(points: NDArray[np.float64]) -> NDArray[np.float64]:
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        base, rot = poses(len(p))
        feet_b = np.repeat(held[None], len(p), axis=0)
        feet_b[:, leg] = np.einsum("nji,nj->ni", rot, p - base)
        return np.asarray(wb.inverse_kinematics(feet_b)[0][:, leg], dtype=float)

    def feet(q_leg: NDArray[np.float64]) -> NDArray[np.float64]:
        a = np.asarray(q_leg, dtype=float).reshape(-1, 3)
        base, rot = poses(len(a))
        q = np.repeat(swing_pose.q[None], len(a), axis=0)
        q[:, leg] = a
        local = np.asarray(wb.foot_positions(q), dtype=float)[:, leg]
        return base + np.einsum("nij,nj->ni", rot, local)

    return angles, feet


def build_initial_trajectory(
    wb: WholeBody,
    step: StepSpec,
    start: StartState,
    swing_pose: BodyKeyframe,
    timing: StepTiming,
    dt: float,
    controller: ZmpPreviewController,
    reference: NDArray[np.float64],
    preview_samples: int,
    swing_config: SwingConfig,
    terrain: Terrain | None,
    *,
    end_pose: BodyKeyframe | None = None,
    used_shortcut: bool = False,
) -> FootstepState:
    """Assemble the footstep's initial trajectory.

    Parameters
    ----------
    wb:
        The robot's batched kinematics.
    step:
        The footstep.
    start:
        Its start (the previous step's end).
    swing_pose:
        The keyframe held through the swing (the certificate, or its
        shortcut translation); its CoM is the ZMP anchor.
    timing:
        Phase durations, whole multiples of ``dt``.
    dt:
        Sample period [s].
    controller:
        The ZMP preview controller for this step's CoM height.
    reference:
        (M, 2) ZMP reference [m] at t = start.time + i·dt over the preview
        window (this step and the next ones).
    preview_samples:
        The preview horizon N.
    swing_config, terrain:
        For the swing foot's lift-off and drop-off points.
    end_pose:
        The certificate of the stance the step reaches: the trunk's height and
        tilt at touchdown (and through the settling phase); None holds the
        swing pose.
    used_shortcut:
        Recorded in the result.
    """
    n_shift, n_swing, n_settle = timing.samples(dt)
    n = n_shift + n_swing + n_settle
    t0 = start.time
    times = t0 + dt * np.arange(n + 1, dtype=np.float64)
    lift_off, touchdown = n_shift, n_shift + n_swing

    # Trunk height, orientation and CoM offset: smoothstep between keyframes (§5.2).
    # The shift brings the trunk to the swing pose; the swing carries it on to
    # the certificate of the stance it reaches, whose height and tilt let the
    # foot land (the planner checked that pose, not the swing pose, against
    # the new foothold).
    rpy_swing = swing_pose.rpy.copy()
    rpy_swing[2] = _unwrap_to(rpy_swing[2], float(start.rpy[2]))
    knots = [t0, times[lift_off], times[touchdown]]
    values = [
        np.concatenate([[start.base_pos[2]], start.rpy, start.com_offset]),
        np.concatenate([[swing_pose.base_pos[2]], rpy_swing, swing_pose.com_offset]),
    ]
    if end_pose is not None:
        rpy_end = end_pose.rpy.copy()
        rpy_end[2] = _unwrap_to(rpy_end[2], float(rpy_swing[2]))
        values.append(np.concatenate([[end_pose.base_pos[2]], rpy_end, end_pose.com_offset]))
    else:
        values.append(values[-1])
    if n_settle:
        knots.append(times[-1])
        values.append(values[-1])
    run = controller.run(reference, n, start.com_state, preview=preview_samples)
    values_arr = np.array(values)
    spline = BodySpline(np.array(knots), values_arr)
    pose = spline.value(times)
    # The ZMP keeps the trunk from the landing pose's x–y at touchdown; where
    # the landing foot is then out of reach, lower and tilt the trunk there
    # instead (Zucker 2011, §3.2, with the horizontal push left out: vertical
    # motion and rotation barely move the ZMP, §5.2 footnote 3).
    touch_xy = run.com[touchdown] - pose[touchdown, 4:6]
    fixed = _reach_by_height_and_tilt(
        wb, step.stance_after, np.concatenate([touch_xy, pose[touchdown, :4]])
    )
    if fixed is not None:
        values_arr[2:, :4] = fixed[2:]
        spline = BodySpline(np.array(knots), values_arr)
    if swing_config.lift_off_reach:
        # The same at lift-off for the foot about to lift: the preview leads
        # the trunk ahead of the swing pose, which a trailing foot at the
        # back of its reach then misses (a long stride's last crawl step).
        pose = spline.value(times)
        lift_xy = run.com[lift_off] - pose[lift_off, 4:6]
        lifted = _reach_by_height_and_tilt(
            wb, step.stance_before, np.concatenate([lift_xy, pose[lift_off, :4]])
        )
        if lifted is not None:
            values_arr[1, :4] = lifted[2:]
            spline = BodySpline(np.array(knots), values_arr)
    pose, pose_rate, pose_acc = spline.evaluate(times)
    offset = pose[:, 4:7]

    body = np.empty((n + 1, 6))
    body[:, :2] = run.com - offset[:, :2]
    body[:, 2] = pose[:, 0]
    body[:, 3:] = pose[:, 1:4]

    law_legs = None
    rise = abs(float(step.target[2] - step.start[2]))
    if swing_config.law_trunk == "moving" and rise >= swing_config.law_trunk_rise:
        law_legs = moving_trunk_leg(wb, swing_pose, body[lift_off : touchdown + 1], step.leg)
    swing = SwingSpline.plan(
        step.start,
        step.target,
        n_swing * dt,
        swing_config,
        terrain=terrain,
        foot_radius=wb.robot.foot_radius,
        leg_angles=swing_pose.leg_angles(wb, step.leg),
        velocity_limit=wb.velocity_limit[step.leg],
        leg_feet=swing_pose.leg_feet(wb, step.leg),
        joint_range=(wb.lower[step.leg], wb.upper[step.leg]),
        law_legs=law_legs,
    )
    feet = np.repeat(step.stance_before[None], n + 1, axis=0)
    feet[lift_off : touchdown + 1, step.leg] = swing.position(
        times[lift_off : touchdown + 1] - times[lift_off]
    )
    feet[touchdown:, step.leg] = step.target
    support = np.ones((n + 1, 4), dtype=bool)
    support[lift_off + 1 : touchdown, step.leg] = False
    phase = np.full(n + 1, SHIFT, dtype=np.int64)
    phase[lift_off:touchdown] = SWING
    phase[touchdown:] = SETTLE if n_settle else SWING
    if not n_settle:
        phase[-1] = SWING

    polygons = [
        convex_polygon(step.stance_before),
        convex_polygon(step.support_triangle),
        convex_polygon(step.stance_after),
    ]
    polygon_index = np.zeros(n + 1, dtype=np.int64)
    polygon_index[lift_off + 1 : touchdown] = 1
    polygon_index[touchdown:] = 2

    support_z = float(np.mean(step.support_triangle[:, 2]))
    state = FootstepState(
        step=step,
        timing=timing,
        dt=dt,
        times=times,
        phase=phase,
        support=support,
        feet=feet,
        body=body,
        q=np.zeros((n + 1, 4, 3)),
        reached=np.ones((n + 1, 4), dtype=bool),
        com_offset=offset,
        com_offset_acceleration=pose_acc[:, 4:7],
        preview=run,
        zmp_reference=np.asarray(reference, dtype=float)[: n + 1]
        if reference.shape[0] >= n + 1
        else np.concatenate(
            [reference, np.repeat(reference[-1:], n + 1 - reference.shape[0], axis=0)]
        ),
        com_height=max(float(swing_pose.com[2]) - support_z, 1e-3),
        lift_off=lift_off,
        touchdown=touchdown,
        swing=swing,
        anchor=swing_pose.com[:2].copy(),
        used_shortcut=used_shortcut,
        polygons=polygons,
        polygon_index=polygon_index,
    )
    everything = np.ones((n + 1, 4), dtype=bool)
    state.solve_legs(wb, everything)
    for _ in range(3):
        # The trunk carries the CoM the preview planned, offset by where the legs
        # (the swing leg above all) actually put it: a fixed point, in a few rounds.
        for _ in range(3):
            state.update_com_offset(wb)
            xy = run.com - state.com_offset[:, :2]
            moved = float(np.abs(xy - state.body[:, :2]).max())
            state.body[:, :2] = xy
            state.solve_legs(wb, everything)
            if moved < 1e-4:
                break
        # That moves the trunk at touchdown; check the landing foot's reach again.
        fixed = _reach_by_height_and_tilt(wb, step.stance_after, state.body[touchdown])
        if fixed is None:
            break
        values_arr[2:, :4] = fixed[2:]
        spline = BodySpline(np.array(knots), values_arr)
        pose, pose_rate, pose_acc = spline.evaluate(times)
        state.body[:, 2:] = pose[:, :4]
        state.solve_legs(wb, everything)
    # The first sample is the previous step's last, exactly.
    state.body[0] = np.concatenate([start.base_pos, start.rpy])
    state.solve_legs(wb, everything)
    state.update_com_offset(wb)
    offset_rate = np.gradient(state.com_offset, dt, axis=0, edge_order=2)
    rates = np.empty((2, 6))
    accelerations = np.empty((2, 6))
    for row, k in ((0, 0), (1, n)):
        rates[row, :2] = run.com_velocity[k] - offset_rate[k, :2]
        rates[row, 2:] = pose_rate[k, :4]
        accelerations[row, :2] = run.com_acceleration[k] - state.com_offset_acceleration[k, :2]
        accelerations[row, 2:] = pose_acc[k, :4]
    state.end_rates = rates
    state.end_accelerations = accelerations
    return state
