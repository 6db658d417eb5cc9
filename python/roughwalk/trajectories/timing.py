"""How long a footstep takes: its shift and swing phases (Zucker 2011, §5.2–5.3).

"LittleDog's maximum walking speed is largely dictated by the maximum
7.5 rad/s hip joint velocity and 14 rad/s knee joint velocity. Therefore,
footstep timing can be well approximated by computing the maximum over all
joints of minimum time to move the joint from initial to final position."
A footstep is a shift phase (four feet down, the centre of pressure moves
into the next support triangle) followed by a step (swing) phase.

The shift uses that rule with a margin (the CoM's smooth motion peaks near
twice its mean speed), over the peak joint rate along the trunk's path rather
than only its ends: a supporting leg near the edge of its reach turns its
joints several times faster per metre of trunk motion, so a shift that moves
the ZMP little (and whose floor is small, :meth:`TimingConfig.shift_floor`)
is still long enough for its legs. The swing foot follows a known spline, so
its leg's minimum time is exact: the least duration at which the spline's
peak joint speeds stay within the limits (:func:`min_profile_time`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.config import TimingConfig

__all__ = ["StepTiming", "min_joint_time", "min_profile_time", "step_timing"]

PHASES = ("shift", "swing", "settle")


def min_joint_time(path: ArrayLike, velocity_limit: ArrayLike) -> float:
    """Least time [s] to follow joint waypoints (K, J) [rad] at limits (J,) [rad/s].

    The maximum over joints of the total angle each travels divided by its
    limit; joints without a limit (inf) take no time.
    """
    q = np.asarray(path, dtype=float)
    v = np.asarray(velocity_limit, dtype=float).reshape(-1)
    q = q.reshape(q.shape[0], -1)
    if q.shape[1] != v.shape[0]:
        raise InvalidArgumentError(
            f"joint path has {q.shape[1]} joints but {v.shape[0]} velocity limits were given"
        )
    if np.any(v <= 0):
        raise InvalidArgumentError(f"velocity limits must be positive [rad/s], got {v.tolist()}")
    travel = np.abs(np.diff(q, axis=0)).sum(axis=0)
    return float(np.max(travel / v)) if travel.size else 0.0


def min_profile_time(profile: ArrayLike, velocity_limit: ArrayLike) -> float:
    """Least duration [s] of a motion sampled at K uniform time fractions (K, J) [rad].

    The motion's shape is fixed and only its duration T scales: joint j's
    peak speed is max_k |Δq_j|·(K − 1)/T, so T ≥ that over the limit v_j.
    """
    q = np.asarray(profile, dtype=float)
    q = q.reshape(q.shape[0], -1)
    v = np.asarray(velocity_limit, dtype=float).reshape(-1)
    if q.shape[1] != v.shape[0] or q.shape[0] < 2:
        raise InvalidArgumentError(
            f"a joint profile needs K ≥ 2 samples of {v.shape[0]} joints, got {q.shape}"
        )
    peak = np.abs(np.diff(q, axis=0)).max(axis=0) * (q.shape[0] - 1)
    return float(np.max(peak / v))


@dataclass(frozen=True)
class StepTiming:
    """Phase durations of one footstep [s]: shift, swing, and (last step only) settle."""

    shift_s: float
    swing_s: float
    settle_s: float = 0.0

    @property
    def duration_s(self) -> float:
        """Whole footstep [s]."""
        return self.shift_s + self.swing_s + self.settle_s

    def scaled(self, factor: float) -> StepTiming:
        """Every phase lengthened by ``factor`` (a restart, §5.3); settling is kept."""
        return replace(self, shift_s=self.shift_s * factor, swing_s=self.swing_s * factor)

    def samples(self, dt: float) -> tuple[int, int, int]:
        """Sample intervals (shift, swing, settle) at period ``dt`` [s], each rounded up.

        The swing gets at least 2 intervals so the foot has an airborne
        sample; the shift at least 1.
        """
        if not (math.isfinite(dt) and dt > 0):
            raise InvalidArgumentError(f"sample period must be positive [s], got {dt}")

        def count(t: float, least: int) -> int:
            return max(least, math.ceil(t / dt - 1e-9)) if t > 0 or least else 0

        return count(self.shift_s, 1), count(self.swing_s, 2), count(self.settle_s, 0)

    def quantized(self, dt: float) -> StepTiming:
        """The same phases rounded up to whole sample periods ``dt`` [s]."""
        n_shift, n_swing, n_settle = self.samples(dt)
        return StepTiming(n_shift * dt, n_swing * dt, n_settle * dt)


def step_timing(
    shift_path: ArrayLike,
    swing_profile: ArrayLike,
    velocity_limit: ArrayLike,
    config: TimingConfig,
    swing_leg: int,
    settle: bool = False,
    zmp_travel: float | None = None,
    from_rest: bool = False,
) -> StepTiming:
    """Phase durations [s] of one footstep from its joint motion.

    Parameters
    ----------
    shift_path:
        Joint angles (K ≥ 2, 4, 3) [rad] at K uniform fractions of the
        trunk's path in the shift (from its start pose to the pose
        certificate with all four feet held); timed by their peak rate
        (:func:`min_profile_time`), which for K = 2 is the ends' travel.
    swing_profile:
        The swing leg's angles (K, 3) [rad] along its foot spline at K
        uniform time fractions (start to target).
    velocity_limit:
        (4, 3) joint limits [rad/s], canonical.
    config:
        Margins and least durations.
    swing_leg:
        Canonical index of the swing leg.
    settle:
        Add the final settling phase (the plan's last step).
    zmp_travel:
        How far [m] the shift moves the ZMP; the shift's floor is then
        :meth:`TimingConfig.shift_floor` of it (None: ``min_shift_s``).
    from_rest:
        The step starts from rest (a plan's first): its shift takes at
        least :attr:`TimingConfig.first_shift_s` too.
    """
    limits = np.asarray(velocity_limit, dtype=float).reshape(4, 3)
    floor = config.min_shift_s if zmp_travel is None else config.shift_floor(zmp_travel)
    if from_rest:
        floor = max(floor, config.first_shift_s)
    shift = min_profile_time(
        np.asarray(shift_path, dtype=float).reshape(-1, 12), limits.reshape(12)
    )
    swing = min_profile_time(
        np.asarray(swing_profile, dtype=float).reshape(-1, 3), limits[swing_leg]
    )
    return StepTiming(
        shift_s=min(max(floor, config.velocity_margin * shift), config.max_step_s),
        swing_s=min(
            max(config.min_swing_s, config.swing_velocity_margin * swing), config.max_step_s
        ),
        settle_s=config.settle_s if settle else 0.0,
    )
