"""One footstep's trajectory as the executor takes it (Zucker 2011, §5–6).

"The trajectory specifies not only the desired joint angles and velocities
over time, but also additional information such as desired body position and
orientation, corresponding velocities and accelerations, which feet should be
supporting, and estimated ground interaction forces." :func:`resample_footstep`
turns CHOMP's samples into that at the control rate: the trunk path by a
cubic spline, the swing leg's angles likewise, the supporting legs by IK at
every control sample (so the feet stay exactly put), joint velocities by
second-order differences, and the validity report.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import make_interp_spline

from roughwalk.trajectories.config import TrajectoryConfig
from roughwalk.trajectories.contact_forces import static_contact_forces
from roughwalk.trajectories.euler import rpy_to_matrix, rpy_to_quat
from roughwalk.trajectories.initial_trajectory import FootstepState
from roughwalk.trajectories.step_report import StepReport, capsule_clearances, clearance_summary
from roughwalk.trajectories.support_polygon import convex_polygon, polygon_margin
from roughwalk.trajectories.whole_body import WholeBody

__all__ = [
    "FootstepTrajectory",
    "control_times",
    "resample_footstep",
    "swing_leg_angles",
    "phase_speed_ratios",
    "swing_speed_ratio",
    "swing_com_margins",
]


@dataclass(frozen=True)
class FootstepTrajectory:
    """A footstep sampled at the control rate; n samples, both ends included.

    Consecutive footsteps share their boundary sample.

    Attributes
    ----------
    time:
        (n,) [s] from the start of the plan.
    q, qd:
        (n, 12) joint angles [rad] and velocities [rad/s], ``Robot.joint_names`` order.
    base_pos, base_vel, base_acc:
        (n, 3) trunk position [m], velocity [m/s], acceleration [m/s²].
    base_quat:
        (n, 4) trunk orientation (w, x, y, z).
    base_rpy, base_rpy_rate:
        (n, 3) roll–pitch–yaw [rad] and their rates [rad/s].
    com, zmp, zmp_reference:
        (n, 3) centre of mass [m]; (n, 2) its cart-table ZMP and the reference [m].
    support:
        (n, 4) which feet bear weight, canonical legs (LF, RF, LH, RH).
    feet:
        (n, 4, 3) foot centres [m].
    contact_forces:
        (n, 4, 3) expected ground reaction forces [N].
    clearance:
        (n,) least clearance of the collision primitives that are not feet [m].
    foot_clearance:
        (n,) the lifted foot's clearance [m], NaN while every foot is down.
    phase:
        (n,) 0 shift, 1 swing, 2 settle.
    report:
        The :class:`StepReport`.
    """

    time: NDArray[np.float64]
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    base_pos: NDArray[np.float64]
    base_vel: NDArray[np.float64]
    base_acc: NDArray[np.float64]
    base_quat: NDArray[np.float64]
    base_rpy: NDArray[np.float64]
    base_rpy_rate: NDArray[np.float64]
    com: NDArray[np.float64]
    zmp: NDArray[np.float64]
    zmp_reference: NDArray[np.float64]
    support: NDArray[np.bool_]
    feet: NDArray[np.float64]
    contact_forces: NDArray[np.float64]
    clearance: NDArray[np.float64]
    foot_clearance: NDArray[np.float64]
    phase: NDArray[np.int64]
    report: StepReport

    @property
    def step(self) -> int:
        """Footstep number (1 = the first move after the initial stance)."""
        return self.report.step

    @property
    def leg(self) -> str:
        """The swing leg."""
        return self.report.leg

    @property
    def valid(self) -> bool:
        """Collision-free, within limits, reachable and dynamically stable."""
        return self.report.valid

    def arrays(self) -> dict[str, NDArray[Any]]:
        """Every sampled array by name."""
        names = (
            "time q qd base_pos base_vel base_acc base_quat base_rpy base_rpy_rate com zmp "
            "zmp_reference support feet contact_forces clearance foot_clearance phase"
        ).split()
        return {k: getattr(self, k) for k in names}


def control_times(state: FootstepState, rate_hz: float) -> tuple[NDArray[np.float64], float]:
    """The control-rate sample times [s] of a footstep (both ends included) and their period."""
    t0, t1 = float(state.times[0]), float(state.times[-1])
    n = max(int(round((t1 - t0) * rate_hz)), 1)
    return np.linspace(t0, t1, n + 1), (t1 - t0) / n


def swing_leg_angles(
    state: FootstepState, wb: WholeBody, time: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The swing leg's angles (len(time), 3) [rad]: a cubic through its CHOMP samples.

    Clamped to the joint limits; ``time`` [s] should lie between lift-off and touchdown.
    """
    leg = state.step.leg
    window = slice(state.lift_off, state.touchdown + 1)
    swing_times = state.times[window]
    spline = make_interp_spline(swing_times, state.q[window, leg], k=min(3, len(swing_times) - 1))
    return np.clip(spline(time), wb.lower[leg], wb.upper[leg])


def swing_speed_ratio(state: FootstepState, wb: WholeBody, rate_hz: float) -> float:
    """Peak over the swing leg's joints of |q̇| / velocity limit while it is airborne.

    q̇ as :func:`resample_footstep` computes it (second-order differences at
    the control rate ``rate_hz`` [Hz] of :func:`swing_leg_angles`), so a value
    above 1 predicts that its velocity check will fail on the swing leg.
    """
    time, dt = control_times(state, rate_hz)
    t_lift, t_touch = state.times[state.lift_off], state.times[state.touchdown]
    airborne = (time > t_lift + 1e-9) & (time < t_touch - 1e-9)
    if airborne.sum() < 3:
        return 0.0
    q = swing_leg_angles(state, wb, time[airborne])
    qd = np.gradient(q, dt, axis=0, edge_order=2)
    return float(np.max(np.abs(qd) / wb.velocity_limit[state.step.leg]))


def swing_com_margins(state: FootstepState) -> NDArray[np.float64]:
    """Signed margins [m] of the planned CoM in the swing's support triangle, lift-off to touchdown.

    The CoM is the preview controller's (the cart-table's), sampled at the
    state's rate from ``lift_off`` to ``touchdown`` inclusive; the triangle is
    the three supporting feet's x–y. Negative: outside.
    """
    lift, touch = state.lift_off, state.touchdown
    triangle = convex_polygon(np.asarray(state.step.support_triangle, dtype=float)[:, :2])
    margins, _ = polygon_margin(state.preview.com[lift : touch + 1], triangle)
    return margins


def phase_speed_ratios(state: FootstepState, wb: WholeBody, rate_hz: float) -> tuple[float, float]:
    """Peak |q̇| / velocity limit over every joint in the shift and in the swing: (shift, swing).

    The supporting legs' rates are differences of the state's samples (their
    angles follow the trunk by IK); the swing leg's in the air is
    :func:`swing_speed_ratio`.
    """
    q = np.asarray(state.q, dtype=float).reshape(state.n_samples, 4, 3)
    limit = wb.velocity_limit.reshape(4, 3)
    rate = np.abs(np.diff(q, axis=0)) / state.dt / limit
    lift, touch = state.lift_off, state.touchdown
    shift = float(rate[:lift].max()) if lift > 0 else 0.0
    others = np.arange(4) != state.step.leg
    swing = float(rate[lift:touch][:, others].max()) if touch > lift else 0.0
    return shift, max(swing, swing_speed_ratio(state, wb, rate_hz))


def resample_footstep(
    state: FootstepState,
    wb: WholeBody,
    sdf: Any,
    config: TrajectoryConfig,
    *,
    optimize_ms: float,
    attempts: int,
    iterations: int,
    initial_min_clearance: float,
    chomp_status: str = "",
) -> FootstepTrajectory:
    """Sample ``state`` at the control rate, check it, and package it."""
    robot = wb.robot
    time, dt = control_times(state, config.control_rate_hz)
    n = len(time) - 1
    # A quintic clamped at both ends to the rates and accelerations the step
    # starts and ends with, so consecutive footsteps join with continuous trunk
    # velocity and acceleration (and the ZMP computed from it stays put there).
    if state.n_samples >= 6:
        body_spline = make_interp_spline(
            state.times,
            state.body,
            k=5,
            bc_type=(
                [(1, state.end_rates[0]), (2, state.end_accelerations[0])],
                [(1, state.end_rates[1]), (2, state.end_accelerations[1])],
            ),
        )
    else:
        body_spline = make_interp_spline(
            state.times,
            state.body,
            k=3,
            bc_type=([(1, state.end_rates[0])], [(1, state.end_rates[1])]),
        )
    body = body_spline(time)
    body_vel = body_spline.derivative(1)(time)
    body_acc = body_spline.derivative(2)(time)
    rot = rpy_to_matrix(body[:, 3:])
    t_lift, t_touch = state.times[state.lift_off], state.times[state.touchdown]
    leg = state.step.leg
    airborne = (time > t_lift + 1e-9) & (time < t_touch - 1e-9)
    support = np.ones((n + 1, 4), dtype=bool)
    support[airborne, leg] = False

    feet = np.repeat(state.step.stance_before[None], n + 1, axis=0)
    feet[time >= t_touch - 1e-9, leg] = state.step.target
    feet_b = np.einsum("tji,tlj->tli", rot, feet - body[:, None, :3])
    # The lifted leg's angles come from its own spline below.
    feet_b[airborne, leg] = wb.nominal_feet[leg]
    q, reached = wb.inverse_kinematics(feet_b)
    q[airborne, leg] = swing_leg_angles(state, wb, time[airborne])
    feet_fk = body[:, None, :3] + np.einsum("tij,tlj->tli", rot, wb.foot_positions(q))
    feet[airborne, leg] = feet_fk[airborne, leg]
    qd = np.gradient(q, dt, axis=0, edge_order=2)

    com_b = wb.center_of_mass(q)
    com = body[:, :3] + np.einsum("tij,tj->ti", rot, com_b)
    # The trunk's own acceleration comes from its spline; only the slowly varying
    # CoM offset (legs moving) is differenced.
    offset = com - body[:, :3]
    offset_acc = np.gradient(
        np.gradient(offset, dt, axis=0, edge_order=2), dt, axis=0, edge_order=2
    )
    com_acc = body_acc[:, :3] + offset_acc
    gravity = config.zmp.gravity
    zmp = com[:, :2] - state.com_height / gravity * com_acc[:, :2]
    zmp_ref = np.stack(
        [np.interp(time, state.times, state.zmp_reference[:, a]) for a in range(2)], axis=1
    )
    phase = np.full(n + 1, 0, dtype=np.int64)
    phase[time >= t_lift - 1e-9] = 1
    if state.timing.settle_s > 0:
        phase[time >= t_touch - 1e-9] = 2

    polygon_of = np.where(airborne, 1, np.where(time >= t_touch - 1e-9, 2, 0))
    zmp_margin = np.empty(n + 1)
    for k in range(3):
        sel = polygon_of == k
        if np.any(sel):
            zmp_margin[sel] = polygon_margin(zmp[sel], state.polygons[k])[0]

    clearance_all = capsule_clearances(wb, sdf, q, body[:, :3], rot)
    per_sample, foot_clearance, per_link, collision_free = clearance_summary(
        wb,
        clearance_all,
        support,
        config.validity,
        feet,
        np.array([state.step.start, state.step.target]),
        state.contact_clearance,
    )
    speed_limit = wb.velocity_limit.reshape(12)
    qd_c = qd.reshape(-1, 12)
    q_c = q.reshape(-1, 12)
    velocity_margin = float(np.min(speed_limit - np.abs(qd_c)))
    joint_margin = float(np.min(np.minimum(q_c - wb.lower.reshape(12), wb.upper.reshape(12) - q_c)))
    reachable = bool(np.all(reached | ~support))
    velocity_ok = velocity_margin >= 0
    zmp_min = float(zmp_margin.min())
    zmp_ok = zmp_min >= -config.validity.zmp_tolerance
    valid = collision_free and velocity_ok and reachable and zmp_ok and joint_margin >= -1e-9
    notes = []
    if not collision_free:
        notes.append("collides with the terrain")
    if not velocity_ok:
        notes.append("exceeds a joint velocity limit")
    if not reachable:
        notes.append("a supporting foot is out of reach")
    if not zmp_ok:
        notes.append("the ZMP leaves the support polygon")
    timing = state.timing
    report = StepReport(
        step=state.step.index,
        leg=state.step.leg_name,
        duration_s=timing.duration_s,
        shift_s=timing.shift_s,
        swing_s=timing.swing_s,
        settle_s=timing.settle_s,
        min_clearance_m=float(per_sample.min()),
        swing_foot_clearance_m=float(np.nanmin(foot_clearance))
        if np.any(np.isfinite(foot_clearance))
        else float("nan"),
        link_clearance_m=per_link,
        initial_min_clearance_m=float(initial_min_clearance),
        joint_limit_margin_rad=joint_margin,
        velocity_margin_rad_s=velocity_margin,
        velocity_limits_ok=velocity_ok,
        zmp_margin_m=zmp_min,
        reachable=reachable,
        collision_free=collision_free,
        valid=valid,
        optimize_ms=float(optimize_ms),
        attempts=attempts,
        iterations=iterations,
        used_shortcut=state.used_shortcut,
        chomp_status=chomp_status,
        notes=notes,
    )
    return FootstepTrajectory(
        time=time,
        q=robot.from_canonical(q.reshape(-1, 12)),
        qd=robot.from_canonical(qd_c),
        base_pos=body[:, :3],
        base_vel=body_vel[:, :3],
        base_acc=body_acc[:, :3],
        base_quat=rpy_to_quat(body[:, 3:]),
        base_rpy=body[:, 3:],
        base_rpy_rate=body_vel[:, 3:],
        com=com,
        zmp=zmp,
        zmp_reference=zmp_ref,
        support=support,
        feet=feet,
        contact_forces=static_contact_forces(feet, support, zmp, com_acc, wb.mass, gravity),
        clearance=per_sample,
        foot_clearance=foot_clearance,
        phase=phase,
        report=report,
    )
