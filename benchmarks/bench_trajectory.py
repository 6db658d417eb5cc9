"""Milliseconds to produce one optimised footstep trajectory on the LittleDog boards.

For each board of ``../shared/terrains/littledog`` a plan crosses it (the
footstep planner's, with 10 s to plan; a straight crawl with heuristic
certificates where it finds none), and every footstep's trajectory
is generated (Zucker 2011, §5: timing, ZMP preview, splines, CHOMP, restarts,
checks at the control rate). The time per footstep is what the executor
waits for, restarts included; the target is ≤ 50 ms, so the next step is
ready long before the current one ends. The SDF is built once per board and
not counted. Two settings: the default swing spline, which lifts the foot
over the terrain it scans, and a "blind" one that lifts a fixed 2 cm, as the
paper's heuristic lift-off does, leaving CHOMP to resolve the collisions
(Figure 8). Prints a table per setting and writes
``benchmarks/results/trajectory.json``.

Run: ``python3 benchmarks/bench_trajectory.py [--quick] [--steps N] [--plans DIR]
[--backend rust|python]``. ``--plans DIR`` keeps each board's plan as
``DIR/<board>.json`` and reuses it on the next run, so that runs compare the
same footsteps (the planner is anytime: under load it may find others).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

import roughwalk as rw
from roughwalk.cli.common import machine_description, result_envelope, write_json
from roughwalk.trajectories import FootstepTrajectoryGenerator, straight_crawl_plan

RESULTS = Path(__file__).resolve().parent / "results" / "trajectory.json"
_BESIDE = Path(__file__).resolve().parents[1].parent / "shared"
SHARED = Path(os.environ.get("ROUGHWALK_SHARED") or _BESIDE) / "terrains" / "littledog"
BOARDS = ("A", "AC", "AD", "AE", "C", "Y")
TARGET_MS = 50.0


def make_plan(
    robot: rw.Robot, terrain: rw.Terrain, steps: int, saved: Path | None = None
) -> tuple[Any, str]:
    """A plan across the board and where it came from (read from or written to ``saved``)."""
    if saved is not None and saved.is_file():
        kept = json.loads(saved.read_text())
        return kept["plan"], kept["source"]
    plan, source = _new_plan(robot, terrain, steps)
    if saved is not None:
        saved.parent.mkdir(parents=True, exist_ok=True)
        body = plan.to_json() if hasattr(plan, "to_json") else plan
        saved.write_text(json.dumps({"plan": body, "source": source}))
    return plan, source


def _new_plan(robot: rw.Robot, terrain: rw.Terrain, steps: int) -> tuple[Any, str]:
    x0, x1, y0, y1 = terrain.extent
    try:
        from roughwalk.planning.footstep_planner import plan_footsteps
    except (ImportError, AttributeError):  # the planner's core is not built
        plan_footsteps = None
    if plan_footsteps is not None:
        yc = 0.5 * (y0 + y1)
        # Where the start stance has no certificate, try a little further in.
        for inset in (0.18, 0.15, 0.21, 0.24):
            plan = plan_footsteps(robot, terrain, (x0 + inset, yc, 0.0), (x1 - 0.18, yc), 10.0)
            if plan.solved:
                return plan, "footstep planner (10 s)"
    plan = straight_crawl_plan(
        robot, terrain, (x0 + 0.13, 0.5 * (y0 + y1)), steps=steps, stride=0.05
    )
    return plan, "straight crawl (heuristic certificates)"


SETTINGS = {
    "terrain-aware swing": {},
    "blind swing (CHOMP clears)": {"swing.scan_terrain": False, "swing.lift_height": 0.02},
}


def run_board(
    robot: rw.Robot,
    name: str,
    steps: int,
    overrides: dict[str, Any],
    sdfs: dict[str, Any],
    plans: dict[str, Any],
    plan_dir: Path | None = None,
    backend: str = "auto",
) -> dict[str, Any]:
    """Generate every footstep of a plan across board ``name``; per-step times and validity."""
    terrain = rw.load_terrain(SHARED / f"terrain{name}.mat")
    began = time.perf_counter()
    if name not in sdfs:
        sdfs[name] = terrain.sdf(0.005)
    sdf = sdfs[name]
    sdf_s = time.perf_counter() - began
    cfg = rw.trajectories.trajectory_config(**overrides)
    gen = FootstepTrajectoryGenerator(robot, terrain, sdf=sdf, config=cfg, backend=backend)
    if name not in plans:
        saved = None if plan_dir is None else plan_dir / f"{name}.json"
        plans[name] = make_plan(robot, terrain, steps, saved)
    plan, source = plans[name]
    began = time.perf_counter()
    prepared = gen.prepare(plan)
    prepare_ms = (time.perf_counter() - began) * 1000.0
    ms, cpu_ms, valid, iterations, attempts, invalid = [], [], [], [], [], []
    steps_iter = gen.iter_steps(prepared)
    for k in itertools.count():
        # CPU time of this process (rayon's threads included) per step: it
        # does not grow with the other processes' load as wall time does.
        cpu = time.process_time()
        traj = next(steps_iter, None)
        if traj is None:
            break
        cpu_ms.append((time.process_time() - cpu) * 1000.0)
        r = traj.report
        ms.append(r.optimize_ms)
        valid.append(r.valid)
        iterations.append(r.iterations)
        attempts.append(r.attempts)
        if not r.valid:
            invalid.append(
                {
                    "step": k,
                    "leg": r.leg,
                    "reachable": r.reachable,
                    "collision_free": r.collision_free,
                    "velocity_limits_ok": r.velocity_limits_ok,
                    "zmp_margin_m": r.zmp_margin_m,
                    "min_clearance_m": r.min_clearance_m,
                    "chomp_status": r.chomp_status,
                    "notes": r.notes,
                }
            )
    a = np.array(ms)
    return {
        "board": name,
        "plan": source,
        "steps": len(ms),
        "valid_fraction": float(np.mean(valid)),
        "sdf_build_s": sdf_s,
        "prepare_ms": prepare_ms,
        "ms_per_step": a.tolist(),
        "median_ms": float(np.median(a)),
        "p90_ms": float(np.percentile(a, 90)),
        "max_ms": float(a.max()),
        "within_target": float(np.mean(a <= TARGET_MS)),
        "within_target_cpu": float(np.mean(np.array(cpu_ms) <= TARGET_MS)),
        "cpu_ms_per_step": cpu_ms,
        "median_cpu_ms": float(np.median(cpu_ms)),
        "p90_cpu_ms": float(np.percentile(cpu_ms, 90)),
        "max_cpu_ms": float(np.max(cpu_ms)),
        "mean_iterations": float(np.mean(iterations)),
        "mean_attempts": float(np.mean(attempts)),
        "invalid_steps": invalid,
    }


def figure8_step(robot: rw.Robot, repeats: int = 5, backend: str = "auto") -> dict[str, Any]:
    """The step of Figure 8 (a generated barrier, not a board): CHOMP must clear shin and foot.

    The same scenario as the barrier test: a 4 cm wall, the front leg stepping
    over it with a blind 2 cm lift; ms per repetition, the SDF built once.
    """
    from roughwalk.trajectories.body_keyframes import nominal_fit, pose_over_support
    from roughwalk.trajectories.euler import rpy_to_quat

    terrain = rw.load_terrain("barrier:height=0.04,thickness=0.01,center=1.0")
    cfg = rw.trajectories.trajectory_config(
        **SETTINGS["blind swing (CHOMP clears)"], **{"validity.min_clearance": 0.002}
    )
    gen = FootstepTrajectoryGenerator(robot, terrain, config=cfg, backend=backend)
    feet = robot.nominal_stance.feet.copy()
    feet[:, 0] += 0.98 - feet[0, 0]
    feet[:, 2] = robot.foot_radius
    feet[2, 0] -= 0.05
    target = feet[0] + [0.08, 0.0, 0.0]
    base, rpy = nominal_fit(gen.wb, feet)
    base[2] -= 0.02
    after = feet.copy()
    after[0] = target
    end_base, end_rpy = nominal_fit(gen.wb, after)
    end_base[2] -= 0.02
    end = pose_over_support(gen.wb, after, [0, 1, 2, 3], 0.015, start=(end_base, end_rpy))
    legs = ("LF", "RF", "LH", "RH")
    plan = {
        # Contact points: the foot centres less the radius (flat ground).
        "footsteps": [
            {"leg": n, "x": float(f[0]), "y": float(f[1]), "z": 0.0}
            for n, f in zip(legs, feet, strict=True)
        ]
        + [{"leg": "LF", "x": float(target[0]), "y": float(target[1]), "z": 0.0}],
        "initial_pose": {"base_pos": base.tolist(), "base_quat": rpy_to_quat(rpy).tolist()},
        "certificates": [
            {"step": 1, "base_pos": end.base_pos.tolist(), "base_quat": end.base_quat.tolist()}
        ],
    }
    gen.sdf  # noqa: B018 - build the SDF before timing
    ms, cpu_ms, valid, iterations = [], [], [], []
    for _ in range(repeats):
        cpu = time.process_time()
        traj = next(iter(gen.iter_steps(plan)))
        cpu_ms.append((time.process_time() - cpu) * 1000.0)
        ms.append(traj.report.optimize_ms)
        valid.append(traj.report.valid)
        iterations.append(traj.report.iterations)
    return {
        "median_ms": float(np.median(ms)),
        "ms": ms,
        "median_cpu_ms": float(np.median(cpu_ms)),
        "cpu_ms": cpu_ms,
        "valid": all(valid),
        "iterations": int(np.median(iterations)),
    }


def main() -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="two boards, four steps each")
    parser.add_argument("--steps", type=int, default=12, help="footsteps per board (12)")
    parser.add_argument("--plans", type=Path, help="keep and reuse each board's plan here")
    parser.add_argument(
        "--backend", default="auto", choices=("auto", "rust", "python"), help="CHOMP passes"
    )
    args = parser.parse_args()
    if not SHARED.is_dir():
        print(f"the LittleDog boards are not at {SHARED}")
        return 1
    robot = rw.load_robot("littledog")
    boards = BOARDS[:2] if args.quick else BOARDS
    steps = 4 if args.quick else args.steps
    sdfs: dict[str, Any] = {}
    plans: dict[str, Any] = {}
    # Warm up imports and caches so the first board's first step is not charged for them.
    run_board(robot, boards[0], steps, {}, sdfs, plans, args.plans, args.backend)
    out = {}
    for setting, overrides in SETTINGS.items():
        rows = [
            run_board(robot, b, steps, overrides, sdfs, plans, args.plans, args.backend)
            for b in boards
        ]
        header = (
            f"{'board':<6} {'steps':>5} {'valid':>6} {'median ms':>9} {'p90 ms':>7} "
            f"{'max ms':>7} {'≤50 ms':>6} {'cpu med':>7} {'cpu p90':>7} {'cpu max':>7} "
            f"{'cpu≤50':>6} {'iters':>5} {'tries':>5}  plan"
        )
        print(f"{setting}")
        print(header)
        print("-" * len(header))
        for r in rows:
            print(
                f"{r['board']:<6} {r['steps']:>5} {r['valid_fraction']:>6.0%} "
                f"{r['median_ms']:>9.1f} {r['p90_ms']:>7.1f} {r['max_ms']:>7.1f} "
                f"{r['within_target']:>6.0%} {r['median_cpu_ms']:>7.1f} {r['p90_cpu_ms']:>7.1f} "
                f"{r['max_cpu_ms']:>7.1f} {r['within_target_cpu']:>6.0%} "
                f"{r['mean_iterations']:>5.1f} "
                f"{r['mean_attempts']:>5.2f}  {r['plan']}"
            )
        every = np.concatenate([r["ms_per_step"] for r in rows])
        cpu_every = np.concatenate([r["cpu_ms_per_step"] for r in rows])
        print(
            f"all    {len(every):>5}        {np.median(every):>9.1f} "
            f"{np.percentile(every, 90):>7.1f} {every.max():>7.1f} "
            f"{np.mean(every <= TARGET_MS):>6.0%} {np.median(cpu_every):>7.1f} "
            f"{np.percentile(cpu_every, 90):>7.1f} {cpu_every.max():>7.1f} "
            f"{np.mean(cpu_every <= TARGET_MS):>6.0%}   (target ≤ {TARGET_MS:g} ms)\n"
        )
        out[setting] = {
            "overrides": overrides,
            "boards": rows,
            "median_ms": float(np.median(every)),
            "p90_ms": float(np.percentile(every, 90)),
            "within_target": float(np.mean(every <= TARGET_MS)),
            "median_cpu_ms": float(np.median(cpu_every)),
            "p90_cpu_ms": float(np.percentile(cpu_every, 90)),
            "max_cpu_ms": float(cpu_every.max()),
            "within_target_cpu": float(np.mean(cpu_every <= TARGET_MS)),
            "valid_fraction": float(np.mean([r["valid_fraction"] for r in rows])),
        }
    fig8 = figure8_step(robot, backend=args.backend)
    load = os.getloadavg()
    print(
        f"Figure 8 barrier step (generated terrain): {fig8['median_ms']:.1f} ms median "
        f"({fig8['median_cpu_ms']:.1f} ms CPU) over "
        f"{len(fig8['ms'])} runs, {fig8['iterations']} CHOMP iterations, valid: {fig8['valid']}"
    )
    print(
        f"load average {load[0]:.1f} on {os.cpu_count()} CPUs: the times scale with it "
        "(other processes share the cores)"
    )
    write_json(
        RESULTS,
        result_envelope(
            "bench_trajectory",
            robot=robot.name,
            machine=machine_description(),
            target_ms=TARGET_MS,
            settings=out,
            figure8_step=fig8,
            load_average=list(load),
        ),
    )
    print(f"wrote {RESULTS}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
