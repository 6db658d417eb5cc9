"""Run outcomes by the Learning Locomotion metric (Zucker 2011, §1): success and speed.

A run succeeds when the feet's centroid comes within the goal radius and the
robot never fell: the trunk never touched the terrain and its roll and pitch
stayed within limits. Speed is the straight-line distance from the start
centroid to the goal point over the time from the first motion to reaching
the goal [cm/s]; the initial plan before the first step is excluded (the
trials allowed planning before the clock started), every re-plan and every
wait is included.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.sim.config import OutcomeConfig

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = ["Outcome", "OutcomeMonitor"]


@dataclass(frozen=True)
class Outcome:
    """How a run went.

    Attributes
    ----------
    success:
        Reached the goal without falling.
    reason:
        Why it succeeded or failed, one line.
    distance_m:
        Straight-line distance [m] from the start feet centroid to the goal.
    time_s:
        From the first motion to reaching the goal [s] (to the end of the run
        when it did not reach it).
    speed_cm_s:
        ``distance_m / time_s`` in cm/s; 0 when the run failed.
    reflexes, replans, foot_slips:
        Counts over the run.
    wait_s:
        Simulated time [s] spent waiting for trajectory optimisation.
    replan_s:
        Simulated time [s] spent re-planning after reflexes (standing still).
    fell:
        True when the robot fell (trunk contact or roll/pitch beyond limits).
    final_distance_m:
        Distance [m] from the final feet centroid to the goal, in x–y.
    max_roll_rad, max_pitch_rad:
        Largest trunk roll and pitch magnitudes [rad].
    shin_contacts:
        Control ticks on which a leg other than its foot touched the terrain.
    self_contacts:
        Control ticks on which two of the robot's bodies touched each other
        (:attr:`~roughwalk.sim.measured_state.MeasuredState.self_contact`).
    steps:
        Footsteps executed to completion.
    relaxed_plans:
        Plans (the first or re-plans) that came from the footstep source's
        second planner, without the edge margin
        (:attr:`~roughwalk.sim.config.ExecutorConfig.relax_edge_margin`).
    """

    success: bool
    reason: str
    distance_m: float
    time_s: float
    speed_cm_s: float
    reflexes: int = 0
    replans: int = 0
    foot_slips: int = 0
    wait_s: float = 0.0
    replan_s: float = 0.0
    fell: bool = False
    final_distance_m: float = float("nan")
    max_roll_rad: float = 0.0
    max_pitch_rad: float = 0.0
    shin_contacts: int = 0
    self_contacts: int = 0
    steps: int = 0
    relaxed_plans: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (non-finite numbers as null)."""
        out = asdict(self)
        for k, v in out.items():
            if isinstance(v, float) and not math.isfinite(v):
                out[k] = None
        return out


class OutcomeMonitor:
    """Watches every control tick for falls, slips and reaching the goal.

    Parameters
    ----------
    goal:
        (x, y) [m] of the goal.
    start_centroid:
        (x, y) [m] of the feet centroid at the start.
    config:
        Thresholds (:class:`OutcomeConfig`).
    """

    def __init__(
        self,
        goal: NDArray[np.float64],
        start_centroid: NDArray[np.float64],
        config: OutcomeConfig | None = None,
    ) -> None:
        self.config = config if config is not None else OutcomeConfig()
        self.goal = np.asarray(goal, dtype=float)[:2]
        self.start_centroid = np.asarray(start_centroid, dtype=float)[:2]
        self.first_motion: float | None = None
        self.reached_at: float | None = None
        self.fall_reason: str | None = None
        self.fall_time: float | None = None
        self.foot_slips = 0
        self.max_roll = 0.0
        self.max_pitch = 0.0
        self.shin_contacts = 0
        self.self_contacts = 0
        self._anchor = np.full((4, 3), np.nan)
        self._slipped = np.zeros(4, dtype=bool)
        self.last_centroid = self.start_centroid.copy()

    @property
    def fell(self) -> bool:
        """True once a fall was seen."""
        return self.fall_reason is not None

    def start_clock(self, t: float) -> None:
        """Mark the first motion at simulated time ``t`` [s] (only the first call counts)."""
        if self.first_motion is None:
            self.first_motion = float(t)

    def update(self, measured: MeasuredState, desired: DesiredState | None) -> None:
        """Check one tick."""
        cfg = self.config
        t = measured.time
        if not (np.all(np.isfinite(measured.base_pos)) and np.all(np.isfinite(measured.q))):
            self._fall(t, "the simulation diverged (non-finite state)")
            return
        roll, pitch = measured.roll_pitch
        self.max_roll = max(self.max_roll, abs(roll))
        self.max_pitch = max(self.max_pitch, abs(pitch))
        if measured.trunk_contact:
            self._fall(t, f"the trunk touched the terrain at t = {t:.2f} s")
        elif abs(roll) > cfg.max_roll_rad:
            self._fall(t, f"rolled {math.degrees(roll):.0f}° at t = {t:.2f} s")
        elif abs(pitch) > cfg.max_pitch_rad:
            self._fall(t, f"pitched {math.degrees(pitch):.0f}° at t = {t:.2f} s")
        self.shin_contacts += int(np.any(measured.shin_contact))
        self.self_contacts += int(measured.self_contact)
        centroid = measured.feet_centroid[:2]
        self.last_centroid = centroid
        if (
            self.reached_at is None
            and self.first_motion is not None
            and float(np.linalg.norm(centroid - self.goal)) <= cfg.goal_radius_m
        ):
            self.reached_at = t
        # A foot slip: a weight-bearing foot sliding from where it touched down.
        down = measured.foot_forces[:, 2] > 1.0
        if desired is not None:
            down &= desired.support
        for leg in range(4):
            if not down[leg]:
                self._anchor[leg] = np.nan
                self._slipped[leg] = False
                continue
            if np.isnan(self._anchor[leg, 0]):
                self._anchor[leg] = measured.feet[leg]
                continue
            moved = float(np.linalg.norm(measured.feet[leg, :2] - self._anchor[leg, :2]))
            if moved > cfg.slip_m and not self._slipped[leg]:
                self._slipped[leg] = True
                self.foot_slips += 1

    def _fall(self, t: float, reason: str) -> None:
        if self.fall_reason is None:
            self.fall_reason = reason
            self.fall_time = t

    def finish(
        self,
        end_time: float,
        *,
        reflexes: int = 0,
        replans: int = 0,
        wait_s: float = 0.0,
        replan_s: float = 0.0,
        steps: int = 0,
        relaxed_plans: int = 0,
        failure: str | None = None,
        extra: dict[str, Any] | None = None,
    ) -> Outcome:
        """The :class:`Outcome` of the run that ended at ``end_time`` [s].

        ``failure`` is a reason the executor gives up for (a plan that
        failed, too many reflexes, the time limit); a fall takes precedence.
        """
        distance = float(np.linalg.norm(self.goal - self.start_centroid))
        final = float(np.linalg.norm(self.last_centroid - self.goal))
        start = self.first_motion if self.first_motion is not None else end_time
        reached = self.reached_at is not None and final <= self.config.goal_radius_m * 1.5
        if self.fall_reason is not None:
            success, reason = False, f"fell: {self.fall_reason}"
        elif failure is not None:
            success, reason = False, failure
        elif not reached:
            success, reason = False, f"did not reach the goal: ended {final:.3f} m from it"
        else:
            success, reason = True, "reached the goal"
        stop = self.reached_at if (success and self.reached_at is not None) else end_time
        elapsed = max(float(stop - start), 0.0)
        speed = 100.0 * distance / elapsed if success and elapsed > 0 else 0.0
        return Outcome(
            success=success,
            reason=reason,
            distance_m=distance,
            time_s=elapsed,
            speed_cm_s=speed,
            reflexes=reflexes,
            replans=replans,
            foot_slips=self.foot_slips,
            wait_s=wait_s,
            replan_s=replan_s,
            fell=self.fell,
            final_distance_m=final,
            max_roll_rad=self.max_roll,
            max_pitch_rad=self.max_pitch,
            shin_contacts=self.shin_contacts,
            self_contacts=self.self_contacts,
            steps=steps,
            relaxed_plans=relaxed_plans,
            extra=dict(extra or {}),
        )
