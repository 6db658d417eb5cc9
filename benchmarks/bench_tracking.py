"""Execution success of optimised motions on ANYmal C in MuJoCo (Melon et al. 2020, Figs. 8, 4).

Figure 8's protocol: for held-out tasks of each environment (the double
pallet, the single pallet and flat ground; the task spaces of
``roughwalk.learning``), for each initialiser and each IPOPT iteration limit
(0, 1, 2, 5, 10, 20, 30), solve the NLP (Melon et al.'s costs, the walk of
the environment's task space: 16 steps in 5.5 s as their pallet tasks, 20 in
6.875 s on our double pallet, whose starts lie farther back), execute the result with the
whole-body controller (``roughwalk.track``) and record the success rate and
the mean base tracking error; with fixed and with optimised phase durations.
The robot starts at the plan's first pose; a plan that starts more than
5 cm from its task's start (an unconverged solve need not meet its
initial-state rows) is counted in the table's "off start" column.
20 tasks per point by default, ``--full`` the paper's 100; ``--tasks`` and
``--iters`` make a short run possible. Solves and executions spread over the
learned-initialisation wing's executors (``--workers``, ``--executor ray``).

Figure 4's comparison (``--figure4``): the single-pallet step solved with and
without Melon et al.'s costs (``melon_config`` against TOWR's feasibility
problem, ``towr_config``), both executed; pictures of each go beside the JSON.

The ``learned`` initialiser comes from ``roughwalk.learning`` when it is
installed; otherwise the benchmark says so and runs the heuristic only.

``learned_fixed_durations`` (``--init``) solves the optimised-duration NLP
from the environment's fixed-duration model's guess, its phase durations at
the gait's (``roughwalk.learning.fixed_durations_initializer``); the notes
and each run's ``model`` name the model a learned start used. Every
initialiser of a run solves the NLP of the ``learned`` model that fits the
problem, or with optimised durations and no such model, of the
fixed-duration one.

``--models DIR`` runs ``learned`` with the model file in DIR that fits each
problem instead of the shipped one (a candidate before it is shipped).

Run: ``roughwalk bench tracking [--tasks N] [--iters 0,5] [--env single_pallet]``.
Writes ``benchmarks/results/tracking.json``.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk.cli.common import machine_description, result_envelope, write_json

RESULTS = Path(__file__).resolve().parent / "results" / "tracking.json"
ITERATIONS = (0, 1, 2, 5, 10, 20, 30)
ENVIRONMENTS = ("double_pallet", "single_pallet", "flat")
# The pallet tasks of the paper walk 16 steps in 5.5 s; an environment's task
# space may choose another walk (``walk``), and its learned model shares it.
GAIT, STEPS, DURATION = "walk", 16, 5.5
LEARNED = ("learned", "learned_fixed_durations")
"""The learned initialisers: a model of the problem, and a fixed-duration model's guess."""


def not_run(init: str, optimize_durations: bool) -> str:
    """Why ``init`` is left out with these phase durations ("" when it runs).

    With fixed durations ``learned_fixed_durations`` maps nothing: its guess
    is the ``learned`` fixed-duration model's, run once under that name.
    """
    if init.partition(":")[0] == LEARNED[1] and not optimize_durations:
        return f"{init} with fixed durations is learned's guess; run once, as learned"
    return ""


@dataclass(frozen=True)
class Job:
    """One solve-and-execute."""

    env: str
    terrain: str
    init: str
    max_iter: int
    optimize_durations: bool
    index: int
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    tracking: tuple[tuple[str, str], ...] = ()
    """TrackingConfig fields that differ from the default, dotted key → value (``--tracking``)."""
    constraints: tuple[str, ...] | None = None
    """The NLP's constraint set (None: ``melon_config``'s default)."""
    trajopt: tuple[tuple[str, str], ...] = ()
    """TrajoptConfig fields unlike ``melon_config``'s, dotted key → value (``--trajopt``)."""
    add_constraints: tuple[str, ...] = ()
    """Constraints appended to the set (``--add-constraints``), e.g. ``force_between_nodes``."""
    costs: tuple[tuple[str, float], ...] | None = None
    """Cost weights that differ from ``melon_config``'s, by dotted name (the learned model's)."""


def _task_space(env: str) -> tuple[str, list[Any] | None, str]:
    """(terrain, sampler, note): the learning wing's held-out tasks, or a fallback box."""
    try:
        from roughwalk.learning import task_space
    except ImportError as e:
        return env, None, f"roughwalk.learning unavailable ({e}); fallback task box"
    space = task_space(env)
    return space.terrain, [space], ""


def held_out_tasks(
    env: str,
    n: int,
    seed: int = 0,
    refused: str = "redraw",
    trajopt: tuple[tuple[str, str], ...] = (),
) -> tuple[str, list[Any], str]:
    """``n`` held-out tasks of ``env`` (the test split of its task space).

    A start the solver refuses as input (``task_refusal``: a stance foot on
    a pallet's edge, out of reach of a level base) measures the task sampler,
    not the controller. With ``refused`` "redraw" such a task is drawn again
    (:meth:`TaskSpace.draw`) and the note names it; with "count" it stays
    and counts as a failure ("no trajectory"), as before session 18.
    """
    terrain, spaces, note = _task_space(env)
    if spaces is not None:
        space = spaces[0]
        if refused == "count":
            return terrain, space.sample(n, seed=seed, split="test"), note
        from roughwalk.learning.problem_spec import task_refusal

        spec = _spec(env, False, trajopt)
        tasks, notes = [], [note] if note else []
        for i in range(n):
            task, dropped = space.draw(
                i, seed=seed, split="test", refuse=lambda t: task_refusal(spec, t)
            )
            tasks.append(task)
            notes += [
                f"task {i} redrawn: start {tuple(round(v, 3) for v in t.start)} refused ({why})"
                for t, why in dropped
            ]
        return terrain, tasks, "; ".join(notes)
    import numpy as np

    from roughwalk.trajopt import Task

    goals = {"flat": (1.5, 0.0, 0.0), "single_pallet": (1.6, 0.0, 0.0)}
    goal = goals.get(env, (1.8, 0.0, 0.0))
    rng = np.random.default_rng([seed, 1])
    tasks = [
        Task(
            (float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-0.75, 0.75)), 0.0),
            goal,
        )
        for _ in range(n)
    ]
    return terrain, tasks, note


def walk(env: str) -> tuple[int, float]:
    """(steps, duration [s]) ``env``'s tasks are walked in: its task space's, else 16 in 5.5 s."""
    space = _named_space(env)
    return (STEPS, DURATION) if space is None else (space.steps, space.duration)


def swing_clearance(env: str, trajopt: tuple[tuple[str, str], ...] = ()) -> float | None:
    """``env``'s walk's ``swing_base_clearance`` (its task space's) unless ``--trajopt`` sets it."""
    chosen = dict(trajopt).get("swing_base_clearance")
    if chosen is not None:
        return None if chosen.lower() == "none" else float(chosen)
    space = _named_space(env)
    return None if space is None else space.swing_base_clearance


def _named_space(env: str) -> Any:
    """``env``'s task space, or None (no learning wing, or not a named environment)."""
    try:
        from roughwalk.errors import ConfigError
        from roughwalk.learning import task_space
    except ImportError:
        return None
    try:
        return task_space(env)
    except ConfigError:
        return None


def learned_available() -> str:
    """Why the ``learned`` initialiser cannot be made (empty when it can)."""
    try:
        import roughwalk.learning  # noqa: F401  (registers the initialiser)
        from roughwalk.trajopt import make_initializer

        make_initializer("learned")
    except Exception as e:  # noqa: BLE001  (any failure means: run without it, and say why)
        return f"{type(e).__name__}: {e}"
    return ""


def learned_init(
    env: str,
    optimize_durations: bool,
    models: Path | None,
    trajopt: tuple[tuple[str, str], ...] = (),
    name: str = "learned",
) -> str:
    """The learned initialiser ``name`` for this problem: the shipped model, or one in ``models``.

    ``models`` is a folder of model files (``--models``); the first whose
    header fits the problem (for ``learned_fixed_durations``, the problem
    with fixed durations) is used as ``NAME:FILE``, so that a candidate
    model is benchmarked before it replaces the shipped one. A folder with
    no fitting model gives "NAME:" + the folder, which
    :func:`learned_model_for` then reports as unusable.
    """
    if models is None:
        return name
    try:
        from roughwalk.learning.fixed_durations_initializer import fixed_signature
        from roughwalk.learning.model_file import LearnedModel
    except ImportError:
        return name
    signature = _spec(env, optimize_durations, trajopt).to_dict()
    if name != "learned":
        signature = fixed_signature(signature)
    for path in sorted(models.glob("*.npz")):
        if not LearnedModel.load(path).mismatches(signature):
            return f"{name}:{path}"
    return f"{name}:{models}"


def learned_model_for(
    env: str,
    optimize_durations: bool,
    init: str = "learned",
    trajopt: tuple[tuple[str, str], ...] = (),
) -> str:
    """Why ``init``'s model does not fit the problem of ``env`` ("" when it does)."""
    try:
        from roughwalk.learning.initializer import model_for_spec

        model_for_spec(init, _spec(env, optimize_durations, trajopt))
    except Exception as e:  # noqa: BLE001  (no model: run without it, and say why)
        return f"{type(e).__name__}: {e}"
    return ""


def learned_model_name(
    env: str,
    optimize_durations: bool,
    init: str,
    trajopt: tuple[tuple[str, str], ...] = (),
) -> str | None:
    """The name of the model ``init`` uses for the problem of ``env`` (None: not learned)."""
    if init.partition(":")[0] not in LEARNED:
        return None
    from roughwalk.learning.initializer import model_for_spec

    return model_for_spec(init, _spec(env, optimize_durations, trajopt)).name


def shared_problem(
    env: str,
    optimize_durations: bool,
    models: Path | None,
    trajopt: tuple[tuple[str, str], ...] = (),
) -> tuple[tuple[str, ...] | None, tuple[tuple[str, float], ...] | None]:
    """The constraint set and cost weights every initialiser of ``env`` solves with.

    The ``learned`` model's (:func:`learned_problem`); with optimised
    durations and no such model (the double pallet), the fixed-duration
    model's, which ``learned_fixed_durations`` solves with.
    """
    learned = learned_init(env, optimize_durations, models, trajopt)
    if optimize_durations and learned_model_for(env, optimize_durations, learned, trajopt):
        learned = learned_init(env, optimize_durations, models, trajopt, LEARNED[1])
    return learned_problem(env, optimize_durations, learned, trajopt)


def learned_problem(
    env: str,
    optimize_durations: bool,
    init: str = "learned",
    trajopt: tuple[tuple[str, str], ...] = (),
) -> tuple[tuple[str, ...] | None, tuple[tuple[str, float], ...] | None]:
    """The constraint set and cost weights of ``init``'s learned model (None: the default).

    Every initialiser solves the same NLP on an environment: the one the
    learned model was trained on (the double pallet's adds
    ``unilateral_between_nodes`` and ``joint_torques``; a model trained with
    ``costs.force_between_nodes_penalty=10`` weighs that term), so that the
    initialisers compare on one problem. ``init`` is "learned" (the shipped
    model), "learned:FILE" or "learned_fixed_durations[:FILE]".
    """
    try:
        from roughwalk.learning.model_constraints import spec_for_learned
    except ImportError:
        return None, None
    spec = spec_for_learned(_spec(env, optimize_durations, trajopt), init)
    return spec.constraints, spec.costs


def _spec(env: str, optimize_durations: bool, trajopt: tuple[tuple[str, str], ...] = ()) -> Any:
    """The benchmark's problem of ``env`` (with ``--trajopt``'s clearance) as a ProblemSpec."""
    from roughwalk.learning import ProblemSpec

    steps, duration = walk(env)
    return ProblemSpec(
        terrain=_task_space(env)[0],
        gait=GAIT,
        steps=steps,
        duration=duration,
        optimize_durations=optimize_durations,
        swing_base_clearance=swing_clearance(env, trajopt),
    )


def job_config(job: Job) -> Any:
    """The TrajoptConfig ``job`` solves: the same for every initialiser on its problem.

    The learned model's weights (``job.costs``) are set here rather than left
    to the learned initialiser, so that the heuristic start solves the same
    objective; a weight chosen with ``--trajopt`` wins, as it does for the
    initialiser (:mod:`roughwalk.learning.model_costs`).
    """
    from roughwalk.config import override
    from roughwalk.trajopt import melon_config

    steps, duration = walk(job.env)
    config = melon_config(
        gait=GAIT,
        steps=steps,
        duration=duration,
        optimize_durations=job.optimize_durations,
        swing_base_clearance=swing_clearance(job.env),
    )
    if job.constraints is not None:
        config = replace(config, constraints=job.constraints)
    if job.trajopt:
        config = override(config, dict(job.trajopt))
    if job.add_constraints:
        # Only those the set lacks: a model's recorded set may hold them already.
        new = tuple(c for c in dict.fromkeys(job.add_constraints) if c not in config.constraints)
        config = replace(config, constraints=config.constraints + new)
    if job.costs:
        from roughwalk.learning.model_costs import cost_changes

        chosen = cost_changes(config.costs)
        apply = {f"costs.{k}": v for k, v in job.costs if k not in chosen}
        config = override(config, apply) if apply else config
    return config


def job_tracking(job: Job) -> Any:
    """The TrackingConfig ``job`` executes with: the default and its ``--tracking`` settings."""
    from roughwalk.config import override
    from roughwalk.tracking import TrackingConfig

    return override(TrackingConfig(), dict(job.tracking))


def run_job(job: Job) -> dict[str, Any]:
    """Solve the job's task and execute the result; a plain dict (picklable)."""
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain
    from roughwalk.tracking import track
    from roughwalk.trajopt import Task, optimize_motion

    if job.init.partition(":")[0] in LEARNED:
        import roughwalk.learning  # noqa: F401
    robot = load_robot("anymal_c")
    terrain = load_terrain(job.terrain)
    config = job_config(job)
    row: dict[str, Any] = {
        "env": job.env,
        "init": job.init,
        "max_iter": job.max_iter,
        "optimize_durations": job.optimize_durations,
        "index": job.index,
        "start": list(job.start),
        "model": None,
    }
    started, started_cpu = time.perf_counter(), time.process_time()
    try:
        row["model"] = learned_model_name(job.env, job.optimize_durations, job.init, job.trajopt)
        result = optimize_motion(
            robot,
            terrain,
            Task(job.start, job.goal),
            config=config,
            init=job.init,
            max_iter=max(job.max_iter, 0),
        )
    except Exception as e:  # noqa: BLE001  (a failed solve is a data point, not a crash)
        row.update(success=False, reason=f"solve raised {type(e).__name__}: {e}")
        return row
    row.update(
        solve_status=result.status.value,
        iterations=result.iterations,
        solve_time_s=result.solve_time_s,
        max_violation=result.max_violation if math.isfinite(result.max_violation) else None,
        constraints=list(result.config.get("constraints", [])),
    )
    if result.splines is None:
        row.update(success=False, reason="no trajectory")
        return row
    offset, yaw_offset = start_offset(result, job.start)
    row.update(
        pyramid_violation_n=pyramid_violation(result),
        start_offset_m=offset,
        start_yaw_offset_rad=yaw_offset,
    )
    try:
        outcome = track(result, robot, terrain, job_tracking(job))
    except Exception as e:  # noqa: BLE001
        row.update(success=False, reason=f"execution raised {type(e).__name__}: {e}")
        return row
    # A motion whose first pose is out of reach never starts: its errors are
    # NaN, which JSON cannot hold (the whole run's file used to fail on it).
    row.update(
        success=outcome.success,
        reason=outcome.reason,
        mean_position_error_m=_finite(outcome.mean_position_error_m),
        final_position_error_m=_finite(outcome.final_position_error_m),
        max_orientation_error_rad=_finite(outcome.max_orientation_error_rad),
        fell=outcome.fell,
        tick_cpu_ms=_finite(outcome.mean_tick_cpu_ms),
        first_leg_contact=outcome.first_leg_contact,
        implied_torque=outcome.implied_torque,
        max_implied_torque_nm=(outcome.implied_torque or {}).get("max_nm"),
        friction_demand=outcome.friction_demand,
        time_s=time.perf_counter() - started,
        cpu_s=time.process_time() - started_cpu,
    )
    return row


def pyramid_violation(result: Any, margin_s: float = 0.3, rate_hz: float = 200.0) -> float:
    """Largest max(|f_x| − μ f_z, |f_y| − μ f_z, −f_z) [N] of a stance foot's planned force.

    Sampled every 1/``rate_hz`` [s] between ``margin_s`` and T − ``margin_s``
    [s], so between the force nodes too, where the node rows do not look;
    the upright pyramid (the pallet tops are flat). μ is the body's.
    """
    plan = result.sample(rate_hz)
    keep = (plan["t"] >= margin_s) & (plan["t"] <= result.duration - margin_s)
    f = plan["forces"][keep]
    mu = result.body.friction
    excess = np.maximum(np.abs(f[..., :2]).max(axis=-1) - mu * f[..., 2], -f[..., 2])
    return float(np.where(plan["contact"][keep], excess, -np.inf).max(initial=0.0))


START_OFF_M = 0.05
"""A plan whose first base position lies farther than this [m] from its task's
start is counted as starting off its task (``off_start``): the robot is placed
at the plan's first pose, so its success says nothing about the task's start."""


def start_offset(result: Any, start: tuple[float, float, float]) -> tuple[float, float]:
    """Distance [m] and |yaw difference| [rad] from the task's start to the plan's first pose.

    An unconverged plan need not meet its initial-state rows: on the double
    pallet the learned guess's plans start a median 0.32 m from their task at
    0 iterations (0.24 m at 5; session 12).
    """
    plan = result.sample(times=[0.0])
    x, y, yaw = start
    offset = float(np.hypot(*(plan["base_position"][0, :2] - (x, y))))
    dyaw = (float(plan["base_euler"][0, 2]) - yaw + np.pi) % (2 * np.pi) - np.pi
    return offset, abs(dyaw)


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _executor(name: str, workers: int, address: str | None) -> Any:
    try:
        from roughwalk.learning import make_executor
    except ImportError:
        return None
    return make_executor(name, workers=workers, address=address)


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Success rate and mean tracking error per (env, init, durations, max_iter)."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        key = (r["env"], r["init"], r["optimize_durations"], r["max_iter"])
        groups.setdefault(key, []).append(r)
    out = []
    for (env, init, opt, it), rs in sorted(groups.items(), key=lambda kv: str(kv[0])):
        errors = [
            r["mean_position_error_m"] for r in rs if r.get("mean_position_error_m") is not None
        ]
        ticks = [r["tick_cpu_ms"] for r in rs if r.get("tick_cpu_ms") is not None]
        pyramid = [r["pyramid_violation_n"] for r in rs if r.get("pyramid_violation_n") is not None]
        torque = [
            r["max_implied_torque_nm"] for r in rs if r.get("max_implied_torque_nm") is not None
        ]
        offsets = [r["start_offset_m"] for r in rs if r.get("start_offset_m") is not None]
        beyond = [
            r["friction_demand"]["over_fraction"]
            for r in rs
            if r.get("friction_demand") is not None
        ]
        out.append(
            {
                "env": env,
                "init": init,
                "optimize_durations": opt,
                "max_iter": it,
                "tasks": len(rs),
                "success_rate": sum(bool(r.get("success")) for r in rs) / len(rs),
                "mean_tracking_error_m": sum(errors) / len(errors) if errors else None,
                "mean_tick_cpu_ms": sum(ticks) / len(ticks) if ticks else None,
                "solved_rate": sum(r.get("solve_status") in ("exact", "acceptable") for r in rs)
                / len(rs),
                "median_pyramid_violation_n": float(np.median(pyramid)) if pyramid else None,
                "median_max_implied_torque_nm": float(np.median(torque)) if torque else None,
                "median_beyond_friction_share": float(np.median(beyond)) if beyond else None,
                "median_start_offset_m": float(np.median(offsets)) if offsets else None,
                "off_start": sum(o > START_OFF_M for o in offsets),
            }
        )
    return out


def print_table(summary: list[dict[str, Any]]) -> None:
    """The Figure 8 table."""
    print(
        f"{'env':15s} {'init':10s} {'durations':9s} {'iters':>5s} {'tasks':>5s} "
        f"{'success':>8s} {'tracking err':>12s} {'tick CPU':>9s} {'off start':>9s}"
    )
    for s in summary:
        err = s["mean_tracking_error_m"]
        tick = s["mean_tick_cpu_ms"]
        kind = "optimised" if s["optimize_durations"] else "fixed"
        print(
            f"{s['env']:15s} {s['init']:10s} {kind:9s}"
            f" {s['max_iter']:5d} {s['tasks']:5d} {100 * s['success_rate']:7.0f}% "
            f"{'—' if err is None else f'{100 * err:9.1f} cm':>12s}"
            f"{'—' if tick is None else f'{tick:6.2f} ms':>10s}"
            f" {s.get('off_start', 0):9d}"
        )


def figure4(out_dir: Path) -> list[dict[str, Any]]:
    """The single-pallet step with and without Melon et al.'s costs, executed."""
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain
    from roughwalk.tracking import track
    from roughwalk.trajopt import Task, melon_config, optimize_motion, towr_config
    from roughwalk.viz.tracking import save_tracking_picture

    robot = load_robot("anymal_c")
    terrain = load_terrain("single_pallet")
    task = Task((-0.3, 0.2, 0.3), (1.6, 0.0, 0.0))
    rows = []
    for name, config in (("with Melon's costs", melon_config()), ("TOWR only", towr_config())):
        result = optimize_motion(robot, terrain, task, config=config, body_model="robot")
        row: dict[str, Any] = {"variant": name, "solve_status": result.status.value}
        if result.splines is not None:
            outcome = track(result, robot, terrain)
            picture = out_dir / f"tracking_figure4_{'melon' if 'Melon' in name else 'towr'}.png"
            save_tracking_picture(outcome, picture, title=f"single pallet, {name}")
            log = outcome.log
            assert log is not None
            row.update(
                success=outcome.success,
                reason=outcome.reason,
                mean_position_error_m=outcome.mean_position_error_m,
                max_orientation_error_rad=outcome.max_orientation_error_rad,
                peak_angular_velocity_rad_s=float(abs(log.base_angvel).max()),
                picture=str(picture),
            )
        rows.append(row)
        print(f"figure 4, {name}: {row}")
    return rows


def _tracking_settings(*texts: str) -> tuple[tuple[str, str], ...]:
    """``--tracking`` values as dotted TrackingConfig keys → value strings, checked by name."""
    from roughwalk.tracking import TrackingConfig

    return _settings(texts, TrackingConfig(), "--tracking")


def _trajopt_settings(*texts: str) -> tuple[tuple[str, str], ...]:
    """``--trajopt`` values as dotted TrajoptConfig keys → value strings, checked by name."""
    from roughwalk.trajopt import melon_config

    return _settings(texts, melon_config(), "--trajopt")


def _settings(texts: tuple[str, ...], base: Any, option: str) -> tuple[tuple[str, str], ...]:
    """``NAME=VALUE,...`` (one or more flags, later wins) as the project's ``--set`` overrides.

    Names are dotted keys of any depth (``costs.force.weight=0.1``), read
    by :func:`roughwalk.config.parse_set`; a piece without ``=`` continues
    the previous value, so lists keep their commas
    (``constraints=dynamics,range_of_motion``). The keys and values are
    checked by applying them to ``base`` with :func:`roughwalk.config.override`
    (which names a bad key and lists the valid ones) and kept as strings,
    so that a Job stays plain data; :func:`job_config` applies them.
    """
    from roughwalk.config import override, parse_set
    from roughwalk.errors import ConfigError

    items: list[str] = []
    for text in texts:
        for piece in filter(None, (v.strip() for v in text.split(","))):
            if "=" in piece or not items:
                items.append(piece)
            else:
                items[-1] += "," + piece
    try:
        changes = parse_set(items)
        override(base, changes)
    except ConfigError as e:
        raise SystemExit(f"{option}: {e}") from None
    return tuple(changes.items())


def main() -> None:
    """Run the benchmark and write its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tasks", type=int, default=20, help="held-out tasks per point")
    parser.add_argument("--full", action="store_true", help="the paper's 100 tasks per point")
    parser.add_argument(
        "--iters", default=",".join(map(str, ITERATIONS)), help="IPOPT iteration limits"
    )
    parser.add_argument("--env", default=",".join(ENVIRONMENTS), help="environments")
    parser.add_argument(
        "--init",
        default="heuristic,learned,learned_fixed_durations",
        help="initialisers (learned_fixed_durations runs with optimised durations only)",
    )
    parser.add_argument(
        "--durations", default="fixed,optimised", help="phase durations: fixed, optimised"
    )
    parser.add_argument("--workers", type=int, default=1, help="local worker processes")
    parser.add_argument("--executor", default="local", help="local or ray")
    parser.add_argument("--address", help="Ray cluster address")
    parser.add_argument("--figure4", action="store_true", help="also run Figure 4's comparison")
    parser.add_argument("--seed", type=int, default=0, help="task sampling seed")
    parser.add_argument(
        "--refused-starts",
        choices=("redraw", "count"),
        default="redraw",
        help="a held-out start the solver refuses as input (no level stance): draw it again "
        "(named in the notes) or count it as a failure",
    )
    parser.add_argument(
        "--tracking",
        action="append",
        default=[],
        help="controller settings that differ from the default, NAME=VALUE[,...], "
        "repeatable, dotted names reach nested configs, e.g. track_com=true",
    )
    parser.add_argument(
        "--trajopt",
        action="append",
        default=[],
        help="NLP settings that differ from melon_config's, NAME=VALUE[,...], repeatable, "
        "dotted names reach nested configs, e.g. dt_dynamics=0.05,costs.force.weight=0.1",
    )
    parser.add_argument(
        "--add-constraints",
        default="",
        help="constraints appended to every solve's set where it lacks them, "
        "e.g. force_between_nodes",
    )
    parser.add_argument(
        "--models",
        type=Path,
        help="folder of model files: 'learned' uses the one that fits (default: shipped)",
    )
    parser.add_argument("--json", type=Path, default=RESULTS, help="where to write the results")
    args = parser.parse_args()

    n = 100 if args.full else args.tasks
    iters = [int(v) for v in args.iters.split(",") if v]
    tracking = _tracking_settings(*args.tracking)
    trajopt = _trajopt_settings(*args.trajopt)
    inits = [v for v in args.init.split(",") if v]
    notes = [f"tracking settings: {dict(tracking)}"] if tracking else []
    notes += [f"NLP settings: {dict(trajopt)}"] if trajopt else []
    added = tuple(dict.fromkeys(v for v in args.add_constraints.split(",") if v))
    notes += [f"constraints added: {added}"] if added else []
    if any(i.partition(":")[0] in LEARNED for i in inits):
        why = learned_available()
        if why:
            notes.append(f"learned initialiser unavailable ({why}); heuristic only")
            print(notes[-1])
            inits = [i for i in inits if i.partition(":")[0] not in LEARNED]
    durations = [d == "optimised" for d in args.durations.split(",") if d]
    jobs = []
    for env in [e for e in args.env.split(",") if e]:
        terrain, tasks, note = held_out_tasks(env, n, args.seed, args.refused_starts, trajopt)
        if note:
            notes.append(f"{env}: {note}")
            print(notes[-1])
        for name in inits:
            for opt in durations:
                if why := not_run(name, opt):
                    notes.append(f"{env}: {why}")
                    print(notes[-1])
                    continue
                constraints, costs = shared_problem(env, opt, args.models, trajopt)
                base, _, argument = name.partition(":")
                learned = base in LEARNED
                # A named model file is used as given; otherwise --models or the shipped one.
                init = name
                if learned and not argument:
                    init = learned_init(env, opt, args.models, trajopt, base)
                why = learned_model_for(env, opt, init, trajopt) if learned else ""
                if why:
                    notes.append(f"{env}: {name} initialiser skipped ({why})")
                    print(notes[-1])
                    continue
                if learned:
                    model = learned_model_name(env, opt, init, trajopt)
                    kind = "optimised" if opt else "fixed"
                    notes.append(f"{env}, {kind} durations: {init} uses model {model}")
                    print(notes[-1])
                for it in iters:
                    for i, t in enumerate(tasks):
                        jobs.append(
                            Job(
                                env,
                                terrain,
                                init,
                                it,
                                opt,
                                i,
                                t.start,
                                t.goal,
                                tracking,
                                constraints,
                                trajopt,
                                added,
                                costs,
                            )
                        )
    print(f"{len(jobs)} solve-and-execute jobs ...", flush=True)
    executor = _executor(args.executor, args.workers, args.address)
    started = time.perf_counter()

    def save(rows: list[dict[str, Any]], fig4: list[dict[str, Any]], complete: bool) -> None:
        write_json(
            args.json,
            result_envelope(
                "bench_tracking",
                robot="anymal_c",
                machine=machine_description(),
                tasks_per_point=n,
                gait=GAIT,
                walks={env: walk(env) for env in {job.env for job in jobs}},
                notes=notes,
                complete=complete,
                jobs=len(jobs),
                wall_time_s=time.perf_counter() - started,
                summary=summarise(rows),
                runs=rows,
                figure4=fig4,
            ),
        )

    # Each finished job is printed and saved at once: a long run that is
    # killed keeps what it measured (the file says complete: false).
    rows: list[dict[str, Any]] = []
    results = executor.run(run_job, jobs) if executor else map(run_job, jobs)
    for row in results:
        rows.append(row)
        print(f"[{len(rows)}/{len(jobs)}] {_progress(row)}", flush=True)
        save(rows, [], complete=False)
    summary = summarise(rows)
    print_table(summary)
    fig4 = figure4(args.json.parent) if args.figure4 else []
    save(rows, fig4, complete=True)
    print(f"wrote {args.json} ({time.perf_counter() - started:.0f} s)")


def _progress(row: dict[str, Any]) -> str:
    """One job's line: which point, solved how, tracked how."""
    kind = "optimised" if row["optimize_durations"] else "fixed"
    return (
        f"{row['env']} {row['init']} {kind} iters={row['max_iter']} task {row['index']}: "
        f"{row.get('solve_status', '-')} in {row.get('iterations', '-')} iterations; "
        f"{'success' if row.get('success') else 'failure'}: {row.get('reason', '')}"
        f"{_leg_contact(row.get('first_leg_contact'))}"
        f"{_implied_torque(row.get('implied_torque'))}"
        f"{_friction_demand(row.get('friction_demand'))}"
        f" ({row.get('cpu_s', 0.0):.0f} s CPU)"
    )


def _implied_torque(implied: dict[str, Any] | None) -> str:
    """'; plan asks 317 N·m of RF_HFE at 4.37 s' for the largest torque the plan's forces imply."""
    if not implied:
        return ""
    where = f"{implied['joint']} at {implied['time_s']:.2f} s"
    return f"; plan asks {implied['max_nm']:.0f} N·m of {where}"


def _friction_demand(demand: dict[str, Any] | None) -> str:
    """'; base motion beyond μ 0.6 on 14 % of stance' (the plan's net force outside friction)."""
    if not demand:
        return ""
    return (
        f"; base motion beyond μ {demand['friction']:.2g} on "
        f"{100 * demand['over_fraction']:.0f} % of stance"
    )


def _leg_contact(touch: dict[str, Any] | None) -> str:
    """'; RF knee touched at 4.66 s (planned stance)' for a run's first leg-link touch."""
    if not touch:
        return ""
    return f"; {touch['leg']} leg link touched at {touch['t']:.2f} s (planned {touch['planned']})"


if __name__ == "__main__":
    main()
