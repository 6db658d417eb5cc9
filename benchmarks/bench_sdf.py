"""Benchmark the signed distance field: build time per EDT backend, accuracy, query throughput.

Builds the SDF of a course of three LittleDog boards (≈ 1.83 m × 0.61 m,
default z extent) at 5 mm with each EDT backend, measures each one's error
against the exact height-field distance, and measures point, sphere and
capsule query throughput on one core (a worker process with
RAYON_NUM_THREADS=1) and on all cores. Zucker et al. 2011 report 2–15 s to
build a 2 m × 0.6 m field; the target here is ≤ 0.5 s and ≥ 10 million point
queries per second on one core.

    python benchmarks/bench_sdf.py [--repeat 5] [--out benchmarks/results/sdf.json]

Not a test: it prints a table and writes JSON with the machine's description.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk.cli.common import machine_description, write_json
from roughwalk.terrain import SignedDistanceField, Terrain, load_terrain
from roughwalk.terrain.sdf import available_edt_backends

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("ROUGHWALK_SHARED") or HERE.parent.parent / "shared")
DEFAULT_BOARDS = ("terrainA", "terrainAC", "terrainAE")


def course(boards: list[str]) -> Terrain:
    """The boards laid end to end along x."""
    folder = SHARED / "terrains" / "littledog"
    missing = [b for b in boards if not (folder / f"{b}.mat").is_file()]
    if missing:
        sys.exit(f"bench_sdf: LittleDog boards not found in {folder}: {', '.join(missing)}")
    return load_terrain("+".join(str(folder / f"{b}.mat") for b in boards))


def random_points(sdf: SignedDistanceField, n: int, seed: int = 0) -> np.ndarray:
    """Uniform points in the lattice's box [m]."""
    lo, hi = np.array(sdf.origin), np.array(sdf.upper)
    return lo + (hi - lo) * np.random.default_rng(seed).random((n, 3))


def accuracy(sdf: SignedDistanceField, n: int) -> dict[str, float]:
    """Error [mm] of the field against the exact height-field distance at random points."""
    p = random_points(sdf, n, seed=1)
    near = random_points(sdf, n, seed=2)
    near[:, 2] = sdf.terrain.height(near[:, :2]) + np.random.default_rng(3).uniform(-0.02, 0.02, n)
    p = np.vstack([p, near])
    exact, _ = sdf.surface_query(p)
    d, _ = sdf.query(p)
    err = np.abs(d - exact) * 1000
    return {
        "max_mm": float(err.max()),
        "p99_mm": float(np.percentile(err, 99)),
        "mean_mm": float(err.mean()),
        "half_voxel_diagonal_mm": float(0.5 * np.sqrt(3) * sdf.resolution * 1000),
    }


def throughput(sdf: SignedDistanceField, n: int, repeat: int) -> dict[str, float]:
    """Queries per second (best of ``repeat``) for points, spheres and capsules."""
    p = random_points(sdf, n)
    r = np.full(n, 0.01)
    # Capsules up to ~5 cm long, kept inside the lattice like a robot's links.
    b = np.clip(p + np.random.default_rng(4).uniform(-0.03, 0.03, p.shape), sdf.origin, sdf.upper)
    out: dict[str, float] = {}
    for name, call, count in (
        ("points_per_s", lambda: sdf.query(p), n),
        ("spheres_per_s", lambda: sdf.query_spheres(p, r), n),
        (
            "capsules_per_s",
            lambda: sdf.query_capsules(p[: n // 10], b[: n // 10], r[: n // 10]),
            n // 10,
        ),
    ):
        best = min(_timed(call) for _ in range(repeat))
        out[name] = count / best
    lengths = np.linalg.norm(b - p, axis=1)[: n // 10]
    out["capsule_mean_samples"] = float(np.mean(np.ceil(lengths / sdf.resolution) + 1))
    return out


def raw_transforms(terrain: Terrain, resolution: float, repeat: int) -> dict[str, float]:
    """Seconds (best of ``repeat``) each backend's transform alone takes on the course's band."""
    from roughwalk import _core
    from roughwalk.terrain.sdf import SdfConfig

    cfg = SdfConfig(resolution=resolution)
    origin, shape = SignedDistanceField.lattice_for(terrain, cfg)
    band = _core.SdfBand.from_heightfield(terrain.core, origin, resolution, shape, cfg.band_cells)
    seeds = band.seed_mask()
    calls: dict[str, Any] = {"rust": lambda: _core.feature_transform(seeds)}
    backends = available_edt_backends()
    if "scipy" in backends:
        from scipy import ndimage

        calls["scipy"] = lambda: ndimage.distance_transform_edt(
            ~seeds, return_distances=False, return_indices=True
        )
    if "edt" in backends:
        import edt

        calls["edt"] = lambda: edt.edt(~seeds, parallel=os.cpu_count() or 1)
    return {name: min(_timed(call) for _ in range(repeat)) for name, call in calls.items()}


def _timed(call: Any) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def query_worker(path: str, n: int, repeat: int) -> None:
    """Run in a child process (RAYON_NUM_THREADS set by the parent): print throughput JSON."""
    sdf = SignedDistanceField.load(path)
    print(json.dumps(throughput(sdf, n, repeat)))


def single_core_throughput(sdf: SignedDistanceField, n: int, repeat: int) -> dict[str, float]:
    """Throughput measured in a worker process limited to one rayon thread."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "course_sdf.npz"
        sdf.save(path)
        env = dict(os.environ, RAYON_NUM_THREADS="1")
        cmd = [
            sys.executable,
            __file__,
            "--query-worker",
            str(path),
            "--points",
            str(n),
            "--repeat",
            str(repeat),
        ]
        done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark, print a table and write JSON."""
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--boards", nargs="+", default=list(DEFAULT_BOARDS), help="LittleDog boards, first to last"
    )
    ap.add_argument("--resolution", type=float, default=0.005, help="voxel size [m]")
    ap.add_argument(
        "--repeat", type=int, default=5, help="builds per backend (median and best reported)"
    )
    ap.add_argument("--points", type=int, default=1_000_000, help="points per throughput run")
    ap.add_argument("--accuracy-points", type=int, default=20_000, help="points per accuracy check")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "sdf.json", help="JSON output")
    ap.add_argument("--query-worker", metavar="NPZ", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.query_worker:
        query_worker(args.query_worker, args.points, args.repeat)
        return

    terrain = course(args.boards)
    x_min, x_max, y_min, y_max = terrain.extent
    size = f"{x_max - x_min:.3f} m × {y_max - y_min:.3f} m"
    print(f"course {terrain.name}: {size}, grid {terrain.shape}")
    builds: dict[str, Any] = {}
    fields: dict[str, SignedDistanceField] = {}
    for backend in available_edt_backends():
        times = []
        for _ in range(args.repeat):
            sdf = terrain.sdf(args.resolution, edt_backend=backend)
            times.append(sdf.build_time_s)
        fields[backend] = sdf
        builds[backend] = {
            "build_s_median": statistics.median(times),
            "build_s_best": min(times),
            "build_s_all": times,
            "accuracy": accuracy(sdf, args.accuracy_points),
        }
    raw = raw_transforms(terrain, args.resolution, args.repeat)
    for backend, seconds in raw.items():
        builds[backend]["transform_alone_s"] = seconds
    rust = fields["rust"]
    info = rust.info()
    single = single_core_throughput(rust, args.points, args.repeat)
    multi = throughput(rust, args.points, args.repeat)

    voxels = int(np.prod(info["shape"]))
    print(
        f"\nlattice {info['shape']} at {args.resolution * 1000:g} mm = {voxels:,} voxels, "
        f"{info['memory_bytes'] / 1e6:.1f} MB"
    )
    head = (
        "build median [s]",
        "best [s]",
        "EDT alone [s]",
        "max err [mm]",
        "p99 [mm]",
        "mean [mm]",
    )
    print(
        f"\n{'backend':8} {head[0]:>17} {head[1]:>9} {head[2]:>14} {head[3]:>13} "
        f"{head[4]:>9} {head[5]:>10}"
    )
    for backend, b in builds.items():
        a = b["accuracy"]
        print(
            f"{backend:8} {b['build_s_median']:17.3f} {b['build_s_best']:9.3f} "
            f"{b.get('transform_alone_s', float('nan')):14.3f} {a['max_mm']:13.2f} "
            f"{a['p99_mm']:9.2f} {a['mean_mm']:10.3f}"
        )
    print(f"(half a voxel diagonal: {builds['rust']['accuracy']['half_voxel_diagonal_mm']:.2f} mm)")
    print(f"\n{'queries':10} {'1 core [M/s]':>13} {f'{os.cpu_count()} cores [M/s]':>14}")
    for key in ("points_per_s", "spheres_per_s", "capsules_per_s"):
        print(f"{key.removesuffix('_per_s'):10} {single[key] / 1e6:13.2f} {multi[key] / 1e6:14.2f}")
    print(f"(capsules: 3 cm long on average, {single['capsule_mean_samples']:.1f} samples each)")

    write_json(
        args.out,
        {
            "benchmark": "sdf",
            "machine": machine_description(),
            "terrain": {
                "spec": terrain.spec,
                "shape": list(terrain.shape),
                "extent": list(terrain.extent),
            },
            "sdf": info,
            "builds": builds,
            "queries_single_core": single,
            "queries_all_cores": multi,
            "targets": {"build_s": 0.5, "points_per_s_single_core": 1e7},
        },
    )
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
