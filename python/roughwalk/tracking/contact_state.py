"""The contact state machine: planned against measured contact, per leg.

A plan says when each foot is in stance; the ground says when it really
is. Bellicoso et al. 2016's controller (which Melon et al. 2020 §V used)
reconciles the two; this one does the same with four states per leg:

- ``SWING``: planned swing, no touch that counts — track the swing spline.
- ``STANCE``: planned stance and touching (or touched since) — the foot
  bears load and must not move.
- ``EARLY_TOUCHDOWN``: planned swing, but the foot touched after most of
  its swing — treat it as stance (stop pushing it into the ground).
- ``LATE_TOUCHDOWN``: planned stance, not touching — keep reaching down
  (the ground is lower than planned) and carry no load.

A stance foot that slides faster than a threshold is ``slipping``: the
controller then holds it harder and raises the base gains.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.tracking.config import ContactStateConfig

__all__ = ["LegContact", "ContactEstimate", "ContactStateMachine"]


class LegContact(enum.Enum):
    """What a leg is doing, planned and measured together."""

    SWING = "swing"
    STANCE = "stance"
    EARLY_TOUCHDOWN = "early_touchdown"
    LATE_TOUCHDOWN = "late_touchdown"

    @property
    def bears_load(self) -> bool:
        """Whether the QP may put a contact force on this foot."""
        return self in (LegContact.STANCE, LegContact.EARLY_TOUCHDOWN)


@dataclass(frozen=True)
class ContactEstimate:
    """The state machine's output at one tick.

    Attributes
    ----------
    states:
        Per leg, its :class:`LegContact`.
    slipping:
        (4,) stance feet sliding faster than the slip threshold.
    late_since:
        (4,) time [s] since a late-touchdown leg started reaching down (0 otherwise).
    """

    states: tuple[LegContact, ...]
    slipping: NDArray[np.bool_]
    late_since: NDArray[np.float64]

    @property
    def stance(self) -> NDArray[np.bool_]:
        """(4,) legs that may carry load."""
        return np.array([s.bears_load for s in self.states])


class ContactStateMachine:
    """Per-leg contact states from planned contact, swing progress and measured forces.

    Parameters
    ----------
    config:
        Thresholds (:class:`~roughwalk.tracking.config.ContactStateConfig`).
    """

    def __init__(self, config: ContactStateConfig | None = None) -> None:
        self.config = config if config is not None else ContactStateConfig()
        self.states: list[LegContact] = [LegContact.STANCE] * 4
        self._late_start = np.full(4, np.nan)
        self.counts = {"early_touchdown": 0, "late_touchdown": 0, "slip": 0}
        self._slipping = np.zeros(4, dtype=bool)

    def update(
        self,
        t: float,
        planned_contact: ArrayLike,
        swing_progress: ArrayLike,
        normal_force: ArrayLike,
        foot_speed: ArrayLike,
        on_ground: ArrayLike | None = None,
    ) -> ContactEstimate:
        """Advance every leg's state to time ``t`` [s].

        Parameters
        ----------
        t:
            Time [s].
        planned_contact:
            (4,) planned stance flags.
        swing_progress:
            (4,) fraction of the current planned swing elapsed (0 in stance).
        normal_force:
            (4,) measured normal force on each foot [N].
        foot_speed:
            (4,) measured foot speed [m/s].
        on_ground:
            (4,) the foot touches the terrain at all (a contact exists, whatever
            its force); None: judge by the force alone. A foot planned in stance
            that rests on the ground is in stance even when lightly loaded:
            else it counts as late, gets no force, and its search presses it
            down with the few newtons a free leg's acceleration takes, which
            never reach the touch threshold (issue 10: on the double pallet
            both left feet stood on the pallet unloaded for a second while the
            robot tipped over its right legs).
        """
        cfg = self.config
        planned = np.asarray(planned_contact, dtype=bool)
        progress = np.asarray(swing_progress, dtype=float)
        normal = np.asarray(normal_force, dtype=float)
        touching = normal > cfg.contact_force_n
        # Hysteresis, not a delay: a loaded foot stays loaded down to a smaller
        # force, but one that has left the ground must not be pushed on (the
        # torques meant for a contact would whirl a free leg).
        holding = normal > cfg.release_force_n
        grounded = (
            np.zeros(4, dtype=bool) if on_ground is None else np.asarray(on_ground, dtype=bool)
        )
        speed = np.asarray(foot_speed, dtype=float)
        for leg in range(4):
            old = self.states[leg]
            if planned[leg]:
                if touching[leg] or grounded[leg] or (old.bears_load and holding[leg]):
                    new = LegContact.STANCE
                else:
                    new = LegContact.LATE_TOUCHDOWN
            elif old == LegContact.EARLY_TOUCHDOWN and holding[leg]:
                new = LegContact.EARLY_TOUCHDOWN
            elif touching[leg] and progress[leg] >= cfg.early_touchdown_phase:
                new = LegContact.EARLY_TOUCHDOWN
            else:
                new = LegContact.SWING
            if new == LegContact.LATE_TOUCHDOWN and old != LegContact.LATE_TOUCHDOWN:
                self._late_start[leg] = t
                if old == LegContact.SWING:
                    self.counts["late_touchdown"] += 1
            if new == LegContact.EARLY_TOUCHDOWN and old == LegContact.SWING:
                self.counts["early_touchdown"] += 1
            if new != LegContact.LATE_TOUCHDOWN:
                self._late_start[leg] = np.nan
            self.states[leg] = new
        stance = np.array([s.bears_load for s in self.states])
        slipping = stance & holding & (speed > cfg.slip_speed_m_s)
        self.counts["slip"] += int(np.count_nonzero(slipping & ~self._slipping))
        self._slipping = slipping
        late = np.where(np.isnan(self._late_start), 0.0, t - np.nan_to_num(self._late_start))
        return ContactEstimate(tuple(self.states), slipping, late)
