"""Pictures of footstep plans: the plan over the terrain cost map with the search tree.

As Zucker 2011, Figure 6: the ARA* search tree's states hold four feet
each, so the tree is drawn projected to 2-D — one segment per parent →
child foot move — over the terrain cost (blue low, red high; unknown or
forbidden cells grey), with the plan's footsteps and the feet's centroid path.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from roughwalk.planning.footstep_plan import FootstepPlan

__all__ = ["plot_footstep_plan", "save_footstep_plan_picture"]

LEG_COLOURS = {"LF": "#1b9e77", "RF": "#d95f02", "LH": "#7570b3", "RH": "#e7298a"}
LEGS = ("LF", "RF", "LH", "RH")


def plot_footstep_plan(
    ax: Axes,
    plan: FootstepPlan,
    cost_map: np.ndarray,
    extent: tuple[float, float, float, float],
    *,
    tree: bool = True,
    goal_radius: float | None = None,
) -> None:
    """Draw ``plan`` over ``cost_map`` (nx, ny) covering ``extent`` (x0, x1, y0, y1) [m]."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Circle

    cost = np.ma.masked_invalid(np.where(np.isfinite(cost_map), cost_map, np.nan)).T
    cmap = plt.get_cmap("coolwarm").with_extremes(bad="#9a9a9a")
    finite = np.ma.compressed(cost)
    lo = float(np.percentile(finite, 1)) if finite.size else 0.5
    hi = float(np.percentile(finite, 99)) if finite.size else 2.0
    lo, hi = max(lo, 1e-3), max(hi, lo * 1.01)
    im = ax.imshow(cost, origin="lower", extent=extent, cmap=cmap, norm=LogNorm(vmin=lo, vmax=hi))
    ax.figure.colorbar(im, ax=ax, fraction=0.046, pad=0.02, label="terrain cost (log)")
    if tree and len(plan.tree):
        from matplotlib.collections import LineCollection

        segments = list(plan.tree[:, 1:].reshape(-1, 2, 2))
        ax.add_collection(
            LineCollection(segments, colors="k", linewidths=0.3, alpha=0.35, zorder=2)
        )
    if plan.footsteps:
        stances = plan.stances()
        centroid = stances[:, :, :2].mean(axis=1)
        ax.plot(centroid[:, 0], centroid[:, 1], "-", color="w", lw=1.5, zorder=3)
        for leg in LEGS:
            pts = np.array([[f.x, f.y] for f in plan.footsteps if f.leg == leg])
            ax.plot(
                pts[:, 0],
                pts[:, 1],
                "o-",
                ms=3.5,
                lw=0.8,
                color=LEG_COLOURS[leg],
                mec="k",
                mew=0.4,
                label=leg,
                zorder=4,
            )
        ax.legend(loc="upper right", fontsize=7, ncol=4)
    if np.all(np.isfinite(plan.goal)):
        ax.plot(*plan.goal, "*", color="gold", mec="k", ms=12, zorder=5)
        if goal_radius:
            ax.add_patch(Circle(plan.goal, goal_radius, fill=False, ec="gold", lw=1.2, zorder=5))
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    cost_text = "—" if plan.cost is None else f"{plan.cost:.1f}"
    ax.set_title(
        f"{plan.status}: {plan.steps} steps, cost {cost_text}, "
        f"{plan.states_expanded} states, {plan.heuristic} heuristic"
    )


def save_footstep_plan_picture(
    plan: FootstepPlan,
    cost_map: np.ndarray,
    extent: tuple[float, float, float, float],
    path: str | Path,
    *,
    tree: bool = True,
    goal_radius: float | None = None,
) -> None:
    """Save the picture of :func:`plot_footstep_plan` as a PNG."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    width = extent[1] - extent[0]
    height = extent[3] - extent[2]
    fig, ax = plt.subplots(figsize=(11, max(3.5, 11 * height / max(width, 1e-9)) + 1.0))
    plot_footstep_plan(ax, plan, cost_map, extent, tree=tree, goal_radius=goal_radius)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
