"""Reflex recovery over the phases of the gait: one lateral push per run, at a swept time.

Zucker 2011, §6: a reflex "attempts to restore the robot's balance and place
all four feet firmly on the ground", then the planner re-plans. Whether that
works depends on when in the gait the push lands (which legs are in the
air, how far the trunk has shifted), so a single push time says little.
This sweep walks the test scenario of ``tests/python/test_sim_run.py``
(flat ground, 0.5 m along +x, the planner in its deterministic mode with
2000 expansions, no planning time charged) once per push time, from
``--from`` to ``--to`` in steps of ``--step`` seconds after the first
motion, and reports per push time whether the robot reached the goal, and
its reflexes and re-plans.

Run: ``roughwalk bench push_recovery [--impulse 1.0] [--direction 90]
[--from 1.6] [--to 4.8] [--step 0.2] [--terrain flat] [--set KEY=VALUE ...]``;
``--set`` overrides a simulation setting or, prefixed ``trajectory.``, a
setting of trajectory generation (``trajectory.swing.time_law=even``), as
in ``roughwalk bench littledog``. Writes ``benchmarks/results/push_recovery.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

import roughwalk as rw
from roughwalk.cli.common import (
    machine_description,
    result_envelope,
    simulation_settings,
    write_json,
)
from roughwalk.sim import Push, run
from roughwalk.sim.footstep_source import PlannerSource

RESULTS = Path(__file__).resolve().parent / "results" / "push_recovery.json"
START = (0.25, 0.0, 0.0)
GOAL = (0.75, 0.0)


def push_run(
    robot: rw.Robot,
    terrain: rw.Terrain,
    source: PlannerSource,
    at_s: float,
    impulse: float,
    direction: float,
    sets: dict[str, Any],
    trajectory_config: Any = None,
) -> dict[str, Any]:
    """One walk with a push at ``at_s`` [s] after the first motion; its outcome and events."""
    began = time.process_time()
    result = run(
        robot,
        terrain,
        START,
        GOAL,
        planner=source,
        trajectory_config=trajectory_config,
        disturbances=[Push(impulse_ns=impulse, at_s=at_s, direction_deg=direction)],
        **{"executor.compute_time_scale": 0.0, **sets},
    )
    o = result.outcome
    return {
        "push_s": at_s,
        "success": bool(o.success),
        "reason": o.reason,
        "reflexes": int(o.reflexes),
        "replans": int(o.replans),
        "triggers": [e.get("detail") for e in result.log.events if e["kind"] == "reflex"],
        "cpu_s": time.process_time() - began,
    }


def main(argv: list[str] | None = None) -> int:
    """Run the sweep, print the table, write the JSON."""
    ap = argparse.ArgumentParser(
        prog="roughwalk bench push_recovery", description=__doc__.split("\n")[0]
    )
    ap.add_argument("--impulse", type=float, default=1.0, help="lateral push impulse [N·s]")
    ap.add_argument(
        "--direction", type=float, default=90.0, help="push direction from +x [deg] (90: left)"
    )
    ap.add_argument("--from", dest="first", type=float, default=1.6, help="first push time [s]")
    ap.add_argument("--to", dest="last", type=float, default=4.8, help="last push time [s]")
    ap.add_argument("--step", type=float, default=0.2, help="push time step [s]")
    ap.add_argument("--terrain", default="flat", help="terrain spec")
    ap.add_argument("--expansions", type=int, default=2000, help="planner expansion budget")
    ap.add_argument("--json", default=str(RESULTS), help="where to write the results")
    ap.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        help="override a simulation setting, with a 'trajectory.' prefix a trajectory "
        "setting, with a 'footstep.' prefix a footstep planner setting (repeatable, dotted keys)",
    )
    args = ap.parse_args(argv)
    try:
        sets, traj = simulation_settings(args.set)
    except rw.ConfigError as e:
        ap.error(str(e))
    trajectory_config = rw.trajectories.trajectory_config(**traj) if traj else None
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain(args.terrain)
    source = PlannerSource(robot, terrain, expansions=args.expansions)
    times = np.round(np.arange(args.first, args.last + 1e-9, args.step), 6)
    print(f"{'push [s]':>8} {'ok':>4} {'reflexes':>8} {'replans':>7}  reason", flush=True)
    runs = []
    for at in times:
        r = push_run(
            robot, terrain, source, float(at), args.impulse, args.direction, sets, trajectory_config
        )
        runs.append(r)
        print(
            f"{r['push_s']:>8.2f} {'yes' if r['success'] else 'no':>4} {r['reflexes']:>8} "
            f"{r['replans']:>7}  {r['reason']}",
            flush=True,
        )
    survived = sum(r["success"] for r in runs)
    print(f"survived {survived} of {len(runs)} push times", flush=True)
    doc = result_envelope(
        "bench_push_recovery",
        robot="littledog",
        terrain=args.terrain,
        machine=machine_description(),
        impulse_ns=args.impulse,
        direction_deg=args.direction,
        expansions=args.expansions,
        set={**sets, **{f"trajectory.{k}": v for k, v in traj.items()}},
        survived=survived,
        runs=runs,
    )
    write_json(Path(args.json), doc)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
