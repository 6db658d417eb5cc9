"""Solves: Melon et al.'s three tasks, dynamics against a forward simulation, bad tasks, guesses."""

from __future__ import annotations

import ctypes
import dataclasses
import json
import os
import time
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TrajoptResult,
    TrajoptStatus,
    melon_config,
    optimize_motion,
    towr_config,
)
from roughwalk.trajopt.optimize import TrajoptProblem
from roughwalk.trajopt.parameters import SolverOptions, TrajoptConfig
from roughwalk.trajopt.solver import _single_threaded_blas
from roughwalk.trajopt.task import Task
from roughwalk.trajopt.terrain_model import TerrainModel
from roughwalk.trajopt.variables import euler_to_rotation

GRAVITY = np.array([0.0, 0.0, -9.80665])

# Melon 2020, §V: flat ground 1.5 m in 3.5 s trotting (14 steps); a single
# pallet (edge at x = 1 m) from 0.5–1.5 m before its edge to (1.6, 0) on top,
# and a double pallet to (1.8, 0) on its upper level, walking 16 steps in 5.5 s.
MELON_TASKS = {
    "flat": (
        "flat",
        ((0.0, 0.0, 0.0), (1.5, 0.0, 0.0)),
        {"gait": "trot", "steps": 14, "duration": 3.5},
    ),
    "single_pallet": (
        "single_pallet",
        ((-0.3, 0.15, 0.2), (1.6, 0.0, 0.0)),
        {"gait": "walk", "steps": 16, "duration": 5.5},
    ),
    "double_pallet": (
        "double_pallet",
        ((0.0, 0.0, 0.0), (1.8, 0.0, 0.0)),
        {"gait": "walk", "steps": 16, "duration": 5.5},
    ),
}


@pytest.fixture(scope="module")
def melon() -> dict[str, TrajoptResult]:
    """Each of Melon et al.'s tasks solved once, with TOWR's ANYmal (the robot they used)."""
    out = {}
    for name, (terrain, task, options) in MELON_TASKS.items():
        out[name] = optimize_motion(None, terrain, task, body_model="towr_anymal", **options)
    return out


@pytest.mark.parametrize("name", list(MELON_TASKS))
def test_melon_tasks_solve(melon: dict[str, TrajoptResult], name: str) -> None:
    result = melon[name]
    assert result.status in (TrajoptStatus.EXACT, TrajoptStatus.APPROXIMATE), result.message
    assert result.solved
    assert result.max_violation < 1e-3
    assert 0 < result.objective < 20
    # Start and goal are where the task says, at rest.
    start, goal = MELON_TASKS[name][1]
    s = result.sample(50.0)
    np.testing.assert_allclose(s["com_position"][0, :2], start[:2], atol=1e-6)
    np.testing.assert_allclose(s["com_position"][-1, :2], goal[:2], atol=1e-4)
    np.testing.assert_allclose(s["base_euler"][-1, 2], goal[2], atol=1e-4)
    np.testing.assert_allclose(s["base_linear_velocity"][[0, -1]], 0.0, atol=1e-4)
    # Forces vanish in swing, never exceed f_max, and carry the weight on average.
    assert result.body is not None
    forces = s["forces"]
    assert np.abs(forces[~s["contact"]]).max(initial=0.0) < 1e-9
    assert result.max_force_n <= result.body.force_limit + 1e-3
    mean_total = forces[:, :, 2].sum(axis=1).mean()
    assert mean_total == pytest.approx(result.body.weight, rel=0.1)


def test_feet_stand_on_the_terrain_and_step_over_it(melon: dict[str, TrajoptResult]) -> None:
    for name, result in melon.items():
        terrain = TerrainModel(load_terrain(MELON_TASKS[name][0]))
        s = result.sample(100.0)
        feet = s["feet_position"]
        for foot in range(4):
            h = terrain.height(feet[:, foot, :2])
            stance = s["contact"][:, foot]
            np.testing.assert_allclose(feet[stance, foot, 2], h[stance], atol=2e-3, err_msg=name)
            # Each swing's apex (its middle node) clears both footholds by the
            # swing clearance (Melon's swing-height constraint).
            assert result.schedule is not None
            bounds = result.schedule.phase_times(foot)
            clearance = result.config["swing_clearance"]
            for k in range(1, len(bounds) - 2):
                if result.schedule.is_stance(foot, k):
                    continue
                z = result.sample(
                    times=[bounds[k], 0.5 * (bounds[k] + bounds[k + 1]), bounds[k + 1]]
                )
                before, apex, after = z["feet_position"][:, foot, 2]
                assert apex >= max(before, after) + clearance - 1e-4, (name, foot, k)
    on_top = melon["double_pallet"].sample(10.0)["com_position"][-1, 2]
    assert on_top > 0.31 + 0.3  # the base ends standing on the upper pallet


def test_step_edge_cost_keeps_footholds_off_the_edge() -> None:
    # Melon's Gaussian step-edge cost: the same climb without it puts footholds
    # nearer the pallet's edge than with it.
    task = ((0.0, 0.0, 0.0), (1.6, 0.0, 0.0))
    options = {"body_model": "towr_anymal", "gait": "walk", "steps": 16, "duration": 5.5}
    terrain = TerrainModel(load_terrain("single_pallet"))

    def edge_cost(result: TrajoptResult) -> float:
        s = result.sample(20.0)
        held = s["feet_position"][s["contact"]]
        return float(terrain.edge_cost(held[:, :2]).sum())

    with_cost = optimize_motion(None, "single_pallet", task, **options)
    without = optimize_motion(None, "single_pallet", task, costs__step_edge=0.0, **options)
    assert with_cost.solved and without.solved
    assert "step_edge" in with_cost.costs and "step_edge" not in without.costs
    assert edge_cost(with_cost) < 0.5 * edge_cost(without)


def test_dynamics_match_a_forward_simulation(melon: dict[str, TrajoptResult]) -> None:
    # Integrate m c̈ = Σf + m g and d/dt(I_w ω) = Σ (p − c) × f with the optimised
    # forces and footholds (scipy, written here independently of the NLP),
    # from the plan's state at every dynamics sample over one sample interval
    # (0.1 s: TOWR enforces the dynamics only at these samples). The plan must
    # match; forces 10 % too strong must not.
    result = melon["single_pallet"]
    assert result.body is not None
    mass, inertia = result.body.mass, result.body.inertia_matrix

    def skew(w: np.ndarray) -> np.ndarray:
        return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])

    def state(t: float) -> np.ndarray:
        s = result.sample(times=[t])
        rot = euler_to_rotation(s["base_euler"][0])
        return np.concatenate(
            [
                s["com_position"][0],
                s["base_linear_velocity"][0],
                rot.ravel(),
                s["base_angular_velocity"][0],
            ]
        )

    def errors(scale: float) -> tuple[float, float]:
        splines = result.splines
        assert splines is not None

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            c, v, rot, w = y[:3], y[3:6], y[6:15].reshape(3, 3), y[15:]
            f = scale * np.array([s.evaluate([t])[0][0] for s in splines.forces])
            p = np.array([s.evaluate([t])[0][0] for s in splines.feet])
            i_world = rot @ inertia @ rot.T
            w_dot = np.linalg.solve(i_world, np.cross(p - c, f).sum(0) - np.cross(w, i_world @ w))
            return np.concatenate([v, f.sum(0) / mass + GRAVITY, (skew(w) @ rot).ravel(), w_dot])

        pos, ang = [], []
        for t0 in np.arange(0.0, result.duration - 0.05, 0.1):
            sol = solve_ivp(rhs, (t0, t0 + 0.1), state(t0), rtol=1e-8, atol=1e-10, max_step=0.01)
            ref = state(t0 + 0.1)
            pos.append(np.abs(sol.y[:3, -1] - ref[:3]).max())
            ang.append(np.abs(sol.y[6:15, -1] - ref[6:15]).max())
        return float(np.median(pos)), float(np.median(ang))

    pos, ang = errors(1.0)
    assert pos < 3e-3  # [m] after 0.1 s
    assert ang < 0.01  # rotation matrix entries after 0.1 s
    wrong_pos, _ = errors(1.2)
    assert wrong_pos > 3 * pos


def test_result_json_and_npz(melon: dict[str, TrajoptResult], tmp_path: Path) -> None:
    result = melon["flat"]
    data = json.loads(json.dumps(result.to_dict(rate_hz=20.0)))
    for key in (
        "status",
        "solved",
        "iterations",
        "solve_time_s",
        "objective",
        "max_violation",
        "max_force_n",
        "n_variables",
        "nodes",
        "trajectory",
        "phase_durations",
    ):
        assert key in data
    assert data["solved"] is True
    assert len(data["trajectory"]["t"]) == 71  # 3.5 s at 20 Hz, both ends
    assert np.asarray(data["trajectory"]["feet_position"]).shape == (71, 4, 3)
    out = result.to_dict(rate_hz=50.0, npz=tmp_path / "motion.npz")
    assert "trajectory" not in out
    with np.load(out["trajectory_npz"]) as arrays:
        np.testing.assert_allclose(arrays["t"][-1], 3.5)
        np.testing.assert_allclose(np.linalg.norm(arrays["base_quat"], axis=1), 1.0)


def test_towr_feasibility_problem_reuses_its_build_and_warm_starts() -> None:
    config = towr_config()
    task = ((0.0, 0.0, 0.0), (1.5, 0.0, 0.0))
    first = optimize_motion(None, "flat", task, config=config, gait="walk", steps=16, duration=3.4)
    assert first.solved and first.objective == 0.0 and first.n_variables == 848
    assert first.build_time_s > 0
    second = optimize_motion(
        None,
        "flat",
        ((0.0, 0.0, 0.0), (1.2, 0.2, 0.3)),
        config=config,
        gait="walk",
        steps=16,
        duration=3.4,
    )
    assert second.solved and second.build_time_s == 0.0
    again = optimize_motion(
        None, "flat", task, config=config, gait="walk", steps=16, duration=3.4, warm_start=first
    )
    assert again.solved and again.iterations <= 2


def test_towr_block_solves_unscaled_in_fewer_iterations_than_scaled() -> None:
    # TOWR's block, goal 1.5 m (T = 3.5 s, walk): 106 iterations with IPOPT's
    # gradient-based NLP scaling (and no other option), 41 without, 33 with
    # towr_config's options, and the unscaled rows still meet constr_viol_tol.
    from dataclasses import replace

    config = towr_config()
    assert "nlp_scaling_method=none" in config.solver.ipopt_options
    scaled = replace(
        config,
        solver=replace(config.solver, ipopt_options=(), fixed_durations_ipopt_options=()),
    )
    task = ((0.0, 0.0, 0.0), (1.5, 0.0, 0.0))
    kwargs = {"gait": "walk", "steps": 16, "duration": 3.5}
    unscaled_result = optimize_motion(None, "towr_block", task, config=config, **kwargs)
    scaled_result = optimize_motion(None, "towr_block", task, config=scaled, **kwargs)
    assert unscaled_result.solved and scaled_result.solved
    assert unscaled_result.max_violation <= config.solver.constr_viol_tol
    assert unscaled_result.iterations < 0.6 * scaled_result.iterations


def test_towr_gap_trot_never_falls_back_to_the_monotone_barrier() -> None:
    # TOWR's gap trot, goal 2.5 m (fixed durations): 183 iterations when
    # IPOPT's adaptive barrier update may fall back to its monotone mode, 33
    # when it never does (towr_config's default with fixed durations only).
    from dataclasses import replace

    from roughwalk.trajopt.optimize import solver_options_for

    option = "adaptive_mu_globalization=never-monotone-mode"
    config = towr_config()
    assert option in solver_options_for(config).ipopt_options
    # Optimised durations drop it, however the config came to optimise them
    # (a preset changed afterwards, as `--set optimize_durations=true` does).
    for optimised in (
        towr_config(optimize_durations=True),
        replace(config, optimize_durations=True),
    ):
        assert option not in solver_options_for(optimised).ipopt_options
    task = ((0.0, 0.0, 0.0), (2.5, 0.0, 0.0))
    result = optimize_motion(
        None, "towr_gap", task, config=config, gait="trot", steps=16, duration=3.5
    )
    assert result.solved and result.max_violation <= config.solver.constr_viol_tol
    assert result.iterations <= 60


def test_towr_block_goal_with_hind_feet_at_the_edge_solves() -> None:
    # Goal 0.95 m: the level goal base needs the hind feet up on the block
    # (edge at 0.7 m, hind reach 0.61 + 0.15 m). From the nominal goal stance
    # (hind feet on the ground, 0.5 m below the front ones) IPOPT hit its
    # 40 s limit after ~1500 iterations; from a level goal stance it takes 47.
    from dataclasses import replace

    config = towr_config()
    task = ((0.0, 0.0, 0.0), (0.95, 0.0, 0.0))
    kwargs = {"gait": "walk", "steps": 16, "duration": 3.5}
    guess_only = replace(config, solver=replace(config.solver, max_iter=0))
    guess = optimize_motion(None, "towr_block", task, config=guess_only, **kwargs)
    assert guess.splines is not None
    goal_heights = [float(foot.positions[-1, 2]) for foot in guess.splines.feet]
    assert max(goal_heights) - min(goal_heights) <= 0.2  # 2·Δz of TOWR's ANYmal
    limited = replace(config, solver=replace(config.solver, max_iter=150))
    result = optimize_motion(None, "towr_block", task, config=limited, **kwargs)
    assert result.solved, result.status
    assert result.max_violation <= config.solver.constr_viol_tol


class _GuessWithMultipliers:
    """An initialiser handing over a given guess and multipliers (as the learned one does)."""

    name = "given"

    def __init__(self, result: TrajoptResult) -> None:
        self.result = result

    def schedule(self, gait: object) -> object:
        return gait

    def adjust_task(self, task: object) -> object:
        return task

    def guess(self, nlp: object, task: object) -> np.ndarray:
        return np.asarray(self.result.x)

    def multipliers(self, nlp: object, task: object) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.result.lam_x), np.asarray(self.result.lam_g)


def test_warm_and_guess_options_reach_only_their_own_solves() -> None:
    # An option IPOPT refuses, given to one set only, shows which solves use it:
    # the cold solve (no multipliers) uses neither set.
    from dataclasses import replace

    from roughwalk.trajopt.optimize import clear_cache

    base = towr_config()
    task = ((0.0, 0.0, 0.0), (1.5, 0.0, 0.0))
    kwargs = {"gait": "walk", "steps": 16, "duration": 3.4}
    clear_cache()
    broken = "no_such_ipopt_option=1"
    warm_broken = replace(base, solver=replace(base.solver, warm_ipopt_options=(broken,)))
    first = optimize_motion(None, "flat", task, config=warm_broken, **kwargs)
    assert first.solved
    with pytest.raises(RuntimeError, match="no_such_ipopt_option"):
        optimize_motion(None, "flat", task, config=warm_broken, warm_start=first, **kwargs)
    guess_broken = replace(base, solver=replace(base.solver, guess_ipopt_options=(broken,)))
    again = optimize_motion(None, "flat", task, config=guess_broken, warm_start=first, **kwargs)
    assert again.solved and again.iterations <= 2
    with pytest.raises(RuntimeError, match="no_such_ipopt_option"):
        _problem(guess_broken).solve(Task.from_any(task), _GuessWithMultipliers(first))
    # With the default options a guess with multipliers (here a solution's) converges.
    optimize_motion(None, "flat", task, config=base, **kwargs)
    from_guess = _problem(base).solve(Task.from_any(task), _GuessWithMultipliers(first))
    assert from_guess.solved and from_guess.iterations < first.iterations
    clear_cache()


def _problem(config: TrajoptConfig) -> TrajoptProblem:
    """The cached problem built for ``config``."""
    from roughwalk.trajopt import optimize

    return next(p for p in optimize._problems.values() if p.config.solver == config.solver)


def test_optimised_durations_stay_in_bounds_and_sum_to_the_duration() -> None:
    result = optimize_motion(
        None,
        "flat",
        ((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)),
        config=towr_config(optimize_durations=True),
        gait="walk",
        steps=8,
        duration=3.0,
    )
    assert result.solved, result.message
    assert result.schedule is not None
    for durations in result.schedule.durations:
        assert sum(durations) == pytest.approx(3.0)
        assert min(durations[:-1]) >= 0.2 - 1e-6 and max(durations[:-1]) <= 1.0 + 1e-6


SMALL = {"config": towr_config(), "gait": "walk", "steps": 4, "duration": 2.0}


@pytest.mark.parametrize(
    ("terrain", "task", "options", "match"),
    [
        ("flat", ((float("nan"), 0.0, 0.0), (1.0, 0.0, 0.0)), {}, "not finite"),
        ("flat", ((0.0, 0.0, 0.0), (1.0, float("inf"), 0.0)), {}, "not finite"),
        ("towr_block:height=1.0", ((0.0, 0.0, 0.0), (0.7, 0.0, 0.0)), {}, "inside an obstacle"),
        # Hind feet reach x ≤ 0.71 m (0.2 m up the edge), front feet 0.5 m up: no level goal.
        ("towr_block", ((0.0, 0.0, 0.0), (0.9, 0.0, 0.0)), {}, "no level base"),
        ("flat", ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), {"duration": 0.2}, "too short"),
        (
            "flat",
            ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
            {"duration": 0.5, "config": towr_config(optimize_durations=True)},
            "too short",
        ),
        (
            "flat",
            ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
            {"duration": 9.0, "config": towr_config(optimize_durations=True)},
            "too long",
        ),
        # Held-out single-pallet task 189: the start's left front foot stands 0.161 m up
        # the pallet's smoothed edge, beyond its range of motion under a level base.
        (
            "single_pallet",
            ((0.49522, 0.317274, -0.387406), (1.6, 0.0, 0.0)),
            {"robot": "anymal_c", "config": melon_config()},
            "LF foot of its stance is 0.121 m from its nominal position along z",
        ),
    ],
)
def test_bad_tasks_get_a_clear_status(terrain: str, task: tuple, options: dict, match: str) -> None:
    rest = {k: v for k, v in options.items() if k != "robot"}
    result = optimize_motion(options.get("robot"), terrain, task, **{**SMALL, **rest})
    assert result.status is TrajoptStatus.INVALID_INPUT
    assert not result.solved
    assert match in result.message
    assert json.dumps(result.to_dict(), allow_nan=False)


def test_the_start_reach_check_accepts_what_the_solver_accepts() -> None:
    # Task 189's LF foot is 0.019 m beyond its range of motion: refused at the default
    # constraint tolerance (1e-4 m), tried once the solver itself accepts 0.05 m.
    task = ((0.49522, 0.317274, -0.387406), (1.6, 0.0, 0.0))
    cfg = melon_config()
    loose = dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, constr_viol_tol=0.05))
    refused = optimize_motion("anymal_c", "single_pallet", task, config=cfg, max_iter=0)
    tried = optimize_motion("anymal_c", "single_pallet", task, config=loose, max_iter=0)
    assert refused.status is TrajoptStatus.INVALID_INPUT
    assert tried.status is not TrajoptStatus.INVALID_INPUT, tried.message


def test_limits_and_callback_stop_with_their_status() -> None:
    task = ((0.0, 0.0, 0.0), (0.6, 0.0, 0.0))
    limited = optimize_motion(None, "flat", task, max_iter=2, **SMALL)
    assert limited.status is TrajoptStatus.ITERATION_LIMIT and limited.iterations == 2
    assert limited.sample(10.0)["t"].size == 21  # the last iterate can still be looked at
    seen: list[int] = []
    cancelled = optimize_motion(
        None, "flat", task, callback=lambda i: seen.append(i.iteration) or i.iteration >= 1, **SMALL
    )
    assert cancelled.status is TrajoptStatus.CANCELLED and seen == [0, 1]
    timed = optimize_motion(None, "flat", task, time_limit_s=1e-9, **SMALL)
    assert timed.status is TrajoptStatus.TIMEOUT
    # A far goal in a short time cannot be reached: IPOPT says so, no exception.
    hopeless = optimize_motion(
        None, "flat", ((0.0, 0.0, 0.0), (8.0, 0.0, 0.0)), max_iter=60, **SMALL
    )
    assert not hopeless.solved and hopeless.max_violation > 1e-3
    with pytest.raises(InvalidArgumentError, match="walk gait cannot make 5 steps"):
        optimize_motion(None, "flat", task, **{**SMALL, "steps": 5})


def test_a_cached_solver_honours_each_solves_own_iteration_limit() -> None:
    # The NLP (and its IPOPT) is cached per structure, which excludes the limits: a
    # problem first solved with a limit of 1 must still run a later solve to its own.
    task = ((0.0, 0.0, 0.0), (0.6, 0.0, 0.0))
    first = optimize_motion(None, "flat", task, **{**SMALL, "solver__max_iter": 1})
    assert first.status is TrajoptStatus.ITERATION_LIMIT and first.iterations == 1
    later = optimize_motion(None, "flat", task, **{**SMALL, "solver__max_iter": 6})
    assert later.status is TrajoptStatus.ITERATION_LIMIT and later.iterations == 6


def test_footsteps_guess_from_a_plan(tmp_path: Path) -> None:
    # A hand-made plan in `roughwalk plan`'s format: start stance, then a crawl,
    # each leg 0.15 m forward.
    start = {"LF": (0.34, 0.19), "RF": (0.34, -0.19), "LH": (-0.34, 0.19), "RH": (-0.34, -0.19)}
    steps = [{"leg": leg, "x": x, "y": y, "z": 0.0} for leg, (x, y) in start.items()]
    for leg in ("RH", "RF", "LH", "LF"):
        x, y = start[leg]
        steps.append({"leg": leg, "x": x + 0.15, "y": y, "z": 0.0})
    plan = tmp_path / "plan.json"
    plan.write_text(json.dumps({"schema": "footstep_plan", "footsteps": steps}))
    result = optimize_motion(
        None,
        "flat",
        ((0.0, 0.0, 0.0), (0.15, 0.0, 0.0)),
        config=towr_config(),
        init=f"footsteps:{plan}",
        duration=2.4,
    )
    assert result.solved, result.message
    assert result.schedule is not None and result.schedule.name == "footsteps"
    assert result.schedule.steps == 4
    # One foot at a time: never fewer than three in stance.
    assert result.sample(50.0)["contact"].sum(axis=1).min() == 3
    with pytest.raises(InvalidArgumentError, match="initial stance"):
        plan.write_text(json.dumps({"footsteps": steps[1:]}))
        optimize_motion(
            None,
            "flat",
            ((0.0, 0.0, 0.0), (0.15, 0.0, 0.0)),
            config=towr_config(),
            init=f"footsteps:{plan}",
            duration=2.4,
        )


def test_mumps_runs_on_one_blas_thread_and_orderings_are_checked() -> None:
    library = Path(ca.__file__).resolve().parent / "libcasadi-tp-openblas.so.0"
    if not library.exists() or "OPENBLAS_NUM_THREADS" in os.environ:
        pytest.skip("CasADi without its own OpenBLAS, or the user chose the thread count")
    assert _single_threaded_blas()
    assert ctypes.CDLL(str(library)).openblas_get_num_threads() == 1
    with pytest.raises(ConfigError, match="mumps_pivot_order must be None, 0, 2, 4, 5, 6 or 7"):
        SolverOptions(mumps_pivot_order=3)
    # The ordering is IPOPT's: an explicit one solves the same problem.
    result = optimize_motion(
        None,
        "flat",
        ((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)),
        config=towr_config(optimize_durations=True),
        gait="walk",
        steps=8,
        duration=3.0,
        solver__mumps_pivot_order=0,
    )
    assert result.solved, result.message


def _ipopt_user_options(tmp_path: Path, name: str, **overrides: object) -> dict[str, str]:
    """The options IPOPT itself reports as set by the user, for one short solve."""
    log = tmp_path / f"{name}.txt"
    optimize_motion(
        None,
        "flat",
        ((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)),
        config=towr_config(),
        gait="walk",
        steps=8,
        duration=3.0,
        max_iter=1,
        solver__ipopt_options=(
            f"output_file={log}",
            "file_print_level=5",
            "print_user_options=yes",
        ),
        **overrides,
    )
    options = {}
    for line in log.read_text().splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[1] == "=" and parts[3] in ("yes", "no"):
            options[parts[0]] = parts[2]
    return options


def test_mumps_scaling_follows_the_hessian_unless_set(tmp_path: Path) -> None:
    exact = _ipopt_user_options(tmp_path, "exact", solver__hessian="exact")
    assert exact["hessian_approximation"] == "exact"
    assert exact["mumps_scaling"] == "0" and exact["mumps_permuting_scaling"] == "0"
    lbfgs = _ipopt_user_options(tmp_path, "lbfgs", solver__hessian="limited-memory")
    assert lbfgs["hessian_approximation"] == "limited-memory"
    assert "mumps_scaling" not in lbfgs and "mumps_permuting_scaling" not in lbfgs
    forced = _ipopt_user_options(
        tmp_path, "forced", solver__hessian="limited-memory", solver__mumps_scaling=False
    )
    assert forced["mumps_scaling"] == "0"
    kept = _ipopt_user_options(
        tmp_path, "kept", solver__hessian="exact", solver__mumps_scaling=True
    )
    assert "mumps_scaling" not in kept


def test_guess_solves_order_with_amd_only_with_the_exact_hessian(tmp_path: Path) -> None:
    # A solve from predicted multipliers (the learned guess) builds its own IPOPT.
    from dataclasses import replace

    from roughwalk.trajopt.optimize import clear_cache

    orders = {}
    for hessian in ("exact", "limited-memory"):
        clear_cache()
        log = tmp_path / f"{hessian}.txt"
        base = towr_config()
        config = replace(
            base,
            solver=replace(
                base.solver,
                hessian=hessian,
                ipopt_options=(f"output_file={log}", "file_print_level=5"),
                guess_ipopt_options=(*base.solver.guess_ipopt_options, "print_user_options=yes"),
            ),
        )
        task = ((0.0, 0.0, 0.0), (0.8, 0.0, 0.0))
        kwargs = {"gait": "walk", "steps": 8, "duration": 3.0, "max_iter": 1}
        first = optimize_motion(None, "flat", task, config=config, **kwargs)
        _problem(config).solve(Task.from_any(task), _GuessWithMultipliers(first), max_iter=1)
        for line in log.read_text().splitlines():
            parts = line.split()
            if len(parts) == 4 and parts[0] == "mumps_pivot_order" and parts[1] == "=":
                orders[hessian] = parts[2]
    clear_cache()
    # AMD: the same iterations for less CPU; with L-BFGS it changed the iterations.
    assert orders == {"exact": "0", "limited-memory": "7"}


def test_mumps_ordering_follows_durations_and_hessian(tmp_path: Path) -> None:
    fixed = _ipopt_user_options(tmp_path, "fixed", solver__hessian="exact")
    assert fixed["mumps_pivot_order"] == "0"
    automatic = _ipopt_user_options(tmp_path, "auto", solver__hessian="limited-memory")
    assert automatic["mumps_pivot_order"] == "7"
    metis = _ipopt_user_options(
        tmp_path, "metis", solver__hessian="limited-memory", optimize_durations=True
    )
    assert metis["mumps_pivot_order"] == "5"
    amd = _ipopt_user_options(tmp_path, "amd", solver__hessian="exact", optimize_durations=True)
    assert amd["mumps_pivot_order"] == "0"


def test_making_the_guess_counts_in_the_solve_time(monkeypatch: pytest.MonkeyPatch) -> None:
    # solve_time_s runs from the task to the solution: a slow guess is part of it.
    from roughwalk.trajopt.initializers import HeuristicInitializer

    config = towr_config()
    task = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
    kwargs = {"config": config, "gait": "trot", "steps": 4, "duration": 1.0, "max_iter": 1}
    optimize_motion(None, "flat", task, **kwargs)  # built: later solves reuse the structure
    quick = optimize_motion(None, "flat", task, **kwargs)
    guess = HeuristicInitializer.guess

    def slow_guess(self: HeuristicInitializer, *args: object) -> np.ndarray:
        time.sleep(0.5)
        return guess(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(HeuristicInitializer, "guess", slow_guess)
    slow = optimize_motion(None, "flat", task, **kwargs)
    assert quick.build_time_s == slow.build_time_s == 0.0
    assert slow.solve_time_s >= quick.solve_time_s + 0.45
