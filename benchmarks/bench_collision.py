"""Whole-body SDF distance queries per second (issue 3's benchmark), from Python.

Each query places the robot (FK of every link), samples every non-foot capsule
and asks the terrain's SDF in one batched Rust call. Prints a table and writes
JSON with the machine's description. Not a test.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import roughwalk
from roughwalk.cli.common import machine_description
from roughwalk.robots.collision_model import CollisionModel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=2.0, help="time per robot [s]")
    parser.add_argument("--out", default="benchmarks/results/collision.json")
    args = parser.parse_args()
    terrain = roughwalk.load_terrain("large_rocks:seed=1")
    rows = []
    for name in ("littledog", "anymal_c"):
        robot = roughwalk.load_robot(name)
        # The lattice must reach above the whole robot; queries outside it fall back to
        # the exact (much slower) height-field distance.
        margin = robot.nominal_stance.base_height + 0.3
        sdf = terrain.sdf(resolution=0.005, z_margin=margin)
        cm = CollisionModel.from_robot(robot)
        rng = np.random.default_rng(0)
        base_h = robot.nominal_stance.base_height
        n = 0
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < args.seconds:
            q = robot.nominal_q + rng.normal(scale=0.1, size=12)
            pos = np.array([rng.uniform(0.3, 1.7), rng.uniform(-0.1, 0.1), base_h + 0.05])
            cm.distance(robot, sdf, q, pos)
            n += 1
        dt = time.perf_counter() - t0
        rows.append({"robot": name, "primitives": len(cm), "queries": n, "queries_per_s": n / dt})
    print(f"{'robot':<12}{'primitives':>12}{'queries/s':>14}")
    for r in rows:
        print(f"{r['robot']:<12}{r['primitives']:>12}{r['queries_per_s']:>14.0f}")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"machine": machine_description(), "results": rows}, indent=2))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
