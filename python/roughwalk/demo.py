"""The demo: roughwalk end to end on a generated rocky course, no input files needed.

A LittleDog-scale course → its signed distance field and terrain features
(pictures) → footstep plan, footstep trajectories optimised while the
previous step executes, and the walk in MuJoCo with integrators and reflexes
(``roughwalk.run``) → video, plots and an ``index.html`` that shows them
with the numbers, all in one folder.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from roughwalk.terrain import load_terrain

__all__ = ["run_demo", "DEFAULT_DEMO_TERRAIN"]

# Rocks up to 5 cm: the walk on this course succeeds today; on the full 10.8 cm
# LittleDog rocks it still falls too often (`roughwalk bench littledog` says how often).
DEFAULT_DEMO_TERRAIN = "large_rocks:seed=7,max_height=0.05"
DEMO_START = (0.25, 0.0, 0.0)
DEMO_GOAL = (0.85, 0.0)


def run_demo(
    out_dir: str | Path = "demo-output",
    terrain_spec: str = DEFAULT_DEMO_TERRAIN,
    sdf_resolution: float = 0.005,
    progress: Any = print,
    walk: bool = True,
    start: tuple[float, float, float] = DEMO_START,
    goal: tuple[float, float] = DEMO_GOAL,
    video: bool = True,
) -> dict[str, Any]:
    """Run the demo, writing pictures and ``summary.json`` into ``out_dir``; return the summary.

    With ``walk`` the LittleDog also walks from ``start`` (x, y, yaw) [m, m,
    rad] to ``goal`` (x, y) [m] in MuJoCo, and ``out_dir/index.html`` shows
    the run (with its video unless ``video`` is False).
    """
    from roughwalk.cli.common import result_envelope, write_json
    from roughwalk.viz.sdf_plot import save_sdf_slice_picture
    from roughwalk.viz.terrain_plot import save_terrain_picture

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    steps: dict[str, Any] = {}

    t0 = time.perf_counter()
    terrain = load_terrain(terrain_spec)
    steps["terrain"] = {"seconds": time.perf_counter() - t0, **terrain.info()}
    total = 4 if walk else 3
    progress(f"[1/{total}] terrain  {terrain}")
    save_terrain_picture(terrain, out / "terrain.png")

    sdf = terrain.sdf(resolution=sdf_resolution)
    steps["sdf"] = sdf.info()
    progress(
        f"[2/{total}] SDF      {tuple(sdf.shape)} voxels at {sdf_resolution * 1000:g} mm "
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
    progress(
        f"[3/{total}] features {len(feats.names)} per cell in {steps['features']['seconds']:.2f} s"
    )
    from roughwalk.viz.features_plot import save_features_picture

    save_features_picture(terrain, feats, out / "features.png")

    index = None
    if walk:
        index = _walk(terrain, out, start, goal, video, steps, progress, total)

    summary = result_envelope(
        "demo",
        terrain=terrain.spec,
        pictures=sorted(p.name for p in out.glob("*.png")),
        steps=steps,
        index=str(index) if index is not None else None,
    )
    write_json(out / "summary.json", summary)
    progress(f"wrote {out}/ (terrain.png, sdf_slice.png, features.png, summary.json)")
    if index is not None:
        run = steps["walk"]
        print(
            f"LittleDog {'reached the goal' if run['success'] else 'did not reach the goal'}: "
            f"{run['distance_m']:.2f} m in {run['time_s']:.1f} s ({run['speed_cm_s']:.2f} cm/s), "
            f"{run['reflexes']} reflexes, {run['replans']} re-plans; {run['reason']}"
        )
        print(f"open {index}")
    return summary


def _walk(
    terrain: Any,
    out: Path,
    start: tuple[float, float, float],
    goal: tuple[float, float],
    video: bool,
    steps: dict[str, Any],
    progress: Any,
    total: int,
) -> Path:
    """Plan, optimise and walk in MuJoCo; write the run's files; return index.html's path."""
    from roughwalk.cli.run_cmd import ProgressBar
    from roughwalk.sim import run
    from roughwalk.viz.run_outputs import save_run_outputs

    progress(f"[4/{total}] walk     LittleDog from {start[:2]} to {goal} (plan, optimise, walk)")
    bar = ProgressBar("  walking")
    try:
        result = run("littledog", terrain, start, goal, progress=bar)
    finally:
        bar.close()
    files = save_run_outputs(result, out, video="video.mp4" if video else None, progress=progress)
    steps["walk"] = result.to_dict()
    return Path(files["index"]).resolve()
