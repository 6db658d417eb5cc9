"""Pictures of footstep trajectories: joint angles, clearance and the ZMP against its support."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from roughwalk.trajectories import FootstepTrajectories

__all__ = ["save_trajectory_picture"]

_LEG_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
_JOINT_STYLES = ("-", "--", ":")
_LEGS = ("LF", "RF", "LH", "RH")


def _hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of x–y points, closed (first point repeated)."""
    from roughwalk.trajectories.support_polygon import convex_polygon

    poly = convex_polygon(points)
    return np.vstack([poly, poly[:1]])


def save_trajectory_picture(result: FootstepTrajectories, path: str | Path) -> None:
    """Save a PNG of a plan's footstep trajectories.

    Panels: joint angles over time (legs coloured LF/RF/LH/RH, HAA solid,
    HFE dashed, KFE dotted; swings shaded, invalid steps in red); clearance
    of the body and of the lifted foot over time; joint speeds as a fraction
    of their limits; and, seen from above, the ZMP and its reference inside
    the support polygons, with the CoM path and the footholds.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    data = result.sampled()
    t = data["time"]
    fig, axes = plt.subplots(2, 2, figsize=(15, 9))
    ax_q, ax_xy = axes[0]
    ax_c, ax_v = axes[1]

    for s in result.steps:
        airborne = ~s.support.all(axis=1)
        if np.any(airborne):
            t0, t1 = s.time[airborne][0], s.time[airborne][-1]
            for ax in (ax_q, ax_c, ax_v):
                ax.axvspan(t0, t1, color=_LEG_COLOURS[_LEGS.index(s.leg)], alpha=0.07, lw=0)
        if not s.valid:
            for ax in (ax_q, ax_c, ax_v):
                ax.axvspan(s.time[0], s.time[-1], color="red", alpha=0.08, lw=0)
        for ax in (ax_q, ax_c, ax_v):
            ax.axvline(s.time[0], color="0.6", lw=0.5)

    names = result.joint_names
    for j, name in enumerate(names):
        leg = next((i for i, n in enumerate(_LEGS) if name.upper().startswith(n)), j // 3)
        ax_q.plot(t, data["q"][:, j], color=_LEG_COLOURS[leg % 4], ls=_JOINT_STYLES[j % 3], lw=1)
    ax_q.set_xlabel("t [s]")
    ax_q.set_ylabel("joint angle [rad]")
    ax_q.set_title("joint angles (LF blue, RF orange, LH green, RH red; HAA —, HFE --, KFE ··)")

    ax_c.plot(t, data["clearance"] * 1000, color="0.2", lw=1.2, label="body (all but feet)")
    ax_c.plot(t, data["foot_clearance"] * 1000, color="tab:purple", lw=1, label="lifted foot")
    ax_c.axhline(0.0, color="saddlebrown", lw=1)
    ax_c.set_xlabel("t [s]")
    ax_c.set_ylabel("clearance [mm]")
    top = np.nanpercentile(data["clearance"] * 1000, 95)
    ax_c.set_ylim(
        min(
            -5.0,
            float(np.nanmin(np.concatenate([data["clearance"], data["foot_clearance"]]))) * 1000
            - 2,
        ),
        max(20.0, float(top) * 1.2),
    )
    ax_c.legend(loc="upper right", fontsize=8)
    ax_c.set_title("clearance to the terrain (SDF capsule query)")

    ratio = np.abs(data["qd"]) / result.joint_velocity_limit[None, :]
    for j, name in enumerate(names):
        leg = next((i for i, n in enumerate(_LEGS) if name.upper().startswith(n)), j // 3)
        ax_v.plot(t, ratio[:, j], color=_LEG_COLOURS[leg % 4], ls=_JOINT_STYLES[j % 3], lw=0.8)
    ax_v.axhline(1.0, color="red", lw=1)
    ax_v.set_ylabel("|q̇| / limit")
    ax_v.set_title("joint speeds against their limits")
    ax_v.set_xlabel("t [s]")

    for s in result.steps:
        for phase_support in np.unique(s.support, axis=0):
            rows = np.all(s.support == phase_support, axis=1)
            feet = s.feet[rows][0][phase_support]
            if feet.shape[0] >= 3:
                hull = _hull(feet)
                ax_xy.plot(hull[:, 0], hull[:, 1], color="0.75", lw=0.8)
    feet_all = data["feet"][data["support"]]
    ax_xy.plot(feet_all[:, 0], feet_all[:, 1], "o", color="saddlebrown", ms=3, label="footholds")
    ax_xy.plot(
        data["zmp_reference"][:, 0],
        data["zmp_reference"][:, 1],
        color="tab:green",
        lw=1,
        ls="--",
        label="ZMP reference",
    )
    ax_xy.plot(data["zmp"][:, 0], data["zmp"][:, 1], color="tab:red", lw=1, label="ZMP")
    ax_xy.plot(data["com"][:, 0], data["com"][:, 1], color="0.3", lw=1, label="CoM")
    ax_xy.set_aspect("equal")
    ax_xy.set_xlabel("x [m]")
    ax_xy.set_ylabel("y [m]")
    ax_xy.legend(loc="upper left", fontsize=8)
    ax_xy.set_title("ZMP in the support polygons (grey), from above")

    worst = min((s.report.zmp_margin_m for s in result.steps), default=float("nan"))
    fig.suptitle(
        f"{result.robot} on {result.terrain}: {len(result.steps)} footsteps, "
        f"{result.duration_s:.1f} s, valid {result.valid_fraction:.0%}, "
        f"least ZMP margin {worst * 1000:.1f} mm",
        fontsize=11,
    )
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
