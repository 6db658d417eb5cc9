"""Pictures of signed distance fields: a vertical slice with the zero level set."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from roughwalk.terrain import Terrain
    from roughwalk.terrain.sdf import SignedDistanceField

__all__ = ["save_sdf_slice_picture"]


def save_sdf_slice_picture(
    terrain: Terrain,
    sdf: SignedDistanceField,
    path: str | Path,
    *,
    y: float | None = None,
    z_margin: float = 0.1,
    samples: int = 600,
) -> None:
    """Save a PNG of the SDF on the vertical x–z plane at ``y`` [m] (default: the middle).

    Colours are the signed distance [m] (blue inside, red outside), the black
    line is the SDF's zero level set and the dashed white line the terrain
    profile, so any disagreement between the two is visible at a glance.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    x_min, x_max, y_min, y_max = terrain.extent
    yy = 0.5 * (y_min + y_max) if y is None else float(y)
    lo, hi = terrain.height_range
    xs = np.linspace(x_min, x_max, samples)
    nz = max(60, int(samples * (hi - lo + 2 * z_margin) / max(x_max - x_min, 1e-9)))
    zs = np.linspace(lo - z_margin, hi + z_margin, nz)
    gx, gz = np.meshgrid(xs, zs)
    pts = np.column_stack([gx.ravel(), np.full(gx.size, yy), gz.ravel()])
    d, _ = sdf.query(pts)
    d = d.reshape(gx.shape)
    lim = float(np.max(np.abs(d)))
    aspect = (zs[-1] - zs[0]) / max(xs[-1] - xs[0], 1e-9)
    fig, ax = plt.subplots(figsize=(10, max(2.5, 10 * aspect) + 1.0))
    im = ax.imshow(
        d,
        origin="lower",
        extent=(xs[0], xs[-1], zs[0], zs[-1]),
        cmap="RdBu_r",
        vmin=-lim,
        vmax=lim,
        aspect="equal",
    )
    ax.contour(gx, gz, d, levels=[0.0], colors="black", linewidths=1.2)
    prof = terrain.height(np.column_stack([xs, np.full_like(xs, yy)]))
    ax.plot(xs, prof, "w--", lw=0.8, label="terrain height")
    fig.colorbar(im, ax=ax, fraction=0.03, pad=0.02, label="signed distance [m]")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(
        f"{terrain.name}: SDF slice at y = {yy:.3f} m ({sdf.resolution * 1000:g} mm voxels)"
    )
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
