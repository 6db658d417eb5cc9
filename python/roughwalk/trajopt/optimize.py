"""``optimize_motion``: from a robot, a terrain and a task to an optimised motion.

The NLP's structure depends on the body, the contact schedule, the duration,
the terrain and the configuration, not on the task: a :class:`TrajoptProblem`
is built once for them and solves any number of tasks, and
:func:`optimize_motion` keeps the last few problems it built so that repeated
calls reuse them.
"""

from __future__ import annotations

import hashlib
import time
import warnings
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.config import override, to_dict
from roughwalk.errors import InvalidArgumentError
from roughwalk.terrain import Terrain, load_terrain
from roughwalk.trajopt import compiled_nlp, serialized_nlp
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.gaits import ContactSchedule, make_gait
from roughwalk.trajopt.guess_projection import project_guess
from roughwalk.trajopt.initializers import Initializer, make_initializer
from roughwalk.trajopt.parameters import SolverOptions, TrajoptConfig, melon_config
from roughwalk.trajopt.result import Splines, TrajoptResult
from roughwalk.trajopt.robot_model import SingleRigidBody, rigid_body_model
from roughwalk.trajopt.solver import (
    IterationInfo,
    SolveOutcome,
    TrajoptSolver,
    TrajoptStatus,
    hessian_choice,
    violation,
)
from roughwalk.trajopt.task import (
    ResolvedTask,
    Task,
    resolve,
    task_problems,
)
from roughwalk.trajopt.terrain_model import TerrainModel
from roughwalk.trajopt.variables import NumericSpline

__all__ = ["TrajoptProblem", "optimize_motion", "clear_cache"]

_MIN_FIXED_PHASE = 0.05  # [s] shorter fixed phases are refused as a duration too short
_CACHE_SIZE = 4
_problems: OrderedDict[tuple[Any, ...], TrajoptProblem] = OrderedDict()
_terrains: OrderedDict[tuple[Any, ...], TerrainModel] = OrderedDict()

_MESSAGES = {
    TrajoptStatus.EXACT: "converged",
    TrajoptStatus.APPROXIMATE: "converged to IPOPT's acceptable tolerance",
    TrajoptStatus.ITERATION_LIMIT: "stopped at the iteration limit before converging",
    TrajoptStatus.TIMEOUT: "stopped at the time limit before converging",
    TrajoptStatus.CANCELLED: "stopped by the iteration callback",
    TrajoptStatus.INFEASIBLE: "IPOPT found the constraints locally infeasible",
    TrajoptStatus.FAILED: "IPOPT failed",
}


class TrajoptProblem:
    """One NLP and its solver, built once, solved for any task.

    Parameters
    ----------
    body:
        The single rigid body.
    terrain:
        The smooth terrain.
    schedule:
        The contact schedule (fixes the duration).
    config:
        The configuration.

    """

    def __init__(
        self,
        body: SingleRigidBody,
        terrain: TerrainModel,
        schedule: ContactSchedule,
        config: TrajoptConfig,
    ) -> None:
        start = time.perf_counter()
        self.body = body
        self.terrain = terrain
        self.schedule = schedule
        self.config = config
        self.build = "expression"
        """How the NLP's functions were made: "expression" (CasADi graphs built
        here), "compiled" (built, compiled to C and stored: the build time
        includes gcc's), "cached" (loaded from a compiled library),
        "serialized" (built and stored in CasADi's serialised form: the build
        time includes the writing) or "deserialized" (read from that form)."""
        self.formulation = self._formulation()
        self.solver = TrajoptSolver(self.formulation, solver_options_for(config))
        self.build_time_s = time.perf_counter() - start
        self._build_pending = True

    def _formulation(self) -> Formulation:
        """The NLP: from the on-disk cache when the config allows (``compiled``).

        A compiled entry is preferred (nothing to read but the layout), then
        a serialised one; "on" compiles a missing one, "auto" serialises it
        (and so does "on" for a structure gcc could not compile).
        """
        cfg, body, schedule, terrain = self.config, self.body, self.schedule, self.terrain
        if cfg.compiled == "off":
            return Formulation(cfg, body, schedule, terrain)
        terrain_key = _terrain_key(terrain.terrain)
        key = compiled_nlp.structure_digest(body, terrain_key, schedule, cfg)
        loaded = compiled_nlp.load(key)
        if loaded is not None:
            self.build = "cached"
            return Formulation(cfg, body, schedule, terrain, compiled=loaded)
        built = None
        serial_key = compiled_nlp.structure_digest(
            body, terrain_key, schedule, cfg, kind=serialized_nlp.KIND
        )
        if cfg.compiled == "on" and not compiled_nlp.failed_before(key):
            built = Formulation(cfg, body, schedule, terrain)
            try:
                compiled_nlp.compile_and_store(
                    key, built.functions(self._exact(built)), built.layout()
                )
            except compiled_nlp.CompileError as e:
                warnings.warn(f"{e}; solving with CasADi's serialised functions", stacklevel=3)
                if serialized_nlp.exists(serial_key):
                    # Stored by an earlier "auto" run: nothing to write, and the
                    # expressions just built serve this solve.
                    return built
            else:
                loaded = compiled_nlp.load(key)
                if loaded is None:
                    return built
                self.build = "compiled"
                return Formulation(cfg, body, schedule, terrain, compiled=loaded)
        if built is None:
            loaded = serialized_nlp.load(serial_key)
            if loaded is not None:
                self.build = "deserialized"
                return Formulation(cfg, body, schedule, terrain, compiled=loaded)
            built = Formulation(cfg, body, schedule, terrain)
        try:
            serialized_nlp.store(serial_key, built.functions(self._exact(built)), built.layout())
        except (OSError, RuntimeError) as e:
            warnings.warn(f"could not store the serialised NLP: {e}", stacklevel=3)
            return built
        self.build = "serialized"
        return built

    def _exact(self, built: Formulation) -> bool:
        """Whether IPOPT will ask for the exact Hessian (then it is cached too)."""
        return hessian_choice(self.config.solver, bool(built.cost_names)) == "exact"

    @property
    def n_variables(self) -> int:
        """Number of decision variables."""
        return self.formulation.n_variables

    def solve(
        self,
        task: Task,
        initializer: Initializer,
        *,
        max_iter: int | None = None,
        time_limit_s: float | None = None,
        callback: Callable[[IterationInfo], bool | None] | None = None,
        warm_start: TrajoptResult | NDArray[np.float64] | None = None,
        extra_time_s: float = 0.0,
    ) -> TrajoptResult:
        """Solve ``task`` from ``initializer``'s guess (or the ``warm_start`` solution).

        The solve's time includes building the problem and making the guess
        (and a fallback guess, if one is made); ``extra_time_s`` [s] adds
        time spent before (loading, checks).
        """
        nlp = self.formulation
        resolved = initializer.adjust_task(resolve(task, self.body, self.terrain))
        lam_x = lam_g = None
        predicted = warm_start is None
        if warm_start is None:
            guessed = time.perf_counter()
            x0 = initializer.guess(nlp, resolved)
            # Onto the linearised rows first, when asked: a guess stopped after
            # 0–5 iterations is what the controller executes.
            x0 = project_guess(nlp, x0, resolved.vector(), self.config.guess_projection)
            # A guess that comes with multipliers (the learned one) warm-starts IPOPT.
            multipliers = getattr(initializer, "multipliers", None)
            if multipliers is not None:
                lam_x, lam_g = multipliers(nlp, resolved)
            # Making the guess is part of the solve's time (the task comes in, not a guess).
            extra_time_s += time.perf_counter() - guessed
        else:
            if isinstance(warm_start, TrajoptResult):
                lam_x, lam_g = warm_start.lam_x, warm_start.lam_g
            x0 = np.asarray(warm_start.x if isinstance(warm_start, TrajoptResult) else warm_start)
            if x0 is None or x0.size != nlp.n_variables:
                raise InvalidArgumentError(
                    f"warm start has {getattr(x0, 'size', 0)} values; "
                    f"this NLP has {nlp.n_variables}"
                )
        build = self.build_time_s if self._build_pending else 0.0
        self._build_pending = False
        limit = self.config.solver.max_iter if max_iter is None else int(max_iter)
        seconds = self.config.solver.time_limit_s if time_limit_s is None else time_limit_s
        after = self.config.solver.guess_fallback_after
        has_fallback = getattr(initializer, "has_fallback", None)
        falls_back = (
            predicted
            and after is not None
            and after < limit
            and callable(has_fallback)
            and bool(has_fallback(nlp))
        )
        outcome = self._solve_from(
            resolved,
            x0,
            lam_x,
            lam_g,
            min(limit, after) if falls_back and after is not None else limit,
            seconds,
            callback,
            predicted,
        )
        notes = []
        # A guess that names where it came from (a learned model) says so in the message.
        source = getattr(initializer, "source", None)
        if predicted and callable(source) and source():
            notes.append(f"guess from {source()}")
        visited = [x0, outcome.x]  # the starts and solutions so far, for further starts
        if falls_back and _restartable(outcome.status):
            guessed = time.perf_counter()
            x1, lam_x1, lam_g1 = initializer.fallback(nlp, resolved)  # type: ignore[attr-defined]
            # The fallback's guess is paid for like the first one.
            extra_time_s += time.perf_counter() - guessed
            second = self._solve_from(
                resolved,
                x1,
                lam_x1,
                lam_g1,
                limit - outcome.iterations,
                max(seconds - outcome.solve_time_s, 1e-3),
                callback,
                predicted,
            )
            notes.append(
                f"restarted from the initialiser's fallback guess after "
                f"{outcome.iterations} iterations from its first"
            )
            visited += [x1, second.x]
            outcome = _joined(outcome, second, nlp)
        restarts = self.config.solver.dear_guess_restarts
        cost_limit = getattr(initializer, "cost_limit", None)
        if predicted and restarts > 0 and callable(cost_limit):
            guessed = time.perf_counter()
            ceiling = cost_limit(nlp, resolved)
            extra_time_s += time.perf_counter() - guessed
            tried = 0
            while (
                ceiling is not None
                and tried < restarts
                and outcome.status.solved
                and outcome.objective > ceiling
                and outcome.iterations < limit
                and outcome.solve_time_s < seconds
            ):
                guessed = time.perf_counter()
                start = initializer.other_start(nlp, resolved, visited)  # type: ignore[attr-defined]
                extra_time_s += time.perf_counter() - guessed
                if start is None:
                    break
                x2, lam_x2, lam_g2 = start
                other = self._solve_from(
                    resolved,
                    x2,
                    lam_x2,
                    lam_g2,
                    limit - outcome.iterations,
                    seconds - outcome.solve_time_s,
                    callback,
                    predicted,
                )
                visited += [x2, other.x]
                outcome = _cheaper(outcome, other)
                tried += 1
                if other.status in (TrajoptStatus.CANCELLED, TrajoptStatus.TIMEOUT):
                    break
            if tried:
                notes.append(
                    f"{tried} more start(s) after a converged cost above the initialiser's "
                    f"limit {ceiling:.4g}; the cheapest kept ({outcome.objective:.4g})"
                )
        result = self._result(task, outcome, build, extra_time_s)
        if notes:
            result.message += "; " + "; ".join(notes)
        return result

    def _solve_from(
        self,
        resolved: ResolvedTask,
        x0: NDArray[np.float64],
        lam_x: NDArray[np.float64] | None,
        lam_g: NDArray[np.float64] | None,
        max_iter: int,
        time_limit_s: float,
        callback: Callable[[IterationInfo], bool | None] | None,
        predicted: bool,
    ) -> SolveOutcome:
        """One IPOPT solve; multipliers of the wrong size are dropped."""
        return self.solver.solve(
            resolved.vector(),
            x0,
            max_iter=max_iter,
            time_limit_s=time_limit_s,
            callback=callback,
            lam_x0=lam_x if lam_x is not None and lam_x.size == x0.size else None,
            lam_g0=(
                lam_g
                if lam_g is not None and lam_g.size == self.formulation.n_constraints
                else None
            ),
            predicted=predicted,
        )

    def _result(self, task: Task, outcome: Any, build: float, extra: float) -> TrajoptResult:
        nlp = self.formulation
        viol = violation(outcome.g, nlp.lbg, nlp.ubg)
        bound_viol = violation(outcome.x, nlp.lbx, nlp.ubx)
        per_row = {
            name: float(viol[s].max()) if viol[s].size else 0.0
            for name, s in nlp.row_slices().items()
        }
        parts = nlp.split(outcome.x)
        durations = [d.unpack(parts[d.name]) for d in nlp.durations]
        schedule = self.schedule.with_durations(durations)
        splines = _splines(nlp, parts, durations)
        times = np.linspace(0.0, schedule.total_duration, 400)
        forces = np.stack([f.evaluate(times)[0] for f in splines.forces], axis=1)
        max_violation = float(max(viol.max(initial=0.0), bound_viol.max(initial=0.0)))
        if not np.all(np.isfinite(outcome.x)):
            max_violation = float("inf")
        message = _MESSAGES.get(outcome.status, outcome.return_status)
        if not outcome.status.solved and per_row:
            worst = max(per_row, key=lambda k: per_row[k])
            message += f"; worst constraint '{worst}' violated by {per_row[worst]:.3g}"
        return TrajoptResult(
            status=outcome.status,
            message=message,
            iterations=outcome.iterations,
            solve_time_s=outcome.solve_time_s + build + extra,
            build_time_s=build,
            build=self.build,
            objective=outcome.objective,
            max_violation=max_violation,
            max_force_n=float(np.linalg.norm(forces, axis=2).max()),
            n_variables=nlp.n_variables,
            n_constraints=nlp.n_constraints,
            task=task,
            config=to_dict(self.config),
            body=self.body,
            schedule=schedule,
            splines=splines,
            costs={c: float(v) for c, v in zip(nlp.cost_names, outcome.costs, strict=True)},
            violations=per_row,
            return_status=outcome.return_status,
            history=outcome.history,
            x=outcome.x,
            lam_x=outcome.lam_x,
            lam_g=outcome.lam_g,
            terrain=self.terrain.name,
        )


def _restartable(status: TrajoptStatus) -> bool:
    """Whether a first solve that ended with ``status`` is restarted from the fallback."""
    return not status.solved and status not in (TrajoptStatus.CANCELLED, TrajoptStatus.TIMEOUT)


def solver_options_for(config: TrajoptConfig) -> SolverOptions:
    """``config``'s solver options with those its duration mode adds.

    ``fixed_durations_ipopt_options`` join ``ipopt_options`` when the phase
    durations are fixed; decided here, from the config the NLP is built
    with, so ``--set optimize_durations=true`` on a preset drops them.
    """
    solver = config.solver
    if config.optimize_durations or not solver.fixed_durations_ipopt_options:
        return solver
    extra = solver.fixed_durations_ipopt_options
    return replace(solver, ipopt_options=solver.ipopt_options + extra)


def _joined(first: SolveOutcome, second: SolveOutcome, nlp: Formulation) -> SolveOutcome:
    """The restart's outcome, unless the first ended nearer feasible; both solves' cost.

    Iterations and time are the sum of both solves (the restart is paid for);
    the history runs on: the restart's iterations are numbered after the first's
    and its times after the first's time, and every entry says which solve it
    comes from (``solve`` 0 or 1). The restart's iteration 0 is its own starting
    point, so its number is the first solve's last one: the key tells them apart.
    """
    chosen = second
    if not second.status.solved and _max_violation(first, nlp) < _max_violation(second, nlp):
        chosen = first
    return _paid(chosen, first, second)


def _cheaper(kept: SolveOutcome, other: SolveOutcome) -> SolveOutcome:
    """The cheaper converged outcome of a converged ``kept`` and a further start's; both paid.

    Iterations and time are the sum of both solves; the history runs on as
    :func:`_joined`'s does: numbers and times after ``kept``'s, and each
    entry's ``solve`` one after the last solve's (0 for an untagged first).
    """
    chosen = other if other.status.solved and other.objective < kept.objective else kept
    return _paid(chosen, kept, other)


def _paid(chosen: SolveOutcome, before: SolveOutcome, after: SolveOutcome) -> SolveOutcome:
    """``chosen`` with the iterations, time and history of the solves ``before`` and ``after``.

    ``after``'s entries are numbered and timed after ``before``'s, and tagged
    one solve after its last (``before``'s untagged entries are solve 0).
    """
    first = [h if "solve" in h else {**h, "solve": 0.0} for h in before.history]
    number = max((h["solve"] for h in first), default=-1.0) + 1.0
    history = first + [
        {
            **h,
            "iteration": h.get("iteration", 0) + before.iterations,
            "elapsed_s": h.get("elapsed_s", 0.0) + before.solve_time_s,
            "solve": number,
        }
        for h in after.history
    ]
    return replace(
        chosen,
        iterations=before.iterations + after.iterations,
        solve_time_s=before.solve_time_s + after.solve_time_s,
        history=history,
    )


def _max_violation(outcome: SolveOutcome, nlp: Formulation) -> float:
    """Largest constraint or bound violation of ``outcome``'s point."""
    if not np.isfinite(outcome.x).all():
        return float("inf")
    rows = violation(outcome.g, nlp.lbg, nlp.ubg).max(initial=0.0)
    return float(max(rows, violation(outcome.x, nlp.lbx, nlp.ubx).max(initial=0.0)))


def _splines(
    nlp: Formulation, parts: dict[str, NDArray[np.float64]], durations: list[NDArray[np.float64]]
) -> Splines:
    def nodes(v: Any, poly_durations: list[float]) -> NumericSpline:
        pos, vel = v.unpack(parts[v.name])
        return NumericSpline(pos, vel, poly_durations)

    def phase_polys(v: Any, foot: int) -> list[float]:
        return [durations[foot][p.phase] / p.polys_in_phase for p in v.polys]

    return Splines(
        nodes(nlp.base_lin, nlp.base_lin.durations),
        nodes(nlp.base_ang, nlp.base_ang.durations),
        [nodes(m, phase_polys(m, f)) for f, m in enumerate(nlp.feet)],
        [nodes(m, phase_polys(m, f)) for f, m in enumerate(nlp.forces)],
    )


def _terrain_key(terrain: Terrain) -> tuple[Any, ...]:
    digest = hashlib.blake2b(
        np.ascontiguousarray(terrain.heights).tobytes(), digest_size=16
    ).hexdigest()
    return (terrain.spec, terrain.shape, terrain.x0, terrain.y0, terrain.dx, terrain.dy, digest)


def _cached(
    cache: OrderedDict[tuple[Any, ...], Any], key: tuple[Any, ...], make: Callable[[], Any]
) -> tuple[Any, bool]:
    if key in cache:
        cache.move_to_end(key)
        return cache[key], True
    value = make()
    cache[key] = value
    while len(cache) > _CACHE_SIZE:
        cache.popitem(last=False)
    return value, False


def clear_cache() -> None:
    """Forget every built problem and terrain model."""
    _problems.clear()
    _terrains.clear()


def _configure(config: TrajoptConfig | None, overrides: Mapping[str, Any]) -> TrajoptConfig:
    cfg = config or melon_config()
    changes: dict[str, Any] = {}
    for key, value in overrides.items():
        if key == "fixed_durations":
            changes["optimize_durations"] = not value
        else:
            changes[key.replace("__", ".")] = value
    return override(cfg, changes) if changes else cfg


def _invalid(
    task: Task | None,
    cfg: TrajoptConfig,
    message: str,
    robot: str | None,
    terrain: str | None,
    elapsed: float,
) -> TrajoptResult:
    return TrajoptResult(
        status=TrajoptStatus.INVALID_INPUT,
        message=message,
        solve_time_s=elapsed,
        task=task,
        config=to_dict(cfg),
        robot=robot,
        terrain=terrain,
    )


def _schedule_problems(schedule: ContactSchedule, cfg: TrajoptConfig) -> list[str]:
    out = []
    lo, hi = cfg.phase_duration_bounds
    for foot, durations in enumerate(schedule.durations):
        if cfg.optimize_durations and len(durations) * lo > schedule.total_duration + 1e-9:
            out.append(
                f"duration {schedule.total_duration:g} s is too short for {schedule.steps} steps: "
                f"foot {foot}'s {len(durations)} phases need at least {len(durations) * lo:g} s "
                f"at {lo:g} s each"
            )
            break
        if cfg.optimize_durations and len(durations) * hi < schedule.total_duration - 1e-9:
            out.append(
                f"duration {schedule.total_duration:g} s is too long for {schedule.steps} steps: "
                f"foot {foot}'s {len(durations)} phases last at most {len(durations) * hi:g} s "
                f"at {hi:g} s each"
            )
            break
        if not cfg.optimize_durations and min(durations) < _MIN_FIXED_PHASE:
            out.append(
                f"duration {schedule.total_duration:g} s is too short for {schedule.steps} steps: "
                f"foot {foot}'s shortest phase would last {min(durations):.3f} s "
                f"(at least {_MIN_FIXED_PHASE} s)"
            )
            break
    return out


def optimize_motion(
    robot: Any,
    terrain: Terrain | str,
    task: Any,
    *,
    config: TrajoptConfig | None = None,
    max_iter: int | None = None,
    time_limit_s: float | None = None,
    callback: Callable[[IterationInfo], bool | None] | None = None,
    warm_start: TrajoptResult | NDArray[np.float64] | None = None,
    **overrides: Any,
) -> TrajoptResult:
    """Optimise a motion of ``robot`` over ``terrain`` for ``task`` (Melon 2020, §III).

    Parameters
    ----------
    robot:
        A :class:`~roughwalk.robots.Robot` or its name; may be None with
        ``body_model="towr_anymal"``.
    terrain:
        A :class:`~roughwalk.terrain.Terrain` or a terrain spec.
    task:
        A :class:`Task`, {"start": (x, y, yaw), "goal": (x, y, yaw)} or a
        (start, goal) pair, poses in [m], [m], [rad].
    config:
        The configuration (default :func:`melon_config`).
    max_iter, time_limit_s:
        Per-solve limits (default: the config's ``solver`` ones) [-, s].
    callback:
        Called at every iteration with an :class:`IterationInfo`; returning
        True stops the solve (status CANCELLED).
    warm_start:
        A previous result (or solution vector) of the same problem to start from.
    **overrides:
        Config fields to change: ``gait="trot"``, ``steps=14``,
        ``duration=3.5``, ``fixed_durations=True``, ``init="heuristic"``,
        nested ones with "__" (``costs__force__weight=0``).

    Returns
    -------
    TrajoptResult
        Its status says whether it solved; a malformed task (NaN, off the
        terrain, inside an obstacle, a duration too short for the steps) gives
        status INVALID_INPUT instead of an exception.

    """
    start = time.perf_counter()
    cfg = _configure(config, overrides)
    if isinstance(robot, str):
        from roughwalk.robots import load_robot

        robot = load_robot(robot)
    robot_name = getattr(robot, "name", None) if robot is not None else cfg.body_model
    terrain_obj = load_terrain(terrain) if isinstance(terrain, str) else terrain
    the_task = Task.from_any(task)
    body = rigid_body_model(cfg.body_model, robot)
    problems = the_task.problems()
    if problems:
        return _invalid(
            the_task,
            cfg,
            "; ".join(problems),
            robot_name,
            terrain_obj.spec,
            time.perf_counter() - start,
        )
    terrain_model, _ = _cached(
        _terrains,
        (_terrain_key(terrain_obj), cfg.terrain, cfg.costs.step_edge_sigma),
        lambda: TerrainModel(terrain_obj, cfg.terrain, cfg.costs.step_edge_sigma),
    )
    initializer = make_initializer(cfg.init)
    schedule = initializer.schedule(make_gait(cfg.gait, cfg.steps, cfg.duration))
    # A learned guess belongs to the constraint set its model was trained on.
    choose = getattr(initializer, "constraints", None)
    if callable(choose):
        signature = {
            "robot": body.name,
            "terrain": terrain_model.name,
            "gait": schedule.name,
            "steps": schedule.steps,
            "duration": float(schedule.total_duration),
            "optimize_durations": bool(cfg.optimize_durations),
            "swing_base_clearance": cfg.swing_base_clearance,
        }
        chosen = tuple(choose(tuple(cfg.constraints), signature))
        if chosen != tuple(cfg.constraints):
            cfg = replace(cfg, constraints=chosen)
        # ... and to the cost weights it was trained with (weights the caller set win).
        weigh = getattr(initializer, "costs", None)
        if callable(weigh):
            weights = weigh(cfg.costs, signature)
            if weights != cfg.costs:
                cfg = replace(cfg, costs=weights)
                terrain_model, _ = _cached(
                    _terrains,
                    (_terrain_key(terrain_obj), cfg.terrain, cfg.costs.step_edge_sigma),
                    lambda: TerrainModel(terrain_obj, cfg.terrain, cfg.costs.step_edge_sigma),
                )
    problems = _schedule_problems(schedule, cfg)
    problems += task_problems(
        body, terrain_model, the_task, tuple(cfg.constraints), cfg.solver.constr_viol_tol
    )
    if problems:
        return _invalid(
            the_task,
            cfg,
            "; ".join(problems),
            robot_name,
            terrain_obj.spec,
            time.perf_counter() - start,
        )
    key = (
        body,
        _terrain_key(terrain_obj),
        schedule.durations,
        schedule.in_contact_at_start,
        schedule.name,
        cfg.structure_key(),
        cfg.compiled,
    )
    problem, _ = _cached(_problems, key, lambda: TrajoptProblem(body, terrain_model, schedule, cfg))
    elapsed = (
        time.perf_counter() - start - (problem.build_time_s if problem._build_pending else 0.0)
    )
    result = problem.solve(
        the_task,
        initializer,
        max_iter=max_iter if max_iter is not None else cfg.solver.max_iter,
        time_limit_s=time_limit_s if time_limit_s is not None else cfg.solver.time_limit_s,
        callback=callback,
        warm_start=warm_start,
        extra_time_s=max(elapsed, 0.0),
    )
    result.config = to_dict(cfg)
    result.robot = robot_name
    result.terrain = terrain_obj.spec
    return result
