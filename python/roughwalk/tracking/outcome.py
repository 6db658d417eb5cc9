"""The :class:`TrackingOutcome` of executing a motion, and its :class:`TrackingLog`.

Melon et al. 2020 §V count a motion as executed when the whole-body
controller carries it out without falling and ends where planned; the log
keeps what their Figure 4 plots (planned and measured foot forces, base
angular velocities, base position and orientation errors over time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["TrackingOutcome", "TrackingLog", "first_leg_contact"]


@dataclass
class TrackingLog:
    """Per control tick, what the controller planned, chose and measured (world frame).

    Attributes
    ----------
    t:
        (n,) time [s].
    base_pos, base_pos_ref:
        (n, 3) measured and planned base position [m].
    orientation_error:
        (n, 3) rotation vector log(R_ref Rᵀ) [rad].
    base_angvel, base_angvel_ref:
        (n, 3) measured and planned base angular velocity [rad/s].
    forces, forces_ref, forces_qp:
        (n, 4, 3) measured, planned and QP-chosen foot forces [N].
    contact_ref, stance:
        (n, 4) planned contact and the contact state machine's stance.
    torques:
        (n, 12) joint torques sent [N·m].
    shin_contact:
        (n, 4) a leg link other than the foot touches the terrain.
    qpos:
        (n, nq) MuJoCo ``qpos`` (for videos).
    """

    t: NDArray[np.float64]
    base_pos: NDArray[np.float64]
    base_pos_ref: NDArray[np.float64]
    orientation_error: NDArray[np.float64]
    base_angvel: NDArray[np.float64]
    base_angvel_ref: NDArray[np.float64]
    forces: NDArray[np.float64]
    forces_ref: NDArray[np.float64]
    forces_qp: NDArray[np.float64]
    contact_ref: NDArray[np.bool_]
    stance: NDArray[np.bool_]
    torques: NDArray[np.float64]
    shin_contact: NDArray[np.bool_]
    qpos: NDArray[np.float64]

    @property
    def position_error(self) -> NDArray[np.float64]:
        """(n,) base position error ‖p − p_ref‖ [m]."""
        return np.asarray(np.linalg.norm(self.base_pos - self.base_pos_ref, axis=1))

    @property
    def orientation_error_angle(self) -> NDArray[np.float64]:
        """(n,) base orientation error angle [rad]."""
        return np.asarray(np.linalg.norm(self.orientation_error, axis=1))

    def to_npz(self, path: str) -> None:
        """Save every array to an .npz file [path]."""
        np.savez_compressed(path, **{k: v for k, v in vars(self).items()})


@dataclass
class TrackingOutcome:
    """How the execution of a motion went.

    Attributes
    ----------
    success:
        Never fell and ended within the tolerance of the planned final position.
    reason:
        Why, one line.
    final_position_error_m:
        Distance [m] from the base to the planned final position after the
        motion plus the standing time.
    max_orientation_error_rad, mean_orientation_error_rad:
        Largest and mean base orientation error [rad] over the run.
    max_position_error_m, mean_position_error_m:
        Largest and mean base position error [m] over the run.
    fell:
        The trunk touched the terrain or roll/pitch passed the limit.
    fall_time_s:
        When it fell [s] (None: it did not).
    duration_s:
        The motion's planned duration [s].
    simulated_s:
        Simulated time [s] (the motion plus standing, or up to the fall).
    qp_failures:
        Ticks on which the QP returned no solution (previous torques kept).
    early_touchdowns, late_touchdowns, slips:
        Events of the contact state machine.
    mean_qp_time_ms:
        Mean wall time [ms] of one control tick (state, tasks, QP build and
        solve); it follows the machine's load.
    mean_tick_cpu_ms:
        Mean CPU time [ms] of one control tick (400 Hz leaves 2.5 ms).
    first_leg_contact:
        The first touch of the terrain by a leg link other than a foot (a
        shank or thigh): ``{"leg": "RF", "t": 4.66, "planned": "stance"}``,
        the leg, the time [s] and the foot's planned phase then; None when no
        leg link touched. On the pallets such a touch is often the first
        visible step of a fall.
    implied_torque:
        The largest joint torque the plan's own forces ask of the legs
        (:class:`~roughwalk.trajopt.ImpliedTorques` as a dict: ``max_nm``,
        ``time_s``, ``joint``, ``limit_nm``, ``over_limit_fraction``,
        ``unreachable_fraction``); None when not computed (a reference
        executed without its plan, or a robot without analytic IK).
    friction_demand:
        How much friction the plan's base motion needs against the
        controller's μ (:class:`~roughwalk.trajopt.FrictionDemand` as a dict:
        ``friction``, ``over_fraction``, ``max_ratio``, ``time_s``): beyond
        μ no force distribution realises it; None when not computed.
    log:
        Per-tick arrays (not in :meth:`to_dict`).
    """

    success: bool
    reason: str
    final_position_error_m: float
    max_orientation_error_rad: float
    mean_position_error_m: float
    max_position_error_m: float
    mean_orientation_error_rad: float
    fell: bool
    fall_time_s: float | None
    duration_s: float
    simulated_s: float
    qp_failures: int
    early_touchdowns: int
    late_touchdowns: int
    slips: int
    mean_qp_time_ms: float
    mean_tick_cpu_ms: float = 0.0
    first_leg_contact: dict[str, Any] | None = None
    implied_torque: dict[str, Any] | None = None
    friction_demand: dict[str, Any] | None = None
    log: TrackingLog | None = field(default=None, repr=False)
    video: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (no log)."""
        out: dict[str, Any] = {}
        for k, v in vars(self).items():
            if k == "log":
                continue
            out[k] = None if isinstance(v, float) and not math.isfinite(v) else v
        return out


LEG_NAMES = ("LF", "RF", "LH", "RH")


def first_leg_contact(log: TrackingLog) -> dict[str, Any] | None:
    """The first tick a leg link other than a foot touched the terrain (see TrackingOutcome)."""
    hits = np.argwhere(np.asarray(log.shin_contact, dtype=bool))
    if len(hits) == 0:
        return None
    tick, leg = (int(v) for v in hits[0])
    planned = "stance" if bool(log.contact_ref[tick][leg]) else "swing"
    return {"leg": LEG_NAMES[leg], "t": round(float(log.t[tick]), 4), "planned": planned}
