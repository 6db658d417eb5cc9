"""``roughwalk init generate|train|iterate``: learned initial guesses (Melon 2020, Alg. 1)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from roughwalk.cli.common import info

__all__ = ["register"]

DEFAULT_ROOT = Path(".experience")


def _problem_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--env",
        default="single_pallet",
        help="environment: flat, single_pallet or double_pallet (default), or a terrain "
        "spec with --goal",
    )
    p.add_argument("--goal", help="goal X,Y,YAW for a terrain that is not a named environment")
    p.add_argument(
        "--edge-x", type=float, help="x [m] of the obstacle's edge (starts 0.5–1.5 m before it)"
    )
    p.add_argument("--robot", default="anymal_c", help="a registered robot")
    p.add_argument("--gait", default="walk", help="walk (default), trot, pace, bound, gallop")
    p.add_argument(
        "--steps", type=int, help="swings of all feet (default: the environment's, 16 elsewhere)"
    )
    p.add_argument(
        "--duration",
        type=float,
        help="total duration [s] (default: the environment's, 5.5 elsewhere)",
    )
    p.add_argument(
        "--optimize-durations", action="store_true", help="optimise the phase durations too"
    )
    p.add_argument(
        "--constraints",
        help="constraint set: melon, melon_reach (the default set) or towr, or "
        "comma-separated constraint names",
    )
    p.add_argument(
        "--set",
        metavar="costs.NAME=VALUE",
        action="append",
        default=[],
        help="a cost weight that differs from melon_config's, as for roughwalk optimize "
        "(repeatable, dotted names: costs.force_between_nodes_penalty=10, costs.force.weight=0.1), "
        "or a learned solve's restart setting (solver.guess_fallback_after=40, "
        "solver.dear_guess_restarts=0: a learned run folder records them), "
        "or swing_base_clearance=0.5 (the trunk's least height over a swinging foot, "
        "a fraction of the nominal height; the run and its model record it)",
    )


def _executor_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--executor", default="local", choices=("local", "ray"), help="where to solve")
    p.add_argument("--address", help="Ray cluster address (with --executor ray)")
    p.add_argument("--workers", type=int, default=1, help="local worker processes (default 1)")


def register(sub: Any) -> None:
    """Add the ``init`` command and its subcommands."""
    p = sub.add_parser(
        "init",
        help="learned initial guesses: generate experience, train, iterate",
        description="Melon et al.'s Algorithm 1: solve sampled tasks from the heuristic "
        "guess (generate), learn task → solution (train), re-solve from the learned guess "
        "and retrain (iterate).",
    )
    s = p.add_subparsers(dest="init_command", metavar="SUBCOMMAND")

    g = s.add_parser("generate", help="solve sampled tasks and store the experience (resumable)")
    _problem_args(g)
    _executor_args(g)
    g.add_argument("--tasks", type=int, default=2000, help="number of tasks (default 2000)")
    g.add_argument(
        "--first-task",
        type=int,
        default=0,
        help="index of the first task of the stream (default 0): --tasks 1000 --first-task 1000 "
        "solves tasks 1000..1999, fresh tasks for another round with the same seed, so that "
        "init train can aggregate both runs",
    )
    g.add_argument("--split", default="train", choices=("train", "test"), help="task stream")
    g.add_argument("--seed", type=int, default=0, help="task sampling seed")
    g.add_argument("--max-iter", type=int, help="IPOPT iterations (default 100, N_h)")
    g.add_argument(
        "--time-limit",
        type=float,
        metavar="SECONDS",
        help="IPOPT's wall-time limit per solve (default: the solver's, 40 s); raise it on a "
        "busy machine, where a solve can stop on time before its iteration limit (a solve "
        "that stopped on time stays done when the folder is resumed)",
    )
    g.add_argument(
        "--init",
        default="heuristic",
        help="heuristic (default), learned:MODEL, or nearest:RUN[,RUN...]: each task from the "
        "solution of the nearest feasible solve of those run folders and this run, nearest "
        "tasks first",
    )
    g.add_argument("--out", type=Path, help="run folder (default .experience/ENV_GAITSTEPS_SPLIT)")
    g.add_argument(
        "--jitter",
        metavar="SX,SY,SYAW",
        help="with --init learned:MODEL: ask the model about each task with its start moved "
        "by these standard deviations (m, m, rad): a multi-start re-solve",
    )
    g.add_argument("--jitter-seed", type=int, default=0, help="seed of the jitter draws")
    g.add_argument(
        "--start-x-max",
        type=float,
        help="solve only the tasks (of the --tasks from --first-task) whose start x is at most "
        "this (m)",
    )
    g.add_argument(
        "--start-x-min",
        type=float,
        help="solve only the tasks (of the --tasks from --first-task) whose start x is at least "
        "this (m)",
    )
    g.add_argument(
        "--start-y-max",
        type=float,
        help="solve only the tasks (of the --tasks from --first-task) whose start y is at most "
        "this (m; y left, so -0.3 keeps starts right of the centre line)",
    )
    g.add_argument(
        "--start-y-min",
        type=float,
        help="solve only the tasks (of the --tasks from --first-task) whose start y is at least "
        "this (m)",
    )
    g.set_defaults(func=cmd_generate)

    t = s.add_parser("train", help="filter a dataset and fit the learned initialiser")
    t.add_argument("runs", nargs="+", type=Path, help="run folders or dataset .npz files")
    t.add_argument("--out", type=Path, required=True, help="model file (.npz)")
    t.add_argument("--layers", default="64,64", help="hidden layer sizes (default 64,64)")
    t.add_argument("--g-max", type=float, help="cost threshold (default: start of the tail)")
    t.add_argument("--seed", type=int, default=0, help="training seed")
    t.add_argument("--max-epochs", type=int, default=300, help="L-BFGS iterations")
    t.add_argument("--note", default="", help="text stored in the model header")
    t.add_argument(
        "--round",
        type=int,
        default=1,
        help="the LearnedInit round recorded in the header (default 1: heuristic data)",
    )
    t.add_argument(
        "--library",
        action="store_true",
        help="also keep D_good's solutions and multipliers in the model (a solution "
        "library): the guess is then a training solution, not the network's output",
    )
    t.set_defaults(func=cmd_train)

    it = s.add_parser(
        "iterate", help="LearnedInit-1..K: re-solve from the model, re-filter, retrain"
    )
    it.add_argument("run", type=Path, help="the heuristic experience run folder")
    it.add_argument("--rounds", type=int, default=3, help="LearnedInit rounds (default 3)")
    it.add_argument("--tasks", type=int, help="re-solve only the first N tasks")
    it.add_argument("--max-iter", type=int, default=25, help="N_θ (default 25)")
    it.add_argument("--out", type=Path, required=True, help="folder for rounds and models")
    it.add_argument("--g-max", type=float, help="cost threshold (default: start of the tail)")
    it.add_argument("--seed", type=int, default=0, help="training seed")
    it.add_argument(
        "--set",
        metavar="solver.NAME=VALUE",
        action="append",
        default=[],
        help="a re-solve's restart setting (solver.guess_fallback_after=40, "
        "solver.dear_guess_restarts=0): each round's folder records them",
    )
    _executor_args(it)
    it.set_defaults(func=cmd_iterate)
    p.set_defaults(func=lambda args: p.print_help() or 2)


def _space(args: argparse.Namespace) -> Any:
    from roughwalk.learning.task_space import ENVIRONMENTS, TaskSpace
    from roughwalk.trajopt import parse_pose

    if args.goal is None and args.edge_x is None and args.env in ENVIRONMENTS:
        return ENVIRONMENTS[args.env]
    if args.goal is None:
        from roughwalk.errors import InvalidArgumentError

        raise InvalidArgumentError(
            f"--env {args.env!r} is not a named environment: give --goal X,Y,YAW "
            f"(named: {', '.join(ENVIRONMENTS)})"
        )
    return TaskSpace.for_terrain(args.env, parse_pose(args.goal, "--goal"), edge_x=args.edge_x)


def cmd_generate(args: argparse.Namespace) -> int:
    """Solve ``--tasks`` sampled tasks into a resumable run folder."""
    from roughwalk.learning.executors import make_executor
    from roughwalk.learning.experience import N_HEURISTIC, generate
    from roughwalk.learning.neighbour_starts import parse_nearest
    from roughwalk.learning.problem_spec import (
        ProblemSpec,
        constraint_set,
        cost_weights,
        nlp_settings,
        solver_settings,
    )

    space = _space(args)
    spec = ProblemSpec(
        args.robot,
        space.terrain,
        args.gait,
        space.steps if args.steps is None else args.steps,
        space.duration if args.duration is None else args.duration,
        args.optimize_durations,
        None if args.constraints is None else constraint_set(args.constraints),
        cost_weights(args.set),
        solver_settings(args.set),
        **{"swing_base_clearance": space.swing_base_clearance, **nlp_settings(args.set)},
    )
    out = args.out or DEFAULT_ROOT / f"{space.name}_{args.gait}{spec.steps}_{args.split}"
    seeds = parse_nearest(args.init)
    jitter = _jitter(args.jitter, args.init != "heuristic" and seeds is None)
    model = None
    max_iter = args.max_iter
    if args.init != "heuristic" and seeds is None:
        from roughwalk.errors import InvalidArgumentError
        from roughwalk.learning.initializer import model_for_spec

        if args.init.partition(":")[0] != "learned":
            raise InvalidArgumentError(
                f"--init {args.init}: experience starts from heuristic, learned[:MODEL] or "
                f"nearest:RUN[,RUN...] (a learned start's model must be of this problem)"
            )

        model = model_for_spec(args.init, spec)
        max_iter = 25 if max_iter is None else max_iter
    if args.first_task < 0 or args.tasks < 0:
        from roughwalk.errors import InvalidArgumentError

        raise InvalidArgumentError(
            f"--first-task and --tasks must be >= 0, got {args.first_task} and {args.tasks}"
        )
    span = range(args.first_task, args.first_task + args.tasks)
    indices = None if args.first_task == 0 else list(span)
    box = (args.start_x_min, args.start_x_max, args.start_y_min, args.start_y_max)
    if any(bound is not None for bound in box):
        indices = [
            i
            for i in span
            if _start_in_box(space.task(i, seed=args.seed, split=args.split).start, box)
        ]
    executor = make_executor(args.executor, workers=args.workers, address=args.address)
    n = args.tasks if indices is None else len(indices)
    info(f"solving {n} {args.split} tasks of {space.name} into {out} ...")
    data = generate(
        spec,
        space,
        args.tasks,
        out,
        split=args.split,
        seed=args.seed,
        max_iter=N_HEURISTIC if max_iter is None else max_iter,
        model=model,
        init=args.init,
        executor=executor,
        indices=indices,
        jitter=jitter,
        jitter_seed=args.jitter_seed,
        seeds=seeds,
        batch=args.workers,
        time_limit_s=args.time_limit,
    )
    solved = int(sum(s in ("exact", "approximate") for s in data["status"]))
    print(f"{len(data)} tasks in {out / 'dataset.npz'}: {solved} converged")
    return 0


def _start_in_box(
    start: tuple[float, float, float],
    box: tuple[float | None, float | None, float | None, float | None],
) -> bool:
    """Whether a start's x and y [m] lie in ``box`` = (x_min, x_max, y_min, y_max).

    The bounds are inclusive; a missing one (None) leaves that side open.
    """
    x_min, x_max, y_min, y_max = (
        math.inf * s if b is None else b for b, s in zip(box, (-1, 1, -1, 1), strict=True)
    )
    return x_min <= start[0] <= x_max and y_min <= start[1] <= y_max


def _jitter(text: str | None, learned: bool) -> tuple[float, float, float] | None:
    """``--jitter SX,SY,SYAW`` as three floats; only meaningful with a learned guess."""
    from roughwalk.errors import InvalidArgumentError

    if text is None:
        return None
    if not learned:
        raise InvalidArgumentError(
            "--jitter moves the task a model is asked about: give --init learned:MODEL"
        )
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(v >= 0.0 for v in values):
        raise InvalidArgumentError(f"--jitter is SX,SY,SYAW, three numbers >= 0; got {text!r}")
    return values[0], values[1], values[2]


def cmd_train(args: argparse.Namespace) -> int:
    """Filter the datasets and fit a model."""
    from roughwalk.learning.training import load_datasets, train_model

    data = load_datasets(args.runs)
    layers = tuple(int(v) for v in str(args.layers).split(",") if v.strip())
    model, report = train_model(
        data,
        layers=layers,
        g_max=args.g_max,
        seed=args.seed,
        max_epochs=args.max_epochs,
        note=args.note,
        learned_round=args.round,
        library=args.library,
    )
    model.save(args.out)
    print(report.summary())
    info(f"wrote {args.out}")
    return 0


def cmd_iterate(args: argparse.Namespace) -> int:
    """LearnedInit-1..K from a heuristic run."""
    from roughwalk.errors import InvalidArgumentError
    from roughwalk.learning.executors import make_executor
    from roughwalk.learning.iterate import learned_init_rounds
    from roughwalk.learning.problem_spec import solver_settings

    if any(not item.strip().startswith("solver.") for item in args.set):
        raise InvalidArgumentError(f"init iterate's --set takes solver.NAME=VALUE, got {args.set}")
    executor = make_executor(args.executor, workers=args.workers, address=args.address)
    rounds = learned_init_rounds(
        args.run,
        args.out,
        rounds=args.rounds,
        n_tasks=args.tasks,
        max_iter=args.max_iter,
        g_max=args.g_max,
        seed=args.seed,
        executor=executor,
        progress=sys.stderr,
        solver=solver_settings(args.set),
    )
    for r in rounds:
        print(r.summary())
    return 0
