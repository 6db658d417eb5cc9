"""The :class:`LiftGate`: a foot lifts only once the feet it leaves the robot on bear.

A statically planned crawl lifts each foot at its planned time. On a rock
the foot that landed last may not yet bear: it hangs a few millimetres over
its foothold while the touchdown search (:mod:`roughwalk.sim.touchdown_adapter`)
lowers it, or it slides down a flank. Lifting the next foot then leaves the
robot on two feet and it tips over their diagonal. The gate holds the plan's
clock at the tick before a lift-off while any foot that stays down bears
less than its share (:class:`~roughwalk.sim.config.LiftGateConfig`), up to
a longest hold; the executor stops the trajectory buffer's clock for those
ticks, so the wait counts against the run's speed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from roughwalk.sim.config import LiftGateConfig

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState, Segment

__all__ = ["LiftGate"]


class LiftGate:
    """Whether to hold a footstep at its lift-off, tick by tick.

    Parameters
    ----------
    config:
        Loads and the longest hold (:class:`LiftGateConfig`).
    control_dt:
        The control period [s] (one :meth:`hold` call per tick).
    """

    def __init__(self, config: LiftGateConfig | None = None, control_dt: float = 0.002) -> None:
        self.config = config if config is not None else LiftGateConfig()
        self.dt = control_dt
        self.held_s = 0.0
        self.released_s = 0.0
        self.short: list[int] = []
        self._spent = False  # this lift-off's longest hold is used up

    def reset(self) -> None:
        """Forget a hold in progress (a reflex, a new plan)."""
        self.held_s = 0.0
        self.released_s = 0.0
        self.short = []
        self._spent = False

    def hold(
        self, segment: Segment, tau: float, desired: DesiredState, measured: MeasuredState
    ) -> bool:
        """Whether to hold the footstep ``segment`` at ``tau`` [s] into it for this tick.

        True when a foot down at ``tau`` is up one tick later and a foot down
        at both bears less than ``least_n`` or ``fraction`` of the load the
        next tick plans on it (the smaller), while the hold so far is shorter
        than ``max_hold_s`` (once that is used up, not again before the foot
        has lifted). ``released_s`` is the length of a hold that
        ended on this call (0 otherwise); ``short`` the legs that held it.
        """
        cfg = self.config
        self.released_s = 0.0
        if not cfg.enabled or segment.kind != "step":
            return self._release()
        after = segment.sample(tau + self.dt)
        down = np.asarray(desired.support, dtype=bool)
        lifting = down & ~np.asarray(after.support, dtype=bool)
        if not np.any(lifting):
            self._spent = False
            return self._release()
        stays = down & np.asarray(after.support, dtype=bool)
        need = np.minimum(cfg.least_n, cfg.fraction * np.maximum(after.forces[:, 2], 0.0))
        short = stays & (np.asarray(measured.foot_forces)[:, 2] < need)
        if self.held_s >= cfg.max_hold_s - 1e-12:
            self._spent = True
        if not np.any(short) or self._spent:
            return self._release()
        self.held_s += self.dt
        self.short = [int(i) for i in np.flatnonzero(short)]
        return True

    def _release(self) -> bool:
        if self.held_s > 0:
            self.released_s = self.held_s
        self.held_s = 0.0
        return False
