"""Benchmark the footstep planner: Zucker 2011, Table 1, on LittleDog courses.

Each course is a flat pad, one shared LittleDog board and another pad (large
rocks AE, round rocks AC, small sloped rocks Y, logs AD), plus the generated
gap. LittleDog starts on the first pad and plans to the far pad with an
anytime run of ``--time-limit`` seconds (the paper's 45 s), then re-plans
from the middle of its plan with a 2 s budget (the paper's recovery target).
Columns as Table 1 — States (expanded), Initial (time to the first plan;
then the same in this process's CPU time), Ratio (initial/final cost) —
plus actions evaluated per second, ε₀, the time-limit overrun and the
re-plan's time to a first plan.

Paper (2009 hardware): 24k-47k states, first plan 1.09-4.40 s, ratio
1.35-2.48, 500-1,100 actions/s. Targets here: >= 100,000 actions/s on one
core, a first plan in <= 0.1 s on every course, overrun <= 10 %.

    python benchmarks/bench_planner.py [--time-limit 45] [--courses AE,AC,Y,AD,gap]
                                       [--golden] [--out benchmarks/results/planner.json]
                                       [--expansions N]
    roughwalk bench planner --time-limit 5

``--expansions N`` stops each run after N expansions instead of the time
limit (deterministic, no re-plan): the same work on any machine, for
instruction counts that the load cannot change::

    valgrind --tool=callgrind \
        --toggle-collect='roughwalk_core::footstep::planner::FootstepPlanner::plan' \
        --dump-after='roughwalk_core::footstep::planner::FootstepPlanner::plan' \
        "$(python -c 'import sys; print(sys.executable)')" \
        benchmarks/bench_planner.py --expansions 1500

writes one profile per course (the interpreter itself, not a shell shim such
as pyenv's: valgrind does not follow child processes); its instructions over
the course's actions evaluated are the instructions per action.

``--golden`` also measures the golden sideways scenario of the tests
(tests/data/footstep_golden_sideways.json): expansions to the first plan with
the Dubins and with the Euclidean heuristic.

Not a test: it prints a table and writes JSON with the machine's description.
The planner's search runs on one thread; the precomputation (SDF) may use more.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import roughwalk as rw
from roughwalk.cli.common import machine_description, write_json
from roughwalk.planning import FootstepConfig, FootstepPlanner

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("ROUGHWALK_SHARED") or HERE.parent.parent / "shared")
GOLDEN = HERE.parent / "tests" / "data" / "footstep_golden_sideways.json"
BOARDS = {
    "AE": ("Large rocks", "terrainAE"),
    "AC": ("Round rocks", "terrainAC"),
    "Y": ("Sloped rocks", "terrainY"),
    "AD": ("Logs", "terrainAD"),
}
PAD = 0.4


def course(name: str) -> tuple[str, rw.Terrain, tuple[float, float, float], tuple[float, float]]:
    """A course, its start trunk pose and its goal."""
    if name == "gap":
        terrain = rw.load_terrain("gap")
        x0, x1, y0, y1 = terrain.extent
        mid = 0.5 * (y0 + y1)
        return "Gap", terrain, (x0 + 0.2, mid, 0.0), (x1 - 0.2, mid)
    label, stem = BOARDS[name]
    path = SHARED / "terrains" / "littledog" / f"{stem}.mat"
    if not path.is_file():
        sys.exit(f"bench_planner: LittleDog board not found: {path}")
    terrain = rw.load_terrain(str(path), pad_before=PAD, pad_after=PAD)
    x0, x1, y0, y1 = terrain.extent
    mid = 0.5 * (y0 + y1)
    return f"{label} ({stem})", terrain, (x0 + 0.2, mid, 0.0), (x1 - 0.2, mid)


def run_course(
    name: str, robot: rw.Robot, time_limit: float, expansions: int | None = None
) -> dict[str, Any]:
    """One anytime run and one 2 s re-plan on a course.

    With ``expansions``, only the run, stopped after that many expansions.
    """
    label, terrain, start, goal = course(name)
    t0 = time.perf_counter()
    planner = FootstepPlanner(robot, terrain)
    precompute = time.perf_counter() - t0
    first_cpu: list[float] = []

    def on_solution(_report: Any) -> bool:
        # CPU time to the first plan: on a shared machine the wall-clock
        # "Initial" grows with the load, this does not (much).
        if not first_cpu:
            first_cpu.append(time.process_time() - cpu1)
        return False

    t1, cpu1 = time.perf_counter(), time.process_time()
    if expansions is None:
        plan = planner.plan(start, goal, time_limit=time_limit, callback=on_solution)
    else:
        plan = planner.plan(
            start, goal, time_limit=None, expansions=expansions, callback=on_solution
        )
    wall, cpu = time.perf_counter() - t1, time.process_time() - cpu1
    row: dict[str, Any] = {
        "course": label,
        "terrain": terrain.spec,
        "status": plan.status,
        "reason": plan.reason,
        "precompute_s": precompute,
        "precompute_parts_s": planner.precompute_s,
        "states": plan.states_expanded,
        "initial_s": plan.first_solution_s,
        "initial_cpu_s": first_cpu[0] if first_cpu else None,
        "ratio": plan.solutions[0].cost / plan.solutions[-1].cost if plan.solutions else None,
        "steps": plan.steps,
        "cost": plan.cost,
        "epsilon0": plan.epsilon0,
        "final_epsilon": plan.final_epsilon,
        "epsilon_bound": plan.epsilon_bound if plan.solutions else None,
        "actions_evaluated": plan.actions_evaluated,
        "actions_per_s": plan.actions_per_s,
        # The search is single-threaded: actions per second of this process's
        # CPU time is the one-core rate with the other processes' share taken
        # out (the wall-clock rate drops with the machine's load).
        "cpu_s": cpu,
        "actions_per_cpu_s": plan.actions_evaluated / cpu if cpu > 0 else None,
        "certificate_cache_hits": plan.certificate_cache_hits,
        "certificate_failures": plan.certificate_failures,
        "solutions": len(plan.solutions),
        "time_limit_s": time_limit if expansions is None else None,
        "expansions_budget": expansions,
        "search_s": plan.search_s,
        "call_s": wall,
        "overrun": (wall - time_limit) / time_limit if expansions is None else None,
    }
    if plan.steps >= 8 and expansions is None:
        # An execution error halfway: re-plan from the feet where they stand.
        k = plan.steps // 2
        stance = plan.stances()[k]
        next_leg = plan.footsteps[4 + k].leg
        t2 = time.perf_counter()
        again = planner.replan(stance, next_leg=next_leg, time_limit=2.0)
        row["replan"] = {
            "status": again.status,
            "first_s": again.first_solution_s,
            "call_s": time.perf_counter() - t2,
            "states": again.states_expanded,
            "certificate_cache_hits": again.certificate_cache_hits,
        }
    return row


def run_golden(robot: rw.Robot, factor: int = 200) -> dict[str, Any]:
    """Expansions to the first plan of the sideways scenario, per heuristic."""
    scenario = json.loads(GOLDEN.read_text())
    terrain = rw.load_terrain(scenario["terrain"])
    out: dict[str, Any] = {"scenario": str(GOLDEN.relative_to(HERE.parent))}
    sdf = None
    budget = scenario["dubins_expansions"]
    for heuristic in ("dubins", "euclidean"):
        config = FootstepConfig.for_robot(robot, heuristic=heuristic, **scenario["settings"])
        planner = FootstepPlanner(robot, terrain, config, sdf=sdf)
        sdf = planner.sdf
        plan = planner.plan(scenario["start"], scenario["goal"], time_limit=None, expansions=budget)
        first = plan.solutions[0].expansions if plan.solutions else None
        out[heuristic] = {
            "first_plan_expansions": first,
            "budget": budget,
            "first_plan_s": plan.first_solution_s,
            "search_s": plan.search_s,
        }
        # The Euclidean search gets `factor` times the Dubins search's budget.
        budget = factor * (first or budget)
    d, e = out["dubins"]["first_plan_expansions"], out["euclidean"]["first_plan_expansions"]
    out["ratio"] = (e / d) if d and e else None
    out["ratio_at_least"] = (out["euclidean"]["budget"] / d) if d and e is None else None
    return out


def fmt(v: float | None, spec: str) -> str:
    return "—" if v is None else format(v, spec)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--time-limit", type=float, default=45.0, help="anytime budget [s] (45)")
    parser.add_argument(
        "--courses", default="AE,AC,Y,AD,gap", help="comma-separated: AE, AC, Y, AD, gap"
    )
    parser.add_argument("--golden", action="store_true", help="also run the golden scenario")
    parser.add_argument(
        "--expansions",
        type=int,
        default=None,
        help="stop each run after this many expansions instead of --time-limit "
        "(deterministic; no re-plan, no overrun)",
    )
    parser.add_argument("--out", default=str(HERE / "results" / "planner.json"))
    args = parser.parse_args()
    names = [c.strip() for c in args.courses.split(",") if c.strip()]
    unknown = [c for c in names if c != "gap" and c not in BOARDS]
    if unknown:
        parser.error(f"unknown course(s) {unknown}; known: {', '.join([*BOARDS, 'gap'])}")
    robot = rw.load_robot("littledog")
    rows = []
    header = (
        f"{'Terrain':<28} {'States':>8} {'Initial':>9} {'cpu':>7} {'Ratio':>6} {'actions/s':>10} "
        f"{'per cpu-s':>10} "
        f"{'eps0':>5} {'overrun':>8} {'replan':>8}  status"
    )
    print(header)
    print("-" * len(header))
    for name in names:
        row = run_course(name, robot, args.time_limit, args.expansions)
        rows.append(row)
        replan = row.get("replan", {}).get("first_s")
        print(
            f"{row['course']:<28} {row['states']:>8} {fmt(row['initial_s'], '8.3f')}s "
            f"{fmt(row['initial_cpu_s'], '6.3f')}s "
            f"{fmt(row['ratio'], '6.2f')} {row['actions_per_s']:>10,.0f} "
            f"{fmt(row['actions_per_cpu_s'], '>10,.0f')} {row['epsilon0']:>5.1f} "
            f"{fmt(row['overrun'], '7.1%')} {fmt(replan, '7.3f')}s  {row['status']}",
            flush=True,
        )
    solved = [r for r in rows if r["initial_s"] is not None]
    summary: dict[str, Any] = {
        "min_actions_per_s": min((r["actions_per_s"] for r in rows), default=None),
        "min_actions_per_cpu_s": min(
            (r["actions_per_cpu_s"] for r in rows if r["actions_per_cpu_s"]), default=None
        ),
        "max_initial_s": max((r["initial_s"] for r in solved), default=None),
        "max_overrun": max((r["overrun"] for r in rows if r["overrun"] is not None), default=None),
        "targets": {"actions_per_s": 100_000, "initial_s": 0.1, "overrun": 0.10},
    }
    summary["met"] = {
        "actions_per_s": bool(rows) and summary["min_actions_per_s"] >= 100_000,
        "initial_s": len(solved) == len(rows) and summary["max_initial_s"] <= 0.1,
        "overrun": summary["max_overrun"] is not None and summary["max_overrun"] <= 0.10,
    }
    print(
        f"\nworst: {summary['min_actions_per_s']:,.0f} actions/s "
        f"({fmt(summary['min_actions_per_cpu_s'], ',.0f')} per CPU second; target 100,000), "
        f"first plan {fmt(summary['max_initial_s'], '.3f')} s (target 0.1), "
        f"overrun {fmt(summary['max_overrun'], '.1%')} (target 10%)"
    )
    result: dict[str, Any] = {
        "benchmark": "planner",
        "machine": machine_description(),
        "time_limit_s": args.time_limit if args.expansions is None else None,
        "expansions_budget": args.expansions,
        "rows": rows,
        "summary": summary,
    }
    if args.golden:
        golden = run_golden(robot)
        result["golden"] = golden
        d = golden["dubins"]["first_plan_expansions"]
        e = golden["euclidean"]["first_plan_expansions"]
        print(
            f"golden sideways: first plan after {d} expansions (Dubins) vs "
            f"{e if e is not None else '> ' + str(golden['euclidean']['budget'])} (Euclidean)"
        )
    write_json(args.out, json.loads(json.dumps(result, default=_jsonable)))
    print(f"wrote {args.out}")
    return 0


def _jsonable(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(type(o).__name__)


if __name__ == "__main__":
    raise SystemExit(main())
