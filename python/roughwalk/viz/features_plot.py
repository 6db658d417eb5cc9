"""Pictures of terrain features (Zucker 2011, §4.2): slope, curvature and roughness maps."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from roughwalk.terrain import Terrain
    from roughwalk.terrain.features import TerrainFeatures

__all__ = ["save_features_picture"]


def save_features_picture(
    terrain: Terrain, features: TerrainFeatures, path: str | Path, radius: float | None = None
) -> None:
    """Save a 2×2 PNG: terrain relief, slope |k|, curvature λ_min/λ_max and fit residual.

    ``radius`` [m] picks the disc (default: the middle one of ``features.radii``).
    Invalid cells (border, unknown) are grey.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from roughwalk.viz.terrain_plot import plot_terrain

    radii = list(features.radii)
    r = radii[len(radii) // 2] if radius is None else min(radii, key=lambda v: abs(v - radius))
    tag = f"r{r:g}"

    def layer(name: str) -> np.ndarray:
        v = np.asarray(features.values[:, :, features.index(f"{tag}/{name}")], dtype=float)
        return np.ma.masked_where(~features.valid_by_radius[radii.index(r)], v).T

    x_min, x_max, y_min, y_max = terrain.extent
    ext = (x_min, x_max, y_min, y_max)
    aspect = (y_max - y_min) / max(x_max - x_min, 1e-9)
    fig, axes = plt.subplots(2, 2, figsize=(13, max(4.0, 13 * aspect) + 1.2))
    plot_terrain(terrain, axes[0, 0], title=f"{terrain.name}: height", scale_bar=True)
    panels = [
        (axes[0, 1], layer("grad_norm"), "slope |k| [-]", "viridis", None),
        (
            axes[1, 0],
            layer("lambda_max") + layer("lambda_min"),
            "curvature λ_min+λ_max [1/m] (− dome, + dip)",
            "RdBu",
            "sym",
        ),
        (axes[1, 1], layer("residual") * 1000, "fit residual [mm]", "magma", None),
    ]
    cmap_bad = "#bbbbbb"
    for ax, data, title, cmap, mode in panels:
        cm = plt.get_cmap(cmap).copy()
        cm.set_bad(cmap_bad)
        finite = np.ma.compressed(data)
        hi = float(np.percentile(np.abs(finite), 99)) if finite.size else 1.0
        hi = hi if hi > 0 else 1.0
        vmin, vmax = (-hi, hi) if mode == "sym" else (0.0, hi)
        im = ax.imshow(data, origin="lower", extent=ext, cmap=cm, vmin=vmin, vmax=vmax)
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02)
        ax.set_title(f"{title}, disc {r * 100:g} cm")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal")
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
