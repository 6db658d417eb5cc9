"""The validity report of one footstep trajectory (Zucker 2011, §5.3).

"If, after CHOMP finishes, the trajectory is in collision with the terrain,
or if the leg joint velocity limits are violated, the estimated duration of
the footstep is increased ..." The checks run on the trajectory as it will be
executed, at the control rate: the clearance of every collision capsule
(supporting feet excepted) by the SDF's capsule query, joint and velocity
limits, reachability of the supporting feet, and the ZMP's margin to the
support polygon.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk import _core
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.trajectories.body_pass import compiled_field
from roughwalk.trajectories.config import ValidityConfig
from roughwalk.trajectories.whole_body import LINK_NAMES, WholeBody

__all__ = ["StepReport", "capsule_clearances", "capsule_clearances_numpy", "primitive_names"]


@dataclass(frozen=True)
class StepReport:
    """How one footstep trajectory came out.

    Distances [m], angles [rad], speeds [rad/s], times [s] and [ms].
    ``link_clearance_m`` is the least clearance of each checked link over
    the step ("trunk", "LF_thigh", "LF_shank", the swing "LF_foot", ...);
    ``min_clearance_m`` the least of them but the swing foot, which touches
    the ground at lift-off and touchdown (``swing_foot_clearance_m`` is its
    own, over its airborne samples); ``initial_min_clearance_m`` is
    ``min_clearance_m`` of the initial trajectory of the last attempt. ``velocity_margin``
    is the least of (limit − |q̇|) over joints and samples; ``zmp_margin_m``
    the least signed distance of the ZMP inside the support polygon.
    ``valid`` is False when the step stayed infeasible after every restart;
    it is handed on all the same, as the paper does. ``fitted_shift_s`` and
    ``fitted_swing_s`` are the phases' durations fitted before optimisation
    (``timing.measured_speed``; the nominal timing where that is off, NaN
    where the generator did not say): what the step's ``shift_s`` and
    ``swing_s`` exceed them by is the stretch that the re-timing for joint
    speed limits, the restarts (§5.3) and the fall-back to the nominal
    timing added.
    """

    step: int
    leg: str
    duration_s: float
    shift_s: float
    swing_s: float
    settle_s: float
    min_clearance_m: float
    swing_foot_clearance_m: float
    link_clearance_m: dict[str, float]
    initial_min_clearance_m: float
    joint_limit_margin_rad: float
    velocity_margin_rad_s: float
    velocity_limits_ok: bool
    zmp_margin_m: float
    reachable: bool
    collision_free: bool
    valid: bool
    optimize_ms: float
    attempts: int
    iterations: int
    used_shortcut: bool
    chomp_status: str = ""
    notes: list[str] = field(default_factory=list)
    fitted_shift_s: float = float("nan")
    fitted_swing_s: float = float("nan")

    @property
    def stretch_s(self) -> tuple[float, float]:
        """How much longer [s] the shift and the swing are than fitted (0 where unknown)."""
        return (
            max(self.shift_s - self.fitted_shift_s, 0.0) if self.fitted_shift_s >= 0 else 0.0,
            max(self.swing_s - self.fitted_swing_s, 0.0) if self.fitted_swing_s >= 0 else 0.0,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (a NaN becomes None)."""
        out = asdict(self)
        for k, v in out.items():
            if isinstance(v, float) and v != v:
                out[k] = None
        return out


def primitive_names(wb: WholeBody) -> list[str]:
    """A link name per collision primitive: "trunk", "LF_thigh", "LF_shank", "LF_foot", ..."""
    cm = wb.collision
    out = []
    for k in range(len(cm)):
        if cm.leg[k] < 0:
            out.append("trunk")
        elif cm.is_foot[k]:
            out.append(f"{LEG_NAMES[cm.leg[k]]}_foot")
        else:
            out.append(f"{LEG_NAMES[cm.leg[k]]}_{LINK_NAMES[cm.link[k]]}")
    return out


def capsule_clearances(
    wb: WholeBody,
    sdf: Any,
    q: NDArray[np.float64],
    base_pos: NDArray[np.float64],
    rotation: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Clearance (n, P) [m] of every collision primitive at n configurations (SDF capsule query).

    One Rust call when ``sdf`` is the compiled field; numpy otherwise (and as its reference).
    """
    cm = wb.collision
    core_field = compiled_field(sdf)
    if core_field is not None:
        return _core.capsule_clearances(
            wb.core,
            core_field,
            cm.leg,
            cm.link,
            cm.a,
            cm.b,
            cm.radius,
            np.asarray(q, dtype=float).reshape(-1, 4, 3),
            base_pos,
            rotation,
        )
    return capsule_clearances_numpy(wb, sdf, q, base_pos, rotation)


def capsule_clearances_numpy(
    wb: WholeBody,
    sdf: Any,
    q: NDArray[np.float64],
    base_pos: NDArray[np.float64],
    rotation: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`capsule_clearances` over numpy link frames and any ``query_capsules`` field."""
    cm = wb.collision
    positions, rotations, _, _ = wb.link_frames(q)
    leg = np.maximum(cm.leg, 0)
    link = np.maximum(cm.link, 0)
    on_leg = cm.leg >= 0
    frames_p = positions[:, leg, link]
    frames_r = rotations[:, leg, link]
    a = np.where(on_leg[None, :, None], frames_p + np.einsum("npij,pj->npi", frames_r, cm.a), cm.a)
    b = np.where(on_leg[None, :, None], frames_p + np.einsum("npij,pj->npi", frames_r, cm.b), cm.b)
    aw = base_pos[:, None] + np.einsum("nij,npj->npi", rotation, a)
    bw = base_pos[:, None] + np.einsum("nij,npj->npi", rotation, b)
    n, p = aw.shape[:2]
    d, _ = sdf.query_capsules(aw.reshape(-1, 3), bw.reshape(-1, 3), np.tile(cm.radius, n))
    return np.asarray(d).reshape(n, p)


def clearance_summary(
    wb: WholeBody,
    clearance: NDArray[np.float64],
    support: NDArray[np.bool_],
    validity: ValidityConfig,
    feet: NDArray[np.float64],
    footholds: NDArray[np.float64],
    contact_clearance: float = 0.0,
) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, float], bool]:
    """Clearances of a footstep's samples from its primitives' clearances (n, P) [m].

    Returns the least clearance per sample over the primitives that are not
    feet (n,), the lifted foot's (n,; NaN while all feet are down), the least
    per link, and whether the footstep is collision-free: supporting feet
    are skipped; a lifted foot (centres ``feet`` (n, 4, 3)) near its
    ``footholds`` (K, 3) may dip ``foot_tolerance`` into the field (below
    their ``contact_clearance`` [m]); everything else must keep
    ``min_clearance``.
    """
    cm = wb.collision
    leg = np.maximum(cm.leg, 0)
    checked = ~(cm.is_foot[None, :] & support[:, leg])
    masked = np.where(checked, clearance, np.inf)
    feet_at = feet
    body = masked[:, ~cm.is_foot].min(axis=1)
    foot_min = masked[:, cm.is_foot].min(axis=1)
    foot_min = np.where(np.isinf(foot_min), np.nan, foot_min)
    names = primitive_names(wb)
    per_link: dict[str, float] = {}
    for k, name in enumerate(names):
        col = masked[:, k]
        if np.all(np.isinf(col)):
            continue
        per_link[name] = min(per_link.get(name, np.inf), float(col.min()))
    centres = np.zeros(clearance.shape + (3,))
    foot_rows = np.flatnonzero(cm.is_foot)
    centres[:, foot_rows] = feet_at[:, cm.leg[foot_rows]]
    need = validity.required_clearance(centres, cm.is_foot, footholds, contact_clearance)
    free = bool(np.all(masked >= need))
    return body, foot_min, per_link, free
