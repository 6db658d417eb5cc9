"""The :class:`CopStabilizer`: measured centre of pressure versus the planned ZMP.

The trajectory's trunk motion puts the zero-moment point where the plan
wants it (the cart-table model, Zucker 2011, §5.2), but the model is not the
robot: leg masses, servo sag and feet that settle on rounded rocks move the
real centre of pressure (CoP) by about a centimetre, which on LittleDog's
small support triangles is most of the margin, and a robot on three feet then
tips over the diagonal. Kalakrishnan et al. (IJRR 2010) close this loop on
the real LittleDog by moving the body from the measured CoP; here the trunk
shifts horizontally by s while every foot keeps its world target (the feet's
body-frame targets move by −Rᵀs), and the integrators and reflexes judge the
trunk against the shifted pose.

Feeding the CoP error straight back into s is unstable: the cart-table's
ZMP is p = c − (h/g)·c̈, so a trunk accelerating toward the error first moves
the ZMP away from it, and the faster the loop the worse. The stabiliser
therefore estimates the offset d that the plan and its own shift do not
explain,

    p = Σ f_z,i · p_i / Σ f_z,i                  (measured CoP, x–y [m])
    r = (p − p̄) − (s − (h/g)·s̈)                  (p̄ the planned CoP)
    d ← low-pass(r),    s̈ = ω²(clip(−d, s_max) − s) − 2ω·ṡ

(s follows −d critically damped, so its acceleration is bounded and known)
and cancels it. Only the part of s the model gets wrong (the legs do not
move with the trunk) feeds back, with a gain well below one. The model holds
only while the planned feet, and only they, bear load: when a supporting
foot lets go the CoP is pinned to the support polygon's edge and no longer
follows the trunk, and a swing foot that strikes something is a collision,
not an offset. The estimate then holds still (and fades) until the contacts
have matched the plan again for a while, and the reflexes deal with the rest.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.config import StabilizerConfig

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = ["CopStabilizer", "centre_of_pressure"]

_GRAVITY = 9.81


def centre_of_pressure(
    forces: NDArray[np.float64], feet: NDArray[np.float64], min_load: float = 1e-9
) -> NDArray[np.float64] | None:
    """CoP (2,) [m] of vertical foot forces ``forces`` (4, 3) [N] at ``feet`` (4, 3) [m].

    Pulling (negative) vertical forces count as zero. None when the total
    load is below ``min_load`` [N] (a robot in the air has no CoP).
    """
    fz = np.clip(np.asarray(forces, dtype=float)[:, 2], 0.0, None)
    total = float(fz.sum())
    if total < min_load:
        return None
    return np.asarray((fz @ np.asarray(feet, dtype=float)[:, :2]) / total, dtype=float)


class CopStabilizer:
    """Shifts the trunk horizontally by s (3,) [m, world] to cancel the CoP offset.

    Parameters
    ----------
    config:
        Time constants and bound (:class:`StabilizerConfig`).
    control_dt:
        The control period [s] (one update per tick).
    """

    def __init__(self, config: StabilizerConfig | None = None, control_dt: float = 0.002) -> None:
        self.config = config if config is not None else StabilizerConfig()
        cfg = self.config
        self.dt = control_dt
        self.shift = np.zeros(3)
        self.offset = np.zeros(2)
        """The estimated CoP offset d (2,) [m] the plan does not explain."""
        self.velocity = np.zeros(2)
        self.acceleration = np.zeros(2)
        self._estimate = 1.0 - math.exp(-control_dt / cfg.estimate_s)
        self._omega = 1.0 / cfg.follow_s
        self._leak = math.exp(-control_dt / cfg.leak_s)
        self._mismatch_at = -math.inf

    def reset(self) -> None:
        """Zero the shift and the estimate."""
        self.shift[:] = 0.0
        self.offset[:] = 0.0
        self.velocity[:] = 0.0
        self.acceleration[:] = 0.0
        self._mismatch_at = -math.inf

    def update(self, desired: DesiredState, measured: MeasuredState) -> DesiredState:
        """Update s from this tick's CoP; returns ``desired`` with its trunk moved by s."""
        cfg = self.config
        if not cfg.enabled:
            return desired
        support = desired.support
        planned = centre_of_pressure(desired.forces * support[:, None], desired.feet)
        cop = centre_of_pressure(measured.foot_forces, measured.feet, cfg.min_load_n)
        s = self.shift[:2].copy()
        loaded = measured.foot_forces[:, 2] > cfg.min_foot_n
        if np.any(loaded != support) or desired.kind != "step":
            self._mismatch_at = measured.time
        if planned is None or cop is None or measured.time - self._mismatch_at < cfg.holdoff_s:
            # Nothing the model explains: let the shift fade.
            self.offset *= self._leak
            target = -self.offset
        else:
            height = float(desired.base_pos[2] - desired.feet[support, 2].mean())
            explained = s - (max(height, 0.0) / _GRAVITY) * self.acceleration
            residual = (cop - planned) - explained
            self.offset += self._estimate * (residual - self.offset)
            target = -self.offset
        norm = float(np.linalg.norm(target))
        if norm > cfg.max_shift_m:
            target = target * (cfg.max_shift_m / norm)
        w = self._omega
        self.acceleration = w * w * (target - s) - 2.0 * w * self.velocity
        self.velocity = self.velocity + self.acceleration * self.dt
        self.shift[:2] = s + self.velocity * self.dt
        if not np.any(self.shift):
            return desired
        return replace(desired, base_pos=desired.base_pos + self.shift)

    def feet_offset(self, desired: DesiredState) -> NDArray[np.float64]:
        """Body-frame foot offsets (4, 3) [m] −Rᵀs that keep the world footholds in place.

        ``desired`` is the unshifted state (its orientation R).
        """
        rot = quat_to_matrix(desired.base_quat)
        return np.repeat((-(rot.T @ self.shift))[None], 4, axis=0)
