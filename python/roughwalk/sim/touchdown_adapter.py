"""The :class:`TouchdownAdapter`: feet that meet the ground before or after their plan.

The plan's footholds come from the map, and the map and the real ground
differ by millimetres: on a rock's edge or a steep slope a millimetre is the
difference between a foot that bears its load and one that hangs just
above the ground. Both cases were seen in MuJoCo on the LittleDog
sloped-rocks board (Y): a hind foot that hung 1–2 mm over a rock's edge
for the whole four-foot shift, so that when the next foot lifted the robot
tipped onto its diagonal and a foot-force reflex fired; and a front foot
that landed early, high, and was then pushed down towards its planned
height.

Per leg, a vertical offset h [m, world] moves the foot's target:

* early touchdown: a swing foot within ``early_window_s`` of its planned
  touchdown that already pushes on the ground (vertical force above
  ``early_force_n``) stops where it stands: h ≥ z_measured − z_planned;
* late touchdown: a foot planned to support that bears less than
  ``loaded_n`` searches downward, h ← h − v·dt, down to −``search_max_m``,
  until it does, but only while the trunk is where planned (orientation
  error below ``max_tilt_rad``): a foot lifted by a rocking trunk must not
  be lengthened;
* in flight (and in every motion that is not a footstep) h fades to zero
  with ``release_s``, so the next foot lands where planned.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.config import TouchdownConfig
from roughwalk.sim.reflexes import orientation_error

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = ["TouchdownAdapter"]


class TouchdownAdapter:
    """The four feet's vertical target offsets h (4,) [m, world] for early and late touchdowns.

    Parameters
    ----------
    config:
        Thresholds, search speed and depth (:class:`TouchdownConfig`).
    control_dt:
        The control period [s] (one update per tick).
    """

    def __init__(self, config: TouchdownConfig | None = None, control_dt: float = 0.002) -> None:
        self.config = config if config is not None else TouchdownConfig()
        self.dt = control_dt
        self.height = np.zeros(4)
        self._decay = math.exp(-control_dt / self.config.release_s)

    def reset(self) -> None:
        """Zero every offset (a reflex, a new plan)."""
        self.height[:] = 0.0

    def update(self, desired: DesiredState, measured: MeasuredState) -> NDArray[np.float64]:
        """Update h from this tick's contacts; returns the body-frame foot offsets (4, 3) [m].

        ``desired`` is the plan's state (its trunk orientation R turns the
        world offsets into body-frame ones, Rᵀ·(0, 0, h)).
        """
        cfg = self.config
        if not cfg.enabled:
            return np.zeros((4, 3))
        h = self.height
        if desired.kind != "step":
            h *= self._decay
        else:
            fz = np.asarray(measured.foot_forces)[:, 2]
            down = np.asarray(desired.support, dtype=bool)
            early = ~down & (desired.touchdown_in <= cfg.early_window_s) & (fz > cfg.early_force_n)
            landed = measured.feet[:, 2] - desired.feet[:, 2]
            h[early] = np.maximum(h[early], landed[early])
            flying = ~down & ~early
            h[flying] *= self._decay
            level = orientation_error(measured.base_quat, desired.base_quat) < cfg.max_tilt_rad
            if level:
                search = down & (fz < cfg.loaded_n)
                h[search] = np.maximum(h[search] - cfg.search_rate_m_s * self.dt, -cfg.search_max_m)
        if not np.any(h):
            return np.zeros((4, 3))
        rot = quat_to_matrix(desired.base_quat)
        return np.outer(h, rot[2])
