"""The demo: the longest end-to-end slice of roughwalk that exists, with pictures.

Today: a LittleDog-scale course → its signed distance field and terrain
features → pictures and a JSON summary. Each later part (footstep plan,
trajectory, MuJoCo walk) extends :func:`run_demo`.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from roughwalk.terrain import load_terrain

__all__ = ["run_demo", "DEFAULT_DEMO_TERRAIN"]

DEFAULT_DEMO_TERRAIN = "large_rocks:seed=7"


def run_demo(
    out_dir: str | Path = "demo-output",
    terrain_spec: str = DEFAULT_DEMO_TERRAIN,
    sdf_resolution: float = 0.005,
    progress: Any = print,
) -> dict[str, Any]:
    """Run the demo, writing pictures and ``summary.json`` into ``out_dir``; return the summary."""
    from roughwalk.cli.common import result_envelope, write_json
    from roughwalk.viz.sdf_plot import save_sdf_slice_picture
    from roughwalk.viz.terrain_plot import save_terrain_picture

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    steps: dict[str, Any] = {}

    t0 = time.perf_counter()
    terrain = load_terrain(terrain_spec)
    steps["terrain"] = {"seconds": time.perf_counter() - t0, **terrain.info()}
    progress(f"[1/3] terrain  {terrain}")
    save_terrain_picture(terrain, out / "terrain.png")

    sdf = terrain.sdf(resolution=sdf_resolution)
    steps["sdf"] = sdf.info()
    progress(
        f"[2/3] SDF      {tuple(sdf.shape)} voxels at {sdf_resolution * 1000:g} mm "
        f"in {steps['sdf']['build_time_s']:.3f} s"
    )
    save_sdf_slice_picture(terrain, sdf, out / "sdf_slice.png")

    t0 = time.perf_counter()
    feats = terrain.features()
    steps["features"] = {
        "seconds": time.perf_counter() - t0,
        "count": len(feats.names),
        "radii_m": list(feats.radii),
    }
    progress(f"[3/3] features {len(feats.names)} per cell in {steps['features']['seconds']:.2f} s")
    from roughwalk.viz.features_plot import save_features_picture

    save_features_picture(terrain, feats, out / "features.png")

    summary = result_envelope(
        "demo",
        terrain=terrain.spec,
        pictures=sorted(p.name for p in out.glob("*.png")),
        steps=steps,
    )
    write_json(out / "summary.json", summary)
    progress(f"wrote {out}/ (terrain.png, sdf_slice.png, features.png, summary.json)")
    return summary
