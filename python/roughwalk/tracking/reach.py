"""Reach-aware references: lower the planned base where the legs cannot reach the planned feet.

TOWR's range of motion is a box around each foot's nominal position (Winkler
et al. 2018; Melon et al. 2020 §II), and the box trajopt derives for ANYmal C
(``trajopt.robot_model``) reaches beyond its legs. Trajopt's ``leg_reach``
ball cuts those corners off, so converged plans keep their feet within reach
(0.1 % of 10 ms samples), but a plan stopped after a few iterations from a
learned guess still puts some stance foot out of reach in 25–55 % of its
samples, by up to 20 cm. A whole-body controller asked for such a
base stretches the stance legs through the knee singularity and loses them.
:class:`LegReach` is the legs' real reach; :func:`reach_aware_reference`
lowers the planned base (along world z, smoothly, with consistent velocity
and acceleration) just enough that every planned stance foot stays within a
knee bend of its leg's full extension.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.tracking.reference import Reference, ReferenceSample

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot

__all__ = ["LegReach", "reach_aware_reference"]


class LegReach:
    """How far each leg of an abduction–flexion–knee quadruped reaches.

    A foot sits at a fixed lateral offset from its leg's HAA axis; in the
    plane of the thigh and shank, its distance from the HFE joint is
    r = √(a² + b² + 2ab cos φ) for thigh a, shank b and knee bend φ (0 is
    straight). The leg reaches a point when r ≤ r(φ_min).

    Parameters
    ----------
    robot:
        The quadruped (canonical leg descriptions).
    min_knee_bend_rad:
        Smallest knee bend φ_min [rad] the legs are asked to keep: the
        singular straight knee is where a whole-body controller loses a leg.
    """

    def __init__(self, robot: Robot, min_knee_bend_rad: float = 0.35) -> None:
        legs = robot.description.legs
        self.haa = np.array([leg.body_pos[0] for leg in legs])
        self.hfe_x = np.array([leg.body_pos[1][0] for leg in legs])
        self.lateral = np.array(
            [leg.body_pos[1][1] + leg.body_pos[2][1] + leg.foot[1] for leg in legs]
        )
        lengths = robot.leg_lengths
        a, b = lengths[:, 0], lengths[:, 1]
        self.max_reach = np.sqrt(a * a + b * b + 2 * a * b * math.cos(min_knee_bend_rad))
        self.foot_radius = float(robot.foot_radius)
        self.min_knee_bend_rad = float(min_knee_bend_rad)
        self._robot = robot

    def joint_range(
        self, min_knee_bend_rad: float, max_knee_bend_rad: float, haa_margin_rad: float = 0.05
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(12,) lower and upper joint angles [rad], ``joint_names`` order, a controller keeps.

        Knees stay bent between ``min_knee_bend_rad`` and ``max_knee_bend_rad``
        on their nominal side of the straight knee (found by forward kinematics:
        the angle of longest reach), so a stretched leg cannot snap through to
        the other knee branch; HAA joints stay ``haa_margin_rad`` inside their
        limits; HFE joints are free.
        """
        robot = self._robot
        lower = np.full(12, -np.inf)
        upper = np.full(12, np.inf)
        nominal = robot.nominal_q
        names = robot.joint_names
        for leg, (haa, _, kfe) in enumerate(robot.leg_joint_names):
            i, k = names.index(haa), names.index(kfe)
            lower[i] = robot.joint_lower[i] + haa_margin_rad
            upper[i] = robot.joint_upper[i] - haa_margin_rad
            straight = float(nominal[k])
            for half_width in (math.pi, 0.01):  # a coarse search, then a fine one
                grid = straight + np.linspace(-half_width, half_width, 401)
                reach = []
                for angle in grid:
                    q = nominal.copy()
                    q[k] = angle
                    reach.append(self.distance(robot.foot_positions(q))[leg])
                straight = float(grid[int(np.argmax(reach))])
            if nominal[k] < straight:
                lower[k], upper[k] = straight - max_knee_bend_rad, straight - min_knee_bend_rad
            else:
                lower[k], upper[k] = straight + min_knee_bend_rad, straight + max_knee_bend_rad
        return lower, upper

    def distance(self, feet_in_base: ArrayLike) -> NDArray[np.float64]:
        """(…, 4) HFE-to-foot distance r [m] of foot centres (…, 4, 3) in the base frame."""
        v = np.asarray(feet_in_base, dtype=float) - self.haa
        rho2 = v[..., 1] ** 2 + v[..., 2] ** 2
        h2 = np.maximum(rho2 - self.lateral**2, 0.0)
        return np.asarray(np.sqrt((v[..., 0] - self.hfe_x) ** 2 + h2))

    def excess(self, sample: ReferenceSample) -> NDArray[np.float64]:
        """(4,) how far [m] each planned foot lies beyond its leg's reach (≤ 0: reachable)."""
        centres = sample.feet_pos + np.array([0.0, 0.0, self.foot_radius])
        local = (centres - sample.base_pos) @ sample.base_rot
        return self.distance(local) - self.max_reach

    def base_drops(
        self, samples: list[ReferenceSample], legs: ArrayLike, limit: float = 0.2
    ) -> NDArray[np.float64]:
        """Smallest lowering dz ≥ 0 [m] of each sample's base that brings its ``legs`` within reach.

        ``legs`` is (n, 4) bool; returns (n,), capped at ``limit`` [m]. Bisection
        on dz for all samples at once (each leg's distance falls monotonically
        while the foot is below its hip).
        """
        use = np.asarray(legs, dtype=bool)
        centres = np.array([s.feet_pos for s in samples]) + np.array([0.0, 0.0, self.foot_radius])
        base = np.array([s.base_pos for s in samples])
        rot = np.array([s.base_rot for s in samples])

        def worst(dz: NDArray[np.float64]) -> NDArray[np.float64]:
            rel = centres - (base - dz[:, None] * np.array([0.0, 0.0, 1.0]))[:, None, :]
            local = np.einsum("nlj,nji->nli", rel, rot)
            excess = self.distance(local) - self.max_reach
            return np.asarray(np.where(use, excess, -np.inf).max(axis=1))

        n = len(samples)
        lo, hi = np.zeros(n), np.full(n, limit)
        need = worst(lo) > 0.0
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            out = worst(mid) > 0.0
            lo = np.where(out, mid, lo)
            hi = np.where(out, hi, mid)
        return np.where(need, hi, 0.0)


def _windowed(values: NDArray[np.float64], half: int, op: str) -> NDArray[np.float64]:
    """Moving max or mean over ±``half`` samples along axis 0 (edges held)."""
    pad = [(half, half)] + [(0, 0)] * (values.ndim - 1)
    padded = np.pad(values, pad, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1, axis=0)
    return np.asarray(windows.max(axis=-1) if op == "max" else windows.mean(axis=-1))


def reach_aware_reference(
    reference: Reference,
    reach: LegReach,
    *,
    rate_hz: float = 200.0,
    smoothing_s: float = 0.15,
    limit_m: float = 0.2,
) -> tuple[Reference, NDArray[np.float64], NDArray[np.float64]]:
    """``reference`` with its base lowered where its stance feet are out of ``reach``.

    The lowering dz(t) [m] is the smallest that keeps every planned stance
    foot (and every foot within ``smoothing_s`` [s] of a stance phase) within
    reach, widened by a moving maximum over ``smoothing_s`` [s] and smoothed by
    a moving average over the same window (so it is still ≥ the need
    everywhere), then made a C² cubic spline whose derivatives correct the
    planned velocity and acceleration. Returns the new reference, the sample
    times [s] and dz at them [m] (all zeros: the reference itself).
    """
    from scipy.interpolate import CubicSpline

    if reference.duration * rate_hz < 1.0:
        # Nothing to smooth over: the pose is the plan's (a first pose out of
        # reach is reported as such by the executor).
        return reference, np.zeros(1), np.zeros(1)
    n = max(2, int(math.ceil(reference.duration * rate_hz)) + 1)
    times = np.linspace(0.0, reference.duration, n)
    samples = reference.sample_many(times)
    contact = np.array([s.contact for s in samples])
    half = max(1, round(smoothing_s * rate_hz))
    # A swing foot about to bear load needs the reach too (and one just lifted is harmless).
    soon = _windowed(contact.astype(float), half, "max") > 0
    need = reach.base_drops(samples, soon, limit_m)
    if not need.any():
        return reference, times, np.zeros(n)
    drop = _windowed(_windowed(need, half, "max"), half, "mean")
    spline = CubicSpline(times, drop, bc_type="clamped")
    velocity, acceleration = spline.derivative(1), spline.derivative(2)
    z = np.array([0.0, 0.0, 1.0])
    end = float(times[-1])

    def sample_many(ts: NDArray[np.float64]) -> list[ReferenceSample]:
        tc = np.minimum(ts, end)
        dz, vz, az = spline(tc), velocity(tc), acceleration(tc)
        return [
            _lowered(s, float(dz[i]), float(vz[i]), float(az[i]), z)
            for i, s in enumerate(reference.sample_many(ts))
        ]

    def sample(t: float) -> ReferenceSample:
        return sample_many(np.array([t]))[0]

    lowered = Reference(reference.duration, sample, name=reference.name, batch=sample_many)
    return lowered, times, drop


def _lowered(
    s: ReferenceSample, dz: float, vz: float, az: float, z: NDArray[np.float64]
) -> ReferenceSample:
    from dataclasses import replace

    return replace(
        s,
        base_pos=s.base_pos - dz * z,
        base_vel=s.base_vel - vz * z,
        base_acc=s.base_acc - az * z,
        com_pos=None if s.com_pos is None else s.com_pos - dz * z,
        com_vel=None if s.com_vel is None else s.com_vel - vz * z,
        com_acc=None if s.com_acc is None else s.com_acc - az * z,
    )
