"""Pictures of optimised motions: Melon et al.'s Figure 3 and a 3-D view of the motion.

The left column is like Melon 2020, Fig. 3: the base's lateral position, one
foot's height and its normal force over time, the splines drawn in black and
their nodes as red dots, the foot's stance phases shaded. The right panel
shows the motion in 3-D: the terrain, the base path and the feet's paths.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from roughwalk.terrain import Terrain
    from roughwalk.trajopt import TrajoptResult

__all__ = ["save_trajopt_picture"]

_LEG_NAMES = ("LF", "RF", "LH", "RH")
_LEG_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def _shade_stance(ax: Any, result: TrajoptResult, foot: int) -> None:
    assert result.schedule is not None
    bounds = result.schedule.phase_times(foot)
    for k in range(len(bounds) - 1):
        if result.schedule.is_stance(foot, k):
            ax.axvspan(bounds[k], bounds[k + 1], color="0.9", lw=0)


def save_trajopt_picture(
    result: TrajoptResult,
    path: str | Path,
    terrain: Terrain | None = None,
    foot: int = 0,
) -> Path:
    """Draw ``result`` (a solved :class:`TrajoptResult`) to the PNG ``path``; return the path.

    ``foot`` (0..3 = LF, RF, LH, RH) is the foot of the time plots; the
    ``terrain``, when given, is drawn under the 3-D motion.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    splines = result._need_splines()
    samples = result.sample(200.0)
    t = samples["t"]
    fig = plt.figure(figsize=(13, 7.5))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.0, 1.25))
    name = _LEG_NAMES[foot]

    ax = fig.add_subplot(grid[0, 0])
    _shade_stance(ax, result, foot)
    ax.plot(t, samples["com_position"][:, 1], "k", lw=1.2)
    node_t = splines.base_linear.node_times
    ax.plot(node_t, splines.base_linear.positions[:, 1], "r.", ms=4)
    ax.set_ylabel("base y [m]")
    ax.set_title(
        f"{result.status.value}: {result.iterations} iterations, {result.solve_time_s:.2f} s, "
        f"objective {result.objective:.3g}",
        fontsize=10,
    )

    ax = fig.add_subplot(grid[1, 0])
    _shade_stance(ax, result, foot)
    ax.plot(t, samples["feet_position"][:, foot, 2], "k", lw=1.2)
    ax.plot(splines.feet[foot].node_times, splines.feet[foot].positions[:, 2], "r.", ms=5)
    ax.set_ylabel(f"{name} foot z [m]")

    ax = fig.add_subplot(grid[2, 0])
    _shade_stance(ax, result, foot)
    ax.plot(t, samples["forces"][:, foot, 2], "k", lw=1.2)
    ax.plot(splines.forces[foot].node_times, splines.forces[foot].positions[:, 2], "r.", ms=5)
    ax.set_ylabel(f"{name} z-force [N]")
    ax.set_xlabel("time [s]")

    ax3 = fig.add_subplot(grid[:, 1], projection="3d")
    com = samples["com_position"]
    feet = samples["feet_position"]
    lo = np.minimum(com.min(axis=0), feet.reshape(-1, 3).min(axis=0)) - 0.3
    hi = np.maximum(com.max(axis=0), feet.reshape(-1, 3).max(axis=0)) + 0.3
    if terrain is not None:
        xs = np.linspace(lo[0], hi[0], 80)
        ys = np.linspace(lo[1], hi[1], 40)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        gz = terrain.height(np.column_stack([gx.ravel(), gy.ravel()])).reshape(gx.shape)
        ax3.plot_surface(gx, gy, gz, color="0.75", alpha=0.5, linewidth=0, shade=True)
    ax3.plot(com[:, 0], com[:, 1], com[:, 2], "k", lw=2, label="base (CoM)")
    for i in range(feet.shape[1]):
        ax3.plot(
            feet[:, i, 0],
            feet[:, i, 1],
            feet[:, i, 2],
            color=_LEG_COLOURS[i],
            lw=1.0,
            label=_LEG_NAMES[i],
        )
        holds = splines.feet[i].positions
        ax3.scatter(holds[:, 0], holds[:, 1], holds[:, 2], color=_LEG_COLOURS[i], s=6)
    # Snapshots of the body every half second: a segment from hind to front hips.
    assert result.body is not None
    stance = result.body.stance
    for k in np.linspace(0, len(t) - 1, max(2, int(result.duration / 0.5) + 1)).astype(int):
        rot = _rotation(samples["base_euler"][k])
        corners = com[k] + stance[[0, 1, 3, 2, 0]] @ rot.T * np.array([1.0, 1.0, 0.0])
        ax3.plot(corners[:, 0], corners[:, 1], corners[:, 2], color="0.3", lw=0.8)
    ax3.set_xlim(lo[0], hi[0])
    ax3.set_ylim(lo[1], hi[1])
    ax3.set_zlim(lo[2], hi[2])
    # Equal scale on every axis, so that steps and heights look as they are.
    ax3.set_box_aspect(tuple(hi - lo))
    ax3.set_xlabel("x [m]")
    ax3.set_ylabel("y [m]")
    ax3.set_zlabel("z [m]")
    ax3.legend(loc="upper left", fontsize=8)
    ax3.set_title(f"{result.terrain or ''}: {result.duration:.2f} s", fontsize=10)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def _rotation(euler: np.ndarray) -> np.ndarray:
    from roughwalk.trajopt.variables import euler_to_rotation

    return np.asarray(euler_to_rotation(euler))
