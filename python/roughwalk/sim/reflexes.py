"""The :class:`ReflexMonitor`: execution errors large enough to stop walking (Zucker 2011, §6).

"Execution errors larger than a certain threshold trigger a reflex module
which attempts to restore the robot's balance and place all four feet
firmly on the ground. The reflex module can be triggered by body position
or orientation errors, foot position errors, or foot force errors."

Opt-in, a fifth trigger: the one-sided state (:func:`tipping_off`), every
loaded foot on one side while the trunk rolls over them.

Each error must persist for :attr:`ReflexConfig.persist_s` so that the
transients of a touchdown do not fire it. The recovery motion itself is
:func:`roughwalk.sim.recovery.recovery_segment`; the executor then re-plans.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from roughwalk.robots._rotations import quat_multiply
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.sim.config import ReflexConfig

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = [
    "ReflexMonitor",
    "ReflexTrigger",
    "lean_toward",
    "orientation_error",
    "tipping_off",
    "SIDES",
]

_KINDS = ("body_position", "body_orientation", "foot_position", "foot_force", "one_sided")

SIDES = ((0, 2), (1, 3))
"""The canonical legs of the left side (LF, LH) and of the right side (RF, RH)."""


@dataclass(frozen=True)
class ReflexTrigger:
    """Why a reflex fired.

    ``kind`` is one of body_position, body_orientation, foot_position,
    foot_force, one_sided (``ReflexConfig.one_sided``); ``value`` and
    ``threshold`` are in SI units; ``leg`` is the leg concerned (or None);
    ``time`` the simulated time [s].
    """

    kind: str
    value: float
    threshold: float
    leg: str | None
    time: float

    def describe(self) -> str:
        """One line for logs and reports."""
        where = f" ({self.leg})" if self.leg else ""
        return f"{self.kind}{where}: {self.value:.3g} beyond {self.threshold:.3g}"


def orientation_error(a: np.ndarray, b: np.ndarray) -> float:
    """Angle [rad] of the rotation between orientations ``a`` and ``b`` (w, x, y, z)."""
    rel = quat_multiply(a, b * np.array([1.0, -1.0, -1.0, -1.0]))
    return float(2.0 * np.arccos(np.clip(abs(rel[0]), 0.0, 1.0)))


def lean_toward(com: np.ndarray, feet: np.ndarray, support: np.ndarray) -> np.ndarray:
    """How far [m] the centre of mass leans towards each supporting foot, past the others' line.

    With three feet down (``support`` (4,)), the distance of ``com``'s
    ground point from the line through the two other supporting feet
    (``feet`` (4, 3) [m]), positive on the foot's side: the robot leans
    onto that foot, and gravity presses it down. A robot balanced on that
    line, or leaning away from it, tips off the foot instead. NaN for a foot
    not down, or with other than three down.
    """
    out = np.full(4, np.nan)
    down = np.flatnonzero(support)
    if len(down) != 3:
        return out
    p = np.asarray(com, dtype=float)[:2]
    for leg in down:
        a, b = (feet[k, :2] for k in down if k != leg)
        along = b - a
        length = float(np.linalg.norm(along))
        if length < 1e-9:
            continue
        normal = np.array([-along[1], along[0]]) / length
        if float(np.dot(feet[leg, :2] - a, normal)) < 0.0:
            normal = -normal
        out[leg] = float(np.dot(p - a, normal))
    return out


def tipping_off(
    support: np.ndarray,
    loaded: np.ndarray,
    feet: np.ndarray,
    angvel: np.ndarray,
) -> tuple[float, int | None]:
    """How fast [rad/s] the trunk rolls over its loaded side, lifting the other side's feet.

    ``support`` (4,) the feet planned down, ``loaded`` (4,) those bearing
    load, ``feet`` (4, 3) [m] where they are, ``angvel`` (3,) [rad/s] the
    trunk's angular velocity (world axes). When every loaded foot is on
    one side (:data:`SIDES`) and a foot of the other side is planned down
    (bearing nothing), the rate is the trunk's rotation about the line
    through that side's two feet (the support polygon's edge there, whether
    one or both of them bear the load) in the sense that lifts the other side
    (negative: it comes down), with the leg of a planned-down foot there.
    (0, None) in any other state.

    Diagonals are not watched: a crawl stands on one while a foot swings,
    and the three-foot foot-force check judges that (on the 1 N·s right
    push at 2.0 s, a diagonal version fired 0.07 s before that check and
    the robot fell: the swinging RH, stepped out by the capture offset of
    that instant, went down 4 cm less far out).
    """
    if not np.any(loaded):
        return 0.0, None
    for side, other in (SIDES, SIDES[::-1]):
        if any(loaded[k] for k in other):
            continue
        lifted = [k for k in other if support[k]]
        if not lifted:
            continue
        a, b = side
        along = np.array([*(feet[b, :2] - feet[a, :2]), 0.0])
        length = float(np.linalg.norm(along))
        if length < 1e-9:
            continue
        along /= length
        # A rotation ω·along lifts a point on the side where (along × offset)·z > 0.
        offset = np.array([*(feet[lifted[0], :2] - feet[a, :2]), 0.0])
        lifts = 1.0 if float(np.cross(along, offset)[2]) > 0 else -1.0
        return float(np.dot(angvel, along)) * lifts, lifted[0]
    return 0.0, None


class ReflexMonitor:
    """Compares the measured state with the desired one every tick."""

    def __init__(self, config: ReflexConfig | None = None) -> None:
        self.config = config if config is not None else ReflexConfig()
        self._since: dict[str, float | None] = dict.fromkeys(_KINDS)
        self._down_since = np.full(4, np.inf)
        self._short_leg: str | None = None
        self._last_desired_z: tuple[float, float] | None = None  # (time [s], trunk height [m])

    def reset(self) -> None:
        """Forget persisting errors (after a reflex, or when a new plan starts)."""
        self._since = dict.fromkeys(_KINDS)
        self._down_since[:] = np.inf
        self._short_leg = None
        self._last_desired_z = None

    def planned_descent(self, desired: DesiredState, now: float) -> float:
        """The planned trunk's descent rate [m/s] since the last tick (0 on the first one)."""
        z = float(desired.base_pos[2])
        last, self._last_desired_z = self._last_desired_z, (now, z)
        if last is None or not 0.0 < now - last[0] <= 0.02:
            return 0.0
        return (last[1] - z) / (now - last[0])

    def errors(
        self, desired: DesiredState, measured: MeasuredState
    ) -> dict[str, tuple[float, float, str | None]]:
        """Each error's (value, threshold, leg) at this instant (the worst leg for foot errors)."""
        cfg = self.config
        now = measured.time
        down = desired.support
        # A foot's position and force are judged once it has been down a while:
        # a landing a few millimetres off is not a slip.
        self._down_since = np.where(down, np.minimum(self._down_since, now), np.inf)
        settled = down & (now - self._down_since >= 2 * cfg.persist_s)
        tilt = orientation_error(measured.base_quat, desired.base_quat)
        out: dict[str, tuple[float, float, str | None]] = {
            "body_position": (
                float(np.linalg.norm(measured.base_pos - desired.base_pos)),
                cfg.body_position_m,
                None,
            ),
            "body_orientation": (tilt, cfg.body_orientation_rad, None),
        }
        foot_error = np.where(settled, np.linalg.norm(measured.feet - desired.feet, axis=1), 0.0)
        worst = int(np.argmax(foot_error))
        out["foot_position"] = (float(foot_error[worst]), cfg.foot_position_m, LEG_NAMES[worst])
        planned = desired.forces[:, 2]
        # With four feet down the load sharing is statically indeterminate: a
        # foot a millimetre high carries nothing and the robot is still fine.
        # With three, a planned load the foot does not carry means tipping.
        determinate = bool(np.sum(down) == 3)
        tipping = tilt > cfg.foot_force_tilt_rad
        # A trunk lowered on purpose (a front foot reaching a trench floor)
        # tilts and leaves a lightly planned foot light: no sign of a tip,
        # while the robot leans onto that foot (it will bear again) rather
        # than balancing on the other two (board AE: a foot on a rock face).
        descending = self.planned_descent(desired, now) > cfg.foot_force_descent_m_s
        least = np.full(4, cfg.foot_force_n)
        if descending and cfg.foot_force_descent_n > cfg.foot_force_n:
            lean = lean_toward(measured.com, measured.feet, down)
            leaning = np.nan_to_num(lean, nan=-np.inf) >= cfg.foot_force_descent_lean_m
            least = np.where(leaning, cfg.foot_force_descent_n, least)
        loaded = settled & (planned >= least) & determinate & tipping
        shortfall = np.where(loaded, planned - measured.foot_forces[:, 2], 0.0)
        limit = np.where(loaded, (1.0 - cfg.foot_force_fraction) * planned, np.inf)
        ratio = shortfall / limit
        worst = int(np.argmax(ratio))
        out["foot_force"] = (
            float(shortfall[worst]),
            float(limit[worst]) if np.isfinite(limit[worst]) else float("inf"),
            LEG_NAMES[worst],
        )
        if cfg.one_sided:
            loaded_feet = measured.foot_forces[:, 2] > cfg.one_sided_loaded_n
            rate, leg = tipping_off(down, loaded_feet, measured.feet, measured.base_angvel)
            out["one_sided"] = (
                rate,
                cfg.one_sided_rate_rad_s,
                LEG_NAMES[leg] if leg is not None else None,
            )
        return out

    def check(self, desired: DesiredState, measured: MeasuredState) -> ReflexTrigger | None:
        """The trigger if an error has stayed beyond its threshold long enough, else None."""
        if not self.config.enabled:
            return None
        now = measured.time
        fired: ReflexTrigger | None = None
        for kind, (value, threshold, leg) in self.errors(desired, measured).items():
            if value > threshold:
                since = self._since[kind]
                if kind == "foot_force" and self.config.foot_force_per_leg:
                    # A foot short of load counts from when it, not any foot, fell short.
                    if leg != self._short_leg:
                        since = None
                    self._short_leg = leg
                if since is None:
                    self._since[kind] = since = now
                persist = (
                    self.config.one_sided_persist_s
                    if kind == "one_sided"
                    else self.config.persist_s
                )
                if fired is None and now - since >= persist - 1e-12:
                    fired = ReflexTrigger(kind, value, threshold, leg, now)
            else:
                self._since[kind] = None
        return fired
