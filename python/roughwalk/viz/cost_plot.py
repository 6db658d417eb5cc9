"""Pictures of learned terrain costs: the cost map beside the terrain, like Zucker 2011, Fig. 5."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from roughwalk.terrain import Terrain

__all__ = ["plot_cost_map", "save_cost_picture"]


def plot_cost_map(
    terrain: Terrain,
    cost: NDArray[np.float64],
    ax: Axes | None = None,
    *,
    title: str | None = None,
    colorbar: bool = True,
) -> Axes:
    """Draw a cost grid (nx, ny) aligned with ``terrain``: blue low, red high, log scale.

    Infinite costs (off the grid, unknown ground) are grey. The colour range
    spans the 2nd to 98th percentile of the finite costs, and always includes
    1 (flat ground), so that one far outlier does not wash out the map.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from roughwalk.errors import InvalidArgumentError

    c = np.asarray(cost, dtype=np.float64)
    if c.shape != terrain.shape:
        raise InvalidArgumentError(
            f"cost grid {c.shape} does not match the terrain's grid {terrain.shape}"
        )
    if ax is None:
        _, ax = plt.subplots(figsize=(9, 4))
    finite = c[np.isfinite(c)]
    lo, hi = np.percentile(finite, [2, 98]) if finite.size else (0.5, 2.0)
    lo, hi = min(float(lo), 0.9), max(float(hi), 1.1)
    masked = np.ma.masked_invalid(np.where(np.isfinite(c), c, np.nan)).T
    cmap = plt.get_cmap("jet").with_extremes(bad="#9a9a9a")
    x_min, x_max, y_min, y_max = terrain.extent
    ext = (
        x_min - terrain.dx / 2,
        x_max + terrain.dx / 2,
        y_min - terrain.dy / 2,
        y_max + terrain.dy / 2,
    )
    image = ax.imshow(
        masked,
        origin="lower",
        extent=ext,
        cmap=cmap,
        norm=LogNorm(vmin=lo, vmax=hi, clip=True),
        interpolation="nearest",
    )
    if colorbar:
        cb = ax.figure.colorbar(image, ax=ax, fraction=0.046, pad=0.02, shrink=0.9)
        cb.set_label("terrain cost (1 = flat ground)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.set_title(title if title is not None else f"terrain cost: {terrain.name}")
    return ax


def save_cost_picture(
    terrain: Terrain,
    cost: NDArray[np.float64],
    path: str | Path,
    *,
    subtitle: str = "",
    **kwargs: Any,
) -> Figure:
    """Save the terrain (shaded relief) above its cost map as a PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from roughwalk.viz.terrain_plot import plot_terrain

    x_min, x_max, y_min, y_max = terrain.extent
    aspect = float(np.clip((y_max - y_min) / max(x_max - x_min, 1e-9), 0.2, 1.5))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 2 * max(2.2, 10 * aspect) + 1.2))
    plot_terrain(terrain, top, scale_bar=True)
    plot_cost_map(terrain, cost, bottom, **kwargs)
    if subtitle:
        fig.suptitle(subtitle, fontsize=10)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return fig
