"""The :class:`Reference`: the planned motion a whole-body controller tracks, at any time.

From a :class:`~roughwalk.trajopt.TrajoptResult` the splines are evaluated
exactly (no resampling): base pose, twist and acceleration of the robot's base
frame (the NLP plans its centre of mass c; the base origin is c − R·r_com),
foot positions, velocities and accelerations, contact flags and contact
forces. After the motion's end the reference holds the final pose at rest,
so a tracker can be asked to stand there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import PlanningError
from roughwalk.robots._rotations import matrix_to_quat
from roughwalk.trajopt.result import TrajoptResult
from roughwalk.trajopt.variables import angular_velocity, euler_to_rotation
from roughwalk.trajopt.variables.base_angular import angular_acceleration

__all__ = ["Reference", "ReferenceSample", "load_trajectory"]

_GRAVITY = 9.81


@dataclass(frozen=True)
class ReferenceSample:
    """The planned state at one instant (world frame, SI units).

    Attributes
    ----------
    t:
        Time [s] since the motion's start.
    base_pos, base_vel, base_acc:
        (3,) base frame origin [m], its velocity [m/s] and acceleration [m/s²].
    base_rot:
        (3, 3) base orientation R (base to world).
    base_angvel, base_angacc:
        (3,) angular velocity ω [rad/s] and acceleration ω̇ [rad/s²], world axes.
    feet_pos, feet_vel, feet_acc:
        (4, 3) foot contact points [m], velocities [m/s], accelerations [m/s²].
    contact:
        (4,) planned stance flags.
    forces:
        (4, 3) planned contact forces on the feet [N].
    swing_progress:
        (4,) fraction of the current swing elapsed (0 in stance).
    com_pos, com_vel, com_acc:
        (3,) the planned whole-body centre of mass [m], [m/s], [m/s²] (the
        single rigid body's; None when the reference plans the base only).
    """

    t: float
    base_pos: NDArray[np.float64]
    base_rot: NDArray[np.float64]
    base_vel: NDArray[np.float64]
    base_angvel: NDArray[np.float64]
    base_acc: NDArray[np.float64]
    base_angacc: NDArray[np.float64]
    feet_pos: NDArray[np.float64]
    feet_vel: NDArray[np.float64]
    feet_acc: NDArray[np.float64]
    contact: NDArray[np.bool_]
    forces: NDArray[np.float64]
    swing_progress: NDArray[np.float64]
    com_pos: NDArray[np.float64] | None = None
    com_vel: NDArray[np.float64] | None = None
    com_acc: NDArray[np.float64] | None = None

    @property
    def base_quat(self) -> NDArray[np.float64]:
        """(4,) base orientation (w, x, y, z)."""
        return np.asarray(matrix_to_quat(self.base_rot), dtype=float)


class Reference:
    """Planned motion of a quadruped, sampled at any time [s].

    Build one with :meth:`from_result` (an optimised motion) or
    :meth:`standing` (hold a pose); call it with a time to get a
    :class:`ReferenceSample`. Times past :attr:`duration` give the final
    pose at rest with the final contact forces.
    """

    def __init__(self, duration: float, sampler: Any, name: str = "reference") -> None:
        if not (math.isfinite(duration) and duration >= 0):
            raise PlanningError(f"a reference needs a duration ≥ 0 s, got {duration}")
        self.duration = float(duration)
        self.name = name
        self._sampler = sampler
        self._final: ReferenceSample | None = None

    def __call__(self, t: float) -> ReferenceSample:
        """The planned state at time ``t`` [s] (clamped to [0, duration], at rest after it)."""
        if t < self.duration:
            sample: ReferenceSample = self._sampler(max(float(t), 0.0))
            return sample
        if self._final is None:
            end = self._sampler(self.duration)
            zero3 = np.zeros(3)
            zero43 = np.zeros((4, 3))
            self._final = ReferenceSample(
                self.duration,
                end.base_pos,
                end.base_rot,
                zero3,
                zero3,
                zero3,
                zero3,
                end.feet_pos,
                zero43,
                zero43,
                np.ones(4, dtype=bool) if end.contact.all() else end.contact,
                end.forces,
                np.zeros(4),
                end.com_pos,
                None if end.com_pos is None else zero3,
                None if end.com_pos is None else zero3,
            )
        return replace(self._final, t=float(t))

    # ---- construction ---------------------------------------------------------------

    @classmethod
    def from_result(cls, result: TrajoptResult) -> Reference:
        """The motion of an optimisation result (its splines, exactly)."""
        splines = result.splines
        schedule = result.schedule
        if splines is None or schedule is None:
            raise PlanningError(
                f"nothing to track: the optimisation ended {result.status.value} "
                f"({result.message}) without a trajectory"
            )
        offset = np.asarray(result.body.com_in_base if result.body else (0.0, 0.0, 0.0))
        bounds = [schedule.phase_times(i) for i in range(4)]

        def progress(foot: int, t: float) -> float:
            b = bounds[foot]
            k = int(np.clip(np.searchsorted(b, t, side="left") - 1, 0, len(b) - 2))
            if schedule.is_stance(foot, k):
                return 0.0
            return float((t - b[k]) / max(b[k + 1] - b[k], 1e-9))

        def sample(t: float) -> ReferenceSample:
            com, com_vel, com_acc = (v[0] for v in splines.base_linear.evaluate(t))
            euler, rates, euler_acc = (v[0] for v in splines.base_angular.evaluate(t))
            rot = np.asarray(euler_to_rotation(euler))
            omega = np.asarray(angular_velocity(euler, rates))
            alpha = np.asarray(angular_acceleration(euler, rates, euler_acc))
            r = rot @ offset
            feet = [f.evaluate(t) for f in splines.feet]
            return ReferenceSample(
                t=t,
                base_pos=com - r,
                base_rot=rot,
                base_vel=com_vel - np.cross(omega, r),
                base_angvel=omega,
                base_acc=com_acc - np.cross(alpha, r) - np.cross(omega, np.cross(omega, r)),
                base_angacc=alpha,
                feet_pos=np.array([f[0][0] for f in feet]),
                feet_vel=np.array([f[1][0] for f in feet]),
                feet_acc=np.array([f[2][0] for f in feet]),
                contact=np.array([bool(schedule.in_contact(i, t)[0]) for i in range(4)]),
                forces=np.array([f.evaluate(t)[0][0] for f in splines.forces]),
                swing_progress=np.array([progress(i, t) for i in range(4)]),
                com_pos=com,
                com_vel=com_vel,
                com_acc=com_acc,
            )

        return cls(result.duration, sample, name=f"{schedule.name or 'trajopt'} motion")

    @classmethod
    def standing(
        cls,
        base_pos: ArrayLike,
        feet: ArrayLike,
        mass: float,
        duration: float = 0.0,
        base_rot: ArrayLike | None = None,
    ) -> Reference:
        """Stand still: base at ``base_pos`` [m], feet at ``feet`` (4, 3) [m], weight shared.

        Each foot is planned to carry a quarter of m·g [N] for the robot of
        ``mass`` [kg].
        """
        pos = np.asarray(base_pos, dtype=float).reshape(3)
        rot = np.eye(3) if base_rot is None else np.asarray(base_rot, dtype=float).reshape(3, 3)
        foot_pos = np.asarray(feet, dtype=float).reshape(4, 3)
        forces = np.tile([0.0, 0.0, mass * _GRAVITY / 4.0], (4, 1))
        zero3, zero43 = np.zeros(3), np.zeros((4, 3))

        def sample(t: float) -> ReferenceSample:
            return ReferenceSample(
                t,
                pos,
                rot,
                zero3,
                zero3,
                zero3,
                zero3,
                foot_pos,
                zero43,
                zero43,
                np.ones(4, dtype=bool),
                forces,
                np.zeros(4),
            )

        return cls(duration, sample, name="standing")


def load_trajectory(source: str | Path | dict[str, Any] | TrajoptResult) -> TrajoptResult:
    """A :class:`TrajoptResult` from a result, its ``to_dict()`` or an optimize JSON path."""
    if isinstance(source, TrajoptResult):
        return source
    if isinstance(source, dict):
        return TrajoptResult.from_dict(source)
    return TrajoptResult.load(source)
