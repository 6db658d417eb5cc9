"""Pictures of terrains: shaded relief with a colour bar and a scale bar."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from roughwalk.terrain import Terrain

__all__ = ["plot_terrain", "save_terrain_picture", "nice_scale_length"]


def nice_scale_length(span: float) -> float:
    """A round scale-bar length [m] of roughly a fifth of ``span`` [m]."""
    target = max(span / 5.0, 1e-6)
    exp = np.floor(np.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * 10**exp <= target:
            return float(m * 10**exp)
    return float(10**exp)


def plot_terrain(
    terrain: Terrain,
    ax: Axes | None = None,
    *,
    title: str | None = None,
    cmap: str = "terrain",
    show_unknown: bool = True,
    colorbar: bool = True,
    scale_bar: bool = True,
) -> Axes:
    """Draw ``terrain`` as shaded relief (height colours × hill shading) on ``ax``.

    Unknown cells are hatched grey. x runs to the right, y up, as seen from above.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LightSource, Normalize

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 8 * _aspect(terrain)))
    h = terrain.heights.T  # rows along y for imshow
    lo, hi = terrain.height_range
    if hi - lo < 1e-9:
        hi = lo + 1e-3
    norm = Normalize(vmin=lo, vmax=hi)
    ls = LightSource(azdeg=315, altdeg=45)
    cm = plt.get_cmap(cmap)
    rgb = ls.shade(
        h, cmap=cm, norm=norm, blend_mode="soft", vert_exag=1.0, dx=terrain.dx, dy=terrain.dy
    )
    x_min, x_max, y_min, y_max = terrain.extent
    ext = (
        x_min - terrain.dx / 2,
        x_max + terrain.dx / 2,
        y_min - terrain.dy / 2,
        y_max + terrain.dy / 2,
    )
    ax.imshow(rgb, origin="lower", extent=ext, interpolation="nearest")
    if show_unknown and not terrain.known.all():
        mask = np.ma.masked_where(terrain.known.T, np.ones_like(h))
        ax.imshow(mask, origin="lower", extent=ext, cmap="Greys", vmin=0, vmax=2, alpha=0.8)
    if colorbar:
        sm = plt.cm.ScalarMappable(norm=norm, cmap=cm)
        cb = ax.figure.colorbar(sm, ax=ax, fraction=0.046, pad=0.02, shrink=0.9)
        cb.set_label("height [m]")
    if scale_bar:
        _scale_bar(ax, terrain)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.set_title(title if title is not None else terrain.name)
    return ax


def _aspect(terrain: Terrain) -> float:
    x_min, x_max, y_min, y_max = terrain.extent
    return float(np.clip((y_max - y_min) / max(x_max - x_min, 1e-9), 0.25, 1.5))


def _scale_bar(ax: Axes, terrain: Terrain) -> None:
    x_min, x_max, y_min, y_max = terrain.extent
    length = nice_scale_length(x_max - x_min)
    x0 = x_min + 0.04 * (x_max - x_min)
    y0 = y_min + 0.06 * (y_max - y_min)
    ax.plot([x0, x0 + length], [y0, y0], color="white", lw=5, solid_capstyle="butt")
    ax.plot([x0, x0 + length], [y0, y0], color="black", lw=2, solid_capstyle="butt")
    label = f"{length * 100:g} cm" if length < 1 else f"{length:g} m"
    ax.text(
        x0 + length / 2,
        y0 + 0.03 * (y_max - y_min),
        label,
        ha="center",
        va="bottom",
        fontsize=9,
        color="black",
        bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 1},
    )


def save_terrain_picture(terrain: Terrain, path: str | Path, **kwargs: Any) -> Figure:
    """Draw ``terrain`` and save it as a PNG at ``path``; returns the figure (closed)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, max(3.0, 9 * _aspect(terrain)) + 0.6))
    plot_terrain(terrain, ax, **kwargs)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return fig
