"""The Learning Locomotion metric in simulation: LittleDog success rate and speed per class.

Zucker 2011, §1: "by the end of Phase III, LittleDog was required to traverse
obstacles up to 10.8 cm height at speeds in excess of 7.2 cm/s". Each run
plans (the anytime planner, ``--plan-time`` seconds before the clock starts),
optimises each footstep while the previous one executes, and walks in MuJoCo
with integrators, reflexes and re-planning (``roughwalk.run``). Speed is the
straight-line distance from the start feet centroid to the goal over the
time from the first motion to reaching it: every wait for optimisation and
every re-plan counts, measured in wall time on this machine.

Terrain classes: large rocks, round rocks, sloped rocks and logs on the
shared LittleDog boards (``../shared/terrains/littledog``: AE, AC, Y, AD)
when present, crossed from one side to the other, with the seed jittering
the start; and on the generators (a new course per seed) otherwise; gap,
barrier and steps (≤ 10.8 cm) on the generators. ``--disturbances`` adds
runs on generated large rocks under a lateral push, a friction drop and a
±1 cm error in the map the planner sees, and reports how many runs the
reflexes and re-planning rescued (succeeded after at least one reflex).

Run: ``roughwalk bench littledog [--seeds N] [--full] [--disturbances] [--jobs N]
[--set KEY=VALUE ...]``; ``--set`` overrides a simulation setting
(``executor.compute_time_scale=0`` charges no planning time, so results do
not depend on the machine's load) or, prefixed ``trajectory.``, a setting
of trajectory generation (``trajectory.swing.time_law=even``).
With ``--jobs`` runs go to N processes at once; every run's on-line
planning and optimisation is charged in wall time, so on a machine with
fewer free cores than jobs the waits, and so the speeds, suffer.
With ``--expansions N`` runs repeat exactly, whatever the load (two runs
of ``--classes steps --expansions 40000 --seeds 2`` with the fast timing:
every field of every run the same but the wall time). 40000 is about what
the initial plan expands in the default 5 s: 22000–63000 states on barrier,
steps and round rocks, seeds 0–1, on this 2-core machine under load.
After the table's ``|``, each class's clock (first motion to the goal or
the end, summed over its runs) splits into shares, in per cent: shifts,
swings, stretch (a shift's or swing's time beyond its fitted timing: the
re-timing for joint speed limits and the restarts), the last footstep's
settling, waits for optimisation, reflexes' recoveries and re-plans (the
charged planning time and the blend back into the walk); each run's own
split is its ``extra.time_breakdown``, each class's seconds its summary's
``time_s``.
Writes ``benchmarks/results/littledog.json``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
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
from roughwalk.sim import FrictionDrop, MapError, Push, run

RESULTS = Path(__file__).resolve().parent / "results" / "littledog.json"
# The shared data folder beside the checkout, or $ROUGHWALK_SHARED (a worktree elsewhere).
SHARED = (
    Path(
        os.environ.get("ROUGHWALK_SHARED") or Path(__file__).resolve().parents[1].parent / "shared"
    )
    / "terrains"
    / "littledog"
)
BOARDS = {"large_rocks": "AE", "round_rocks": "AC", "sloped_rocks": "Y", "logs": "AD"}
CLASSES = ("large_rocks", "round_rocks", "sloped_rocks", "logs", "gap", "barrier", "steps")
TARGET_CM_S = 7.2
# Shares of a run's clock (roughwalk.sim.time_breakdown) and their columns' heads.
SHARES = ("shift", "swing", "stretch", "settle", "wait", "gate", "reflex", "replan")
SHARE_HEADS = {
    "shift": "shift%",
    "swing": "swing%",
    "stretch": "strch%",
    "settle": "settl%",
    "wait": "wait%",
    "gate": "gate%",
    "reflex": "reflx%",
    "replan": "replan%",
}
# Reasons of a run that did not start because of where the robot was put:
# no certificate, a foot on no foothold, no footstep sequence out of the stance.
NO_START = (
    "no plan: start stance",
    "no plan: start: foot",
    "no plan: the planner found no plan (infeasible)",
)
# A reflex this soon [s] after the first motion counts as the start not holding.
PLACEMENT_S = 0.1
# Time limit [s] of every plan under --expansions: a cap the budget should reach first.
BUDGET_TIME_LIMIT_S = 300.0
# Simulated time [s] of a start probe: the settling hold and the first step's start.
PROBE_S = 0.5
# Start offsets (forward [m], sideways [m]) tried in turn until the start
# stance has a pose certificate. Forward only up to 9 cm left the LittleDog
# logs board (AD) without a start on seed 0: every stance straddled a log.
START_NUDGES = sorted(
    ((dx, dy) for dx in (0.0, 0.03, 0.06, 0.09, 0.12, 0.15) for dy in (0.0, -0.03, 0.03)),
    key=lambda d: (d[0], abs(d[1]), d[1]),
)


def course(
    kind: str, seed: int, full: bool
) -> tuple[str, tuple[float, float, float], tuple[float, float]]:
    """Terrain spec, start (x, y, yaw) and goal (x, y) of run ``seed`` of a terrain class."""
    rng = np.random.default_rng(seed)
    jitter = (rng.uniform(-0.02, 0.02), rng.uniform(-0.01, 0.01), rng.uniform(-0.05, 0.05))
    board = SHARED / f"terrain{BOARDS[kind]}.mat" if kind in BOARDS else None
    if board is not None and board.is_file():
        t = rw.load_terrain(str(board))
        x0, x1, y0, y1 = t.extent
        yc = 0.5 * (y0 + y1)
        start = (x0 + 0.17 + jitter[0], yc + jitter[1], jitter[2])
        return str(board), start, (x1 - 0.15, yc)
    randomized = kind not in ("gap", "barrier", "steps")
    spec = f"{kind}:seed={seed}" if randomized else kind
    length = 1.5 if full else 0.8
    start = (0.25 + jitter[0], jitter[1], jitter[2])
    return spec, start, (0.25 + length, 0.0)


def stands_where_put(result: Any) -> bool:
    """Whether a run's start held: a plan came, and no reflex or fall before the walk began.

    A reflex within :data:`PLACEMENT_S` of the first motion means the trunk
    had already tilted or slid while the robot settled before the clock
    started (board Y: a foot put on a steep rock face slid, tipping the trunk
    12°), which a trial's operator would have seen and fixed. So is a start
    with a foot where the planner allows none (``footstep.edge_drop``: on a
    rock's rim, board AE, seeds 2 and 3, where RF slid off in the first
    swings), and one from which the planner exhausts every footstep without
    a plan (board AE, seed 5, nudged 3 cm right: ``infeasible`` after 0.01 s,
    while the starts 3 cm forward are solved).
    """
    if result.outcome.reason.startswith(NO_START):
        return False
    # The outcome's extra fields, not the flat JSON (read from there, the
    # first motion was always None, and every run that fell anywhere was
    # taken for a start that did not hold and walked again from a nudged start).
    first = result.outcome.extra.get("first_motion_s")
    for event in result.log.events:
        if event["kind"] == "fall" and (first is None or event["time"] <= first + PLACEMENT_S):
            return False
        if event["kind"] == "reflex" and first is not None and event["time"] <= first + PLACEMENT_S:
            return False
    return True


def one_run(
    spec: str,
    start: tuple[float, float, float],
    goal: tuple[float, float],
    plan_time: float,
    disturbances: list[Any],
    sets: tuple[tuple[str, str], ...] = (),
) -> dict[str, Any]:
    """Run once; the result's JSON fields plus the wall time.

    ``sets``: (dotted key, value) overrides; keys under ``trajectory.`` go to
    trajectory generation, the others to the simulation.

    Where the start stance has no pose certificate (feet on a rock edge or
    a log's flank), the start moves as a trial's operator would place the
    robot: forward 3 cm at a time up to 15 cm, and at each of those also
    3 cm to either side (:data:`START_NUDGES`, nearest first). The same
    where the robot, put down there, does not stand still until its first
    step (:func:`stands_where_put`, from a short run up to ``PROBE_S``, and
    then from the run itself, whose longer planning may start from another
    first pose); if no start holds, the last run made (or a run from the
    first start) is the result. The nudges are tried first with
    ``executor.relax_edge_margin`` "replans", so that the robot stands where
    the walk's own foothold checks find a plan, and then, if no start
    held, as ``sets`` say (by default "all": the relaxed checks' plan);
    ``starts_tried`` counts the starts of both passes.
    """
    sim = {k: v for k, v in sets if not k.startswith("trajectory.")}
    traj = {k.removeprefix("trajectory."): v for k, v in sets if k.startswith("trajectory.")}
    trajectory_config = rw.trajectories.trajectory_config(**traj) if traj else None
    # With an expansion budget the probe plans as the run does, so that
    # where the robot is put does not depend on the machine's speed either.
    probe_plan_s = plan_time if int(sim.get("executor.plan_expansions", 0) or 0) else 0.5
    began = time.perf_counter()
    result = None
    tried = 0
    # The robot is put where the walk's own foothold checks find a plan
    # (a first plan without the relaxed edge margin; re-plans may relax it),
    # and only where no start does, where the relaxed checks find one.
    margin_counts = all(
        float(sim.get(f"footstep.{k}", 1.0)) > 0 for k in ("edge_margin", "edge_drop")
    )
    passes = (
        [{**sim, "executor.relax_edge_margin": "replans"}, sim]
        if "executor.relax_edge_margin" not in sim and margin_counts
        else [sim]
    )
    held = False
    for k, settings in enumerate(passes):
        last = k == len(passes) - 1
        for dx, dy in START_NUDGES:
            tried += 1
            where = (start[0] + dx, start[1] + dy, start[2])
            # Put the robot down and let it settle: a short run up to the first step.
            probe = run(
                "littledog",
                spec,
                where,
                goal,
                trajectory_config=trajectory_config,
                **{
                    **settings,
                    "executor.initial_plan_s": probe_plan_s,
                    "outcome.time_limit_s": PROBE_S,
                },
            )
            if not stands_where_put(probe) or (
                not last and probe.outcome.reason.startswith("no plan")
            ):
                continue
            result = run(
                "littledog",
                spec,
                where,
                goal,
                disturbances=disturbances,
                trajectory_config=trajectory_config,
                **{"executor.initial_plan_s": plan_time, **settings},
            )
            # The run's longer planning can start from another first pose than
            # the probe's, which may not hold either: then re-place the robot.
            # In the first pass, a first plan that failed for any reason
            # (a search the margin left without a route) leaves the relaxed pass.
            held = stands_where_put(result) and (
                last or not result.outcome.reason.startswith("no plan")
            )
            if held:
                break
        if held:
            break
    if result is None:
        dx, dy = START_NUDGES[0]
        result = run(
            "littledog",
            spec,
            (start[0] + dx, start[1] + dy, start[2]),
            goal,
            disturbances=disturbances,
            trajectory_config=trajectory_config,
            **{"executor.initial_plan_s": plan_time, **sim},
        )
    out = result.to_dict()
    out["wall_s"] = time.perf_counter() - began
    out["starts_tried"] = tried
    out["rescued"] = bool(out["success"] and out["reflexes"] > 0)
    return out


Job = tuple[str, int, bool, float, str | None, float, tuple[tuple[str, str], ...]]


def seeded_run(args: Job) -> dict[str, Any]:
    """One benchmark run from picklable arguments (for a process pool).

    ``args``: terrain class, seed, full, plan time [s], disturbance name
    (None, "push", "friction", "map"), push impulse [N·s] and ``--set``
    overrides.
    """
    kind, seed, full, plan_time, disturbance, push, sets = args
    spec, start, goal = course(kind, seed, full)
    made: list[Any] = []
    if disturbance is not None:
        if spec.endswith(".mat"):
            spec = f"large_rocks:seed={seed - 100}"
            start, goal = (0.25, 0.0, 0.0), (1.05, 0.0)
        if disturbance == "push":
            made = [Push(push, at_s=2.0 + 0.7 * (seed - 100))]
        elif disturbance == "friction":
            made = [FrictionDrop(0.5)]
        else:
            made = [MapError(0.01, seed=seed - 100)]
    r = one_run(spec, start, goal, plan_time, made, sets)
    r["seed"] = seed
    return r


def time_shares(runs: list[dict[str, Any]]) -> dict[str, float]:
    """Seconds of each share of the clock (:data:`SHARES`), summed over the runs.

    From each run's ``extra.time_breakdown`` (:mod:`roughwalk.sim.time_breakdown`):
    the time from the first motion to the goal or the end, successful runs or not.
    """
    total = dict.fromkeys(SHARES, 0.0)
    for r in runs:
        split = (r.get("extra") or {}).get("time_breakdown") or {}
        for k in SHARES:
            total[k] += float(split.get(f"{k}_s") or 0.0)
    return total


def summarize(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Success rate, speeds of the successful runs, counts, where the clock went."""
    ok = [r for r in runs if r["success"]]
    speeds = [r["speed_cm_s"] for r in ok]
    return {
        "runs": len(runs),
        "success_rate": len(ok) / len(runs) if runs else math.nan,
        "speed_cm_s_mean": float(np.mean(speeds)) if speeds else None,
        "speed_cm_s_min": float(np.min(speeds)) if speeds else None,
        "reflexes": int(sum(r["reflexes"] for r in runs)),
        "replans": int(sum(r["replans"] for r in runs)),
        "rescued": int(sum(r["rescued"] for r in runs)),
        "wait_s": float(sum(r["wait_s"] for r in runs)),
        "failures": sorted({r["reason"] for r in runs if not r["success"]}),
        "time_s": time_shares(runs),
    }


def print_row(name: str, s: dict[str, Any]) -> None:
    """One line of the table."""
    speed = f"{s['speed_cm_s_mean']:.2f}" if s["speed_cm_s_mean"] is not None else "—"
    ok = s["speed_cm_s_mean"] is not None and s["success_rate"] >= 0.95
    met = "yes" if ok and s["speed_cm_s_mean"] >= TARGET_CM_S else "no"
    print(
        f"{name:<28} {s['runs']:>4} {100 * s['success_rate']:>7.0f}% {speed:>9} "
        f"{s['reflexes']:>8} {s['replans']:>7} {s['rescued']:>7} {s['wait_s']:>7.1f} {met:>6}"
        f" |{share_columns(s['time_s'])}",
        flush=True,
    )


def share_columns(seconds: dict[str, float]) -> str:
    """The clock's shares as percentages of their sum, one column each (see :data:`SHARES`)."""
    total = sum(seconds.values())
    cells = [f"{100 * seconds[k] / total:.0f}" if total > 0 else "—" for k in SHARES]
    return "".join(f" {c:>{len(SHARE_HEADS[k])}}" for k, c in zip(SHARES, cells, strict=True))


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark, print the table, write the JSON."""
    ap = argparse.ArgumentParser(
        prog="roughwalk bench littledog", description=__doc__.split("\n")[0]
    )
    ap.add_argument(
        "--seeds", type=int, default=None, help="runs per terrain class (default 2; 10 with --full)"
    )
    ap.add_argument(
        "--full",
        action="store_true",
        help="the real protocol: 10 seeds, 1.5 m courses, disturbances",
    )
    ap.add_argument("--disturbances", action="store_true", help="add the disturbance runs")
    ap.add_argument("--classes", default=",".join(CLASSES), help="comma-separated terrain classes")
    ap.add_argument(
        "--plan-time", type=float, default=5.0, help="planning before the clock starts [s]"
    )
    ap.add_argument(
        "--expansions",
        type=int,
        default=0,
        metavar="N",
        help="plan and re-plan with a budget of N expanded states, computing time free "
        f"and time limits of {BUDGET_TIME_LIMIT_S:g} s, so that results do not depend on "
        "the machine's load (default: the anytime time limits)",
    )
    ap.add_argument("--push", type=float, default=0.6, help="lateral push impulse [N·s]")
    ap.add_argument("--json", default=str(RESULTS), help="where to write the results")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once (processes)")
    ap.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        help="override a simulation setting, with a 'trajectory.' prefix a trajectory "
        "setting, with a 'footstep.' prefix a footstep planner setting (repeatable, dotted keys)",
    )
    args = ap.parse_args(argv)
    if args.expansions < 0:
        ap.error(f"--expansions must be >= 0, got {args.expansions}")
    if args.expansions:
        budget = [
            "executor.compute_time_scale=0",
            f"executor.plan_expansions={args.expansions}",
            f"reflex.replan_budget_s={BUDGET_TIME_LIMIT_S:g}",
        ]
        args.set = [*budget, *args.set]  # the user's --set still wins
        args.plan_time = BUDGET_TIME_LIMIT_S
    # Classes whose board is missing (course() then walks a generated course).
    missing = [
        k
        for k in (c.strip() for c in args.classes.split(","))
        if k in BOARDS and not (SHARED / f"terrain{BOARDS[k]}.mat").is_file()
    ]
    if missing:
        print(
            f"note: the LittleDog boards are not at {SHARED} (set ROUGHWALK_SHARED to the "
            f"shared data folder): {', '.join(missing)} walk generated courses instead",
            file=sys.stderr,
        )
    try:
        sim_sets, traj_sets = simulation_settings(args.set)
    except rw.ConfigError as e:
        ap.error(str(e))
    sets = [*sim_sets.items(), *((f"trajectory.{k}", v) for k, v in traj_sets.items())]
    seeds = args.seeds if args.seeds is not None else (10 if args.full else 2)
    classes = [c.strip() for c in args.classes.split(",") if c.strip()]
    unknown = set(classes) - set(CLASSES)
    if unknown:
        ap.error(f"unknown terrain classes {sorted(unknown)}; known: {', '.join(CLASSES)}")
    header = (
        f"{'terrain class':<28} {'runs':>4} {'success':>8} {'cm/s':>9} {'reflexes':>8} "
        f"{'replans':>7} {'rescued':>7} {'wait s':>7} {'target':>6}"
        f" |{''.join(' ' + SHARE_HEADS[k] for k in SHARES)}"
    )
    print(f"LittleDog in MuJoCo, {seeds} runs per class; target ≥95% at ≥{TARGET_CM_S} cm/s")
    print("after |: % of the runs' clock (first motion to goal or end) per share")
    print(header)
    print("-" * len(header))
    table: dict[str, Any] = {}
    load_before = os.getloadavg()
    frozen = tuple(sets)
    jobs: dict[str, list[Job]] = {
        kind: [
            (kind, seed, args.full, args.plan_time, None, args.push, frozen)
            for seed in range(seeds)
        ]
        for kind in classes
    }
    if args.disturbances or args.full:
        for key, name in (
            (f"large_rocks + push {args.push:g} N·s", "push"),
            ("large_rocks + friction 0.5", "friction"),
            ("large_rocks + map error ±1 cm", "map"),
        ):
            jobs[key] = [
                ("large_rocks", seed + 100, args.full, args.plan_time, name, args.push, frozen)
                for seed in range(seeds)
            ]
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        pending = {
            key: [pool.submit(seeded_run, job) for job in todo] for key, todo in jobs.items()
        }
        for key, futures in pending.items():
            runs = [f.result() for f in futures]
            if key not in classes:
                for r in runs:
                    r["seed"] -= 100
            table[key] = {"summary": summarize(runs), "runs": runs}
            print_row(key, table[key]["summary"])
    write_json(
        args.json,
        result_envelope(
            "bench_littledog",
            robot="littledog",
            machine=machine_description(),
            seeds=seeds,
            full=args.full,
            plan_time_s=args.plan_time,
            plan_expansions=args.expansions or None,
            jobs=args.jobs,
            overrides=dict(sets),
            load_average_before=list(load_before),
            load_average_after=list(os.getloadavg()),
            target_cm_s=TARGET_CM_S,
            classes=table,
        ),
    )
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
