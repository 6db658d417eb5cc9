"""Pictures of a simulated run: the path over the terrain, and tracking over time."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from roughwalk.viz.terrain_plot import plot_terrain

if TYPE_CHECKING:
    from roughwalk.sim.run_log import RunLog
    from roughwalk.terrain import Terrain

__all__ = ["save_run_path_picture", "save_run_tracking_picture"]

_LEG_COLOURS = ("tab:red", "tab:orange", "tab:blue", "tab:cyan")
_EVENT_STYLE = {
    "reflex": ("tab:red", "reflex"),
    "replan": ("tab:purple", "re-plan"),
    "push": ("black", "push"),
    "goal": ("tab:green", "goal"),
}


def _quat_rpy(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw [rad] of (n, 4) quaternions (w, x, y, z)."""
    w, x, y, z = q.T
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.column_stack([roll, pitch, yaw])


def save_run_path_picture(log: RunLog, terrain: Terrain, path: str | Path) -> Path:
    """Top view: terrain, planned and measured trunk paths, footholds, start, goal, events."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    x_min, x_max, y_min, y_max = terrain.extent
    aspect = float(np.clip((y_max - y_min) / max(x_max - x_min, 1e-9), 0.25, 1.5))
    fig, ax = plt.subplots(figsize=(10, max(3.2, 10 * aspect) + 0.8))
    plot_terrain(terrain, ax, title=f"{log.meta.get('robot', '')} on {terrain.name}")
    base = np.asarray(log["base_pos"], dtype=float)
    desired = np.asarray(log["base_pos_desired"], dtype=float)
    ax.plot(desired[:, 0], desired[:, 1], color="white", lw=2.5, ls="--", label="planned trunk")
    ax.plot(base[:, 0], base[:, 1], color="black", lw=1.5, label="trunk")
    feet = np.asarray(log["feet"], dtype=float)
    forces = np.asarray(log["foot_forces"], dtype=float)[..., 2]
    for leg in range(4):
        down = forces[:, leg] > 1.0
        ax.scatter(
            feet[down, leg, 0][::25],
            feet[down, leg, 1][::25],
            s=6,
            color=_LEG_COLOURS[leg],
            label=("LF", "RF", "LH", "RH")[leg],
        )
    goal = log.meta.get("goal")
    if goal is not None:
        radius = log.meta.get("outcome", {}).get("extra", {}).get("goal_radius_m", None)
        ax.plot(goal[0], goal[1], marker="*", ms=16, color="gold", mec="black", label="goal")
        if radius:
            ax.add_patch(plt.Circle((goal[0], goal[1]), radius, fill=False, color="gold"))
    times = np.asarray(log["time"], dtype=float)
    for e in log.events:
        style = _EVENT_STYLE.get(e["kind"])
        if style is None or e["kind"] == "goal":
            continue
        k = int(np.clip(np.searchsorted(times, e["time"]), 0, len(times) - 1))
        ax.plot(base[k, 0], base[k, 1], marker="x", ms=10, mew=2, color=style[0])
    ax.legend(loc="upper right", fontsize=8, ncol=4, framealpha=0.8)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def save_run_tracking_picture(log: RunLog, path: str | Path) -> Path:
    """Over time: trunk position error, roll and pitch, foot forces (measured, planned), events."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    t = np.asarray(log["time"], dtype=float)
    base = np.asarray(log["base_pos"], dtype=float)
    desired = np.asarray(log["base_pos_desired"], dtype=float)
    error = np.linalg.norm(base - desired, axis=1)
    rpy = _quat_rpy(np.asarray(log["base_quat"], dtype=float))
    forces = np.asarray(log["foot_forces"], dtype=float)[..., 2]
    planned = np.asarray(log["forces_desired"], dtype=float)[..., 2]
    fig, axes = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    ax = axes[0]
    ax.plot(t, 1000 * error, color="black", lw=1)
    ax.set_ylabel("trunk error [mm]")
    ax.set_title("tracking")
    ax = axes[1]
    ax.plot(t, np.degrees(rpy[:, 0]), label="roll", lw=1)
    ax.plot(t, np.degrees(rpy[:, 1]), label="pitch", lw=1)
    ax.set_ylabel("[deg]")
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[2]
    for leg in range(4):
        c = _LEG_COLOURS[leg]
        ax.plot(t, forces[:, leg], color=c, lw=0.8, label=("LF", "RF", "LH", "RH")[leg])
        ax.plot(t, planned[:, leg], color=c, lw=0.8, ls=":")
    ax.set_ylabel("foot normal force [N]\n(dotted: planned)")
    ax.set_xlabel("time [s]")
    ax.legend(loc="upper right", fontsize=8, ncol=4)
    for e in log.events:
        style = _EVENT_STYLE.get(e["kind"])
        if style is None:
            continue
        for a in axes:
            a.axvline(e["time"], color=style[0], lw=1, alpha=0.7)
        axes[0].text(
            e["time"],
            axes[0].get_ylim()[1],
            style[1],
            color=style[0],
            fontsize=7,
            rotation=90,
            va="top",
            ha="right",
        )
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
