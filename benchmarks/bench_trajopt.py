"""Iterations, time per iteration and total solve time of the dynamic trajectory optimiser.

Two families of tasks (issue 8):

* Melon et al.'s (ICRA 2020, §V), with their costs and constraints
  (``melon_config``): flat ground 1.5 m in 3.5 s trotting (14 steps), the
  single pallet (from 0.5–1.5 m before its edge to (1.6, 0) on top) and the
  double pallet (to (1.8, 0) on the upper level), walking 16 steps in 5.5 s,
  and the single pallet with optimised phase durations;
* TOWR's own test tasks (``towr_config``: TOWR 1.4's feasibility problem with
  its ANYmal values and IPOPT tolerances), T = 3.5 s, 16-step gaits as TOWR's
  figures were measured, goals 1.0–2.5 m ahead on flat ground and TOWR's
  block, stairs, gap and slope, with fixed and optimised phase durations.

Every task runs ``--runs`` times: the first run builds the NLP (its time is
"cold", building included), the next ones reuse it ("warm", the median is
shown), as a planner solving many tasks on one terrain would. TOWR 1.4's
figures measured on this machine kind (issue 8; IPOPT 3.11.9 + MUMPS, exact
Jacobians, L-BFGS Hessian, 40 s CPU limit, medians of 3 runs) are printed
beside ours. The time limit is TOWR's 40 s. Wall times on a shared machine
depend on its load, so the process CPU time of each solve is recorded too,
and the cold run's CPU beyond a warm one's as the build CPU ("b. cpu"). By
default nothing is cached on disk: "cold" is a build from scratch. With
``--compiled on`` the first process compiles each NLP to C (gcc's CPU, in a
child process, is the "gcc" column) and stores it in the cache
(``$ROUGHWALK_CACHE``); a second process loads it ("build" says
expression, compiled or cached). ``--compiled auto`` stores CasADi's
serialised functions instead of compiling ("serialized", then
"deserialized" in a later process).

CPU time is not a fixed cost on a shared machine either: what runs on the
other core (or hyper-thread) slows this one. In session 8 the same commit's
flat walk took 0.56–0.99 s cold CPU (build 0.40–0.75 s) from one run to the
next, and all of session 7's merges measured alike when interleaved (0.56–0.61
s): compare figures from one run, or interleave the versions compared.

Run: ``python3 benchmarks/bench_trajopt.py [--quick] [--runs N]`` or
``roughwalk bench trajopt``. Writes ``benchmarks/results/trajopt.json``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from roughwalk.cli.common import machine_description, result_envelope, write_json
from roughwalk.trajopt import TrajoptResult, clear_cache, melon_config, optimize_motion, towr_config

RESULTS = Path(__file__).resolve().parent / "results" / "trajopt.json"


@dataclass(frozen=True)
class Case:
    """One benchmark task."""

    name: str
    family: str
    terrain: str
    goal: tuple[float, float, float]
    gait: str
    steps: int
    duration: float
    optimize_durations: bool = False
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    towr: str = ""  # TOWR 1.4's figure for the same task (issue 8), "" where none was given
    quick: bool = False
    options: dict[str, Any] = field(default_factory=dict)


CASES = [
    Case("flat trot 1.5 m", "melon", "flat", (1.5, 0, 0), "trot", 14, 3.5, quick=True),
    Case("single pallet, 1.0 m before", "melon", "single_pallet", (1.6, 0, 0), "walk", 16, 5.5,
         quick=True),
    Case("single pallet, 1.5 m before", "melon", "single_pallet", (1.6, 0, 0), "walk", 16, 5.5,
         start=(-0.5, 0.2, 0.3)),
    Case("single pallet, 0.5 m before", "melon", "single_pallet", (1.6, 0, 0), "walk", 16, 5.5,
         start=(0.5, -0.2, -0.3)),
    Case("double pallet", "melon", "double_pallet", (1.8, 0, 0), "walk", 16, 5.5, quick=True),
    Case("single pallet, 1.0 m before, opt. durations", "melon", "single_pallet", (1.6, 0, 0),
         "walk", 16, 5.5, True),
    Case("flat walk 1.5 m", "towr", "flat", (1.5, 0, 0), "walk", 16, 3.5,
         towr="17 it, 0.54–0.62 s", quick=True),
    Case("flat walk 1.5 m, opt. durations", "towr", "flat", (1.5, 0, 0), "walk", 16, 3.5, True,
         towr="1.45 s"),
    Case("flat trot 1.5 m", "towr", "flat", (1.5, 0, 0), "trot", 16, 3.5,
         towr="13 it, 0.42–0.49 s", quick=True),
    Case("block, goal 1.0 m", "towr", "towr_block", (1.0, 0, 0), "walk", 16, 3.5,
         towr="22–64 it, 0.66–1.9 s"),
    Case("block, goal 1.5 m", "towr", "towr_block", (1.5, 0, 0), "walk", 16, 3.5,
         towr="22–64 it, 0.66–1.9 s", quick=True),
    Case("block, goal 1.5 m, opt. durations", "towr", "towr_block", (1.5, 0, 0), "walk", 16, 3.5,
         True, towr="2.6–5.3 s"),
    Case("stairs, goal on them 1.0 m", "towr", "towr_stairs", (1.0, 0, 0), "walk", 16, 3.5,
         towr="fails (40 s limit)", quick=True),
    Case("stairs, goal on them 1.0 m, opt. durations", "towr", "towr_stairs", (1.0, 0, 0), "walk",
         16, 3.5, True, towr="3.9–12 s"),
    Case("stairs, goal 1.5 m", "towr", "towr_stairs", (1.5, 0, 0), "walk", 16, 3.5,
         towr="0.64–0.90 s"),
    Case("stairs, goal 2.0 m", "towr", "towr_stairs", (2.0, 0, 0), "walk", 16, 3.5,
         towr="0.64–0.90 s"),
    Case("gap, goal 2.0 m, walk", "towr", "towr_gap", (2.0, 0, 0), "walk", 16, 3.5,
         towr="fails (40 s limit)", quick=True),
    Case("gap, goal 2.5 m, trot", "towr", "towr_gap", (2.5, 0, 0), "trot", 16, 3.5,
         towr="fails (one opt. run: 23 s)"),
    Case("gap, goal 2.0 m, bound", "towr", "towr_gap", (2.0, 0, 0), "bound", 16, 3.5,
         towr="3.5–37.5 s"),
    Case("slope, goal 2.0 m", "towr", "towr_slope", (2.0, 0, 0), "walk", 16, 3.5),
]  # fmt: skip


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def run_case(case: Case, runs: int, compiled: str = "off") -> dict[str, Any]:
    """Solve ``case`` ``runs`` times (the first one builds); return its row."""
    config = (melon_config if case.family == "melon" else towr_config)(
        body_model="towr_anymal", optimize_durations=case.optimize_durations, compiled=compiled
    )
    results: list[TrajoptResult] = []
    cpu: list[float] = []
    compile_cpu = 0.0
    for _ in range(runs):
        before = os.times()
        start = time.process_time()
        r = optimize_motion(
            None, case.terrain, (case.start, case.goal), config=config, gait=case.gait,
            steps=case.steps, duration=case.duration, **case.options,
        )  # fmt: skip
        cpu.append(time.process_time() - start)
        after = os.times()
        # gcc runs as a child process (compiled="on", first run only).
        compile_cpu += (after.children_user + after.children_system) - (
            before.children_user + before.children_system
        )
        results.append(r)
    cold = results[0]
    warm = results[1:] or results
    warm_cpu = cpu[1:] or cpu
    return {
        "name": case.name,
        "family": case.family,
        "terrain": case.terrain,
        "gait": case.gait,
        "steps": case.steps,
        "duration": case.duration,
        "optimize_durations": case.optimize_durations,
        "start": list(case.start),
        "goal": list(case.goal),
        "status": cold.status.value,
        "solved": all(r.solved for r in results),
        "iterations": int(statistics.median(r.iterations for r in warm)),
        "ms_per_iteration": 1000 * statistics.median(r.time_per_iteration_s for r in warm),
        "cold_total_s": cold.solve_time_s,
        "build_s": cold.build_time_s,
        "build": cold.build,
        "compile_cpu_s": compile_cpu,
        "warm_total_s": statistics.median(r.solve_time_s for r in warm),
        "cold_cpu_s": cpu[0],
        "warm_cpu_s": statistics.median(warm_cpu),
        # The solves repeat the cold one's iterations from the same guess, so
        # the cold run's extra CPU is the building (None with --runs 1).
        "build_cpu_s": cpu[0] - statistics.median(warm_cpu) if runs > 1 else None,
        "objective": _finite(cold.objective),
        "max_violation": _finite(cold.max_violation),
        "n_variables": cold.n_variables,
        "towr": case.towr,
    }


def print_table(rows: list[dict[str, Any]]) -> None:
    """The results, one line per task, TOWR's figure last."""
    head = (
        f"{'task':<44} {'status':<11} {'iter':>5} {'ms/it':>7} {'warm s':>7} {'cold s':>7} "
        f"{'build s':>7} {'cpu w/c':>11} {'b. cpu':>6} {'gcc':>5} {'build':<10} {'vars':>5}  "
        "TOWR 1.4"
    )
    family = None
    for row in rows:
        if row["family"] != family:
            family = row["family"]
            title = "Melon et al.'s tasks (costs)" if family == "melon" else "TOWR's tasks"
            print(f"\n{title}\n{head}\n{'-' * len(head)}")
        build_cpu = "-" if row["build_cpu_s"] is None else f"{row['build_cpu_s']:.2f}"
        print(
            f"{row['name']:<44} {row['status']:<11} {row['iterations']:>5} "
            f"{row['ms_per_iteration']:>7.1f} {row['warm_total_s']:>7.2f} "
            f"{row['cold_total_s']:>7.2f} {row['build_s']:>7.2f} "
            f"{row['warm_cpu_s']:>5.2f}/{row['cold_cpu_s']:<5.2f} {build_cpu:>6} "
            f"{row['compile_cpu_s']:>5.1f} {row['build']:<10} "
            f"{row['n_variables']:>5}  "
            f"{row['towr']}"
        )


def main() -> None:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a representative subset")
    parser.add_argument("--runs", type=int, default=3, help="solves per task (first one builds)")
    parser.add_argument("--family", choices=("melon", "towr"), help="only one family of tasks")
    parser.add_argument("--json", type=Path, default=RESULTS, help="where to write the results")
    parser.add_argument(
        "--compiled",
        choices=("off", "on", "auto"),
        default="off",
        help="the NLP's functions from the compiled cache (see TrajoptConfig.compiled)",
    )
    parser.add_argument("--only", action="append", help="only the task of this name (repeatable)")
    args = parser.parse_args()
    cases = [
        c
        for c in CASES
        if (c.quick or not args.quick)
        and args.family in (None, c.family)
        and (not args.only or c.name in args.only)
    ]
    rows = []
    for case in cases:
        clear_cache()
        rows.append(run_case(case, max(args.runs, 1), args.compiled))
        print(f"  {case.name}: {rows[-1]['status']}", flush=True)
    print_table(rows)
    write_json(
        args.json,
        result_envelope("bench_trajopt", machine=machine_description(), runs=args.runs, tasks=rows),
    )
    print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
