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
    swing_end:
        (4,) time [s] the current swing of each foot ends (NaN in stance;
        None when the reference does not know).
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
    swing_end: NDArray[np.float64] | None = None

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

    def __init__(
        self, duration: float, sampler: Any, name: str = "reference", batch: Any = None
    ) -> None:
        if not (math.isfinite(duration) and duration >= 0):
            raise PlanningError(f"a reference needs a duration ≥ 0 s, got {duration}")
        self.duration = float(duration)
        self.name = name
        self._sampler = sampler
        self._batch = batch
        self._final: ReferenceSample | None = None

    def sample_many(self, times: ArrayLike) -> list[ReferenceSample]:
        """The planned states at ``times`` [s] (one vectorised spline evaluation when it can)."""
        ts = [float(t) for t in np.atleast_1d(np.asarray(times, dtype=float))]
        inside = [t for t in ts if t < self.duration]
        if self._batch is not None and inside:
            rows = iter(self._batch(np.maximum(np.array(inside), 0.0)))
            return [next(rows) if t < self.duration else self(t) for t in ts]
        return [self(t) for t in ts]

    def tabulated(self, rate_hz: float) -> Reference:
        """The same reference with its samples at multiples of 1/``rate_hz`` [s] computed once.

        A controller asks for the same instants every run; other instants are
        sampled as before.
        """
        n = int(math.ceil(self.duration * rate_hz - 1e-9)) + 1
        table = self.sample_many(np.arange(n) / rate_hz)

        def sample(t: float) -> ReferenceSample:
            k = round(t * rate_hz)
            if abs(k - t * rate_hz) < 1e-6 and 0 <= k < n:
                return table[k]
            return self(t)

        return Reference(self.duration, sample, name=self.name, batch=self.sample_many)

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
                None if end.swing_end is None else np.full(4, np.nan),
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

        stance_phase = [
            np.array([schedule.is_stance(i, k) for k in range(len(bounds[i]) - 1)])
            for i in range(4)
        ]

        def progress(foot: int, t: NDArray[np.float64]) -> NDArray[np.float64]:
            """(len(t), 2): swing fraction elapsed and the swing's end [s]; (0, NaN) in stance."""
            b = bounds[foot]
            k = np.clip(np.searchsorted(b, t, side="left") - 1, 0, len(b) - 2)
            span = np.maximum(b[k + 1] - b[k], 1e-9)
            swing = ~stance_phase[foot][k]
            return np.stack(
                [np.where(swing, (t - b[k]) / span, 0.0), np.where(swing, b[k + 1], np.nan)],
                axis=1,
            )

        def sample_many(times: NDArray[np.float64]) -> list[ReferenceSample]:
            lin = splines.base_linear.evaluate(times)
            ang = splines.base_angular.evaluate(times)
            feet = [f.evaluate(times) for f in splines.feet]
            forces = np.stack([f.evaluate(times)[0] for f in splines.forces], axis=1)
            contact = np.stack([schedule.in_contact(i, times) for i in range(4)], axis=1)
            swings_all = np.stack([progress(i, times) for i in range(4)], axis=1)
            out = []
            for j, t in enumerate(times):
                com, com_vel, com_acc = lin[0][j], lin[1][j], lin[2][j]
                euler, rates, euler_acc = ang[0][j], ang[1][j], ang[2][j]
                rot = np.asarray(euler_to_rotation(euler))
                omega = np.asarray(angular_velocity(euler, rates))
                alpha = np.asarray(angular_acceleration(euler, rates, euler_acc))
                r = rot @ offset
                w_r = _cross(omega, r)
                swings = swings_all[j]
                out.append(
                    ReferenceSample(
                        t=float(t),
                        base_pos=com - r,
                        base_rot=rot,
                        base_vel=com_vel - w_r,
                        base_angvel=omega,
                        base_acc=com_acc - _cross(alpha, r) - _cross(omega, w_r),
                        base_angacc=alpha,
                        feet_pos=np.array([f[0][j] for f in feet]),
                        feet_vel=np.array([f[1][j] for f in feet]),
                        feet_acc=np.array([f[2][j] for f in feet]),
                        contact=contact[j].astype(bool),
                        forces=forces[j],
                        swing_progress=swings[:, 0],
                        com_pos=com,
                        com_vel=com_vel,
                        com_acc=com_acc,
                        swing_end=swings[:, 1],
                    )
                )
            return out

        def sample(t: float) -> ReferenceSample:
            return sample_many(np.array([t]))[0]

        return cls(
            result.duration, sample, name=f"{schedule.name or 'trajopt'} motion", batch=sample_many
        )

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


def _cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cross product a × b of 3-vectors (np.cross costs ~20 µs a call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def load_trajectory(source: str | Path | dict[str, Any] | TrajoptResult) -> TrajoptResult:
    """A :class:`TrajoptResult` from a result, its ``to_dict()`` or an optimize JSON path."""
    if isinstance(source, TrajoptResult):
        return source
    if isinstance(source, dict):
        return TrajoptResult.from_dict(source)
    return TrajoptResult.load(source)
