"""``learned_fixed_durations``: a fixed-duration model's guess in the optimised-duration NLP."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _benchmarks import load_benchmark
from _learned_models import SPEC, heuristic_guess_model

from roughwalk.errors import ConfigError
from roughwalk.learning import (
    FixedDurationsInitializer,
    LearnedInitializer,
    ProblemSpec,
    build_problem,
)
from roughwalk.learning.fixed_durations_initializer import (
    DURATION_ROWS,
    NAME,
    fixed_durations_model,
    gait_durations,
    to_optimised_rows,
    to_optimised_variables,
)
from roughwalk.learning.initializer import model_for_spec
from roughwalk.learning.model_file import problem_signature
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    TerrainModel,
    TrajoptProblem,
    make_gait,
    melon_config,
    optimize_motion,
)
from roughwalk.trajopt.solver import violation
from roughwalk.trajopt.task import Task, resolve

STEPS, DURATION = SPEC.steps, SPEC.duration  # the tiny test model's walk: 4 steps in 2 s
TASK = Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
WIDE = (0.1, 2.0)
"""Phase bounds [s] that hold every phase of the walk (the default's 1.0 s does not)."""


@pytest.fixture(scope="module")
def flat() -> TerrainModel:
    return TerrainModel(load_terrain("flat"))


def _problem(
    flat: TerrainModel, optimize: bool, bounds: tuple[float, float], admit_gait: bool = True
) -> TrajoptProblem:
    config = melon_config(
        steps=STEPS,
        duration=DURATION,
        optimize_durations=optimize,
        phase_duration_bounds=bounds,
        phase_bounds_admit_gait=admit_gait,
    )
    return TrajoptProblem(TOWR_ANYMAL, flat, make_gait("walk", STEPS, DURATION), config)


def _violation(nlp: Formulation, x: np.ndarray, p: np.ndarray) -> float:
    g = np.asarray(nlp.evaluator(x, p)[1]).ravel()
    return float(violation(g, nlp.lbg, nlp.ubg).max(initial=0.0))


@pytest.fixture(scope="module")
def solved(flat: TerrainModel) -> tuple[TrajoptProblem, TrajoptProblem, object]:
    """The fixed and the optimised-duration NLPs (wide bounds) and a converged fixed solve."""
    fixed, optimised = _problem(flat, False, WIDE), _problem(flat, True, WIDE)
    result = fixed.solve(TASK, HeuristicInitializer())
    assert result.status.solved
    return fixed, optimised, result


def test_a_fixed_solution_mapped_meets_the_optimised_nlp_as_it_met_the_fixed_one(
    solved: tuple[TrajoptProblem, TrajoptProblem, object],
) -> None:
    fixed, optimised, result = solved
    x = result.x  # type: ignore[attr-defined]
    p = resolve(TASK, TOWR_ANYMAL, fixed.terrain).vector()
    met = _violation(fixed.formulation, x, p)
    mapped = to_optimised_variables(optimised.formulation, x)
    assert mapped.size == optimised.formulation.n_variables > x.size
    assert _violation(optimised.formulation, mapped, p) <= max(met, 1e-9) * 1.0001
    # The same objective too: every spline is the one the fixed NLP solved.
    f_fixed = float(fixed.formulation.evaluator(x, p)[0])
    assert float(optimised.formulation.evaluator(mapped, p)[0]) == pytest.approx(f_fixed, 1e-9)
    # The durations are the gait's own, not the optimised NLP's (fitted) start.
    gait = make_gait("walk", STEPS, DURATION)
    parts = optimised.formulation.split(mapped)
    for d, own in zip(optimised.formulation.durations, gait.durations, strict=True):
        np.testing.assert_allclose(parts[d.name], own[:-1])


def test_the_multipliers_fill_their_own_rows_and_the_duration_rows_start_at_zero(
    solved: tuple[TrajoptProblem, TrajoptProblem, object],
) -> None:
    fixed, optimised, result = solved
    # What the mapping rests on: the fixed NLP's blocks are the optimised
    # one's without the duration rows, in the same order and sizes.
    rows = [b for b in optimised.formulation.row_layout if b[0] not in DURATION_ROWS]
    assert fixed.formulation.row_layout == rows
    lam_g = np.asarray(result.lam_g)  # type: ignore[attr-defined]
    mapped = to_optimised_rows(optimised.formulation, lam_g)
    assert mapped is not None and mapped.size == optimised.formulation.n_constraints
    ours, theirs = optimised.formulation.row_slices(), fixed.formulation.row_slices()
    for name, where in ours.items():
        expected = (
            np.zeros(where.stop - where.start) if name in DURATION_ROWS else lam_g[theirs[name]]
        )
        np.testing.assert_array_equal(mapped[where], expected)
    assert to_optimised_rows(optimised.formulation, lam_g[:-1]) is None  # rows that do not map


def test_an_out_of_bounds_phase_is_clamped_and_the_next_absorbs_it(
    flat: TerrainModel, solved: tuple[TrajoptProblem, TrajoptProblem, object]
) -> None:
    # Bounds that do not admit the gait (phase_bounds_admit_gait off, as in towr_config).
    nlp = _problem(flat, True, (0.2, 1.0), admit_gait=False).formulation
    gait = make_gait("walk", STEPS, DURATION)
    clamped = 0
    for d, timed, own in zip(nlp.durations, gait_durations(nlp), gait.durations, strict=True):
        assert timed.sum() == pytest.approx(DURATION)
        assert np.all((timed[:-1] >= 0.2 - 1e-12) & (timed[:-1] <= 1.0 + 1e-12))
        if np.any(np.asarray(own[:-1]) > 1.0):
            clamped += 1
            # The front-right foot's 1.24 s first stance: its swing starts
            # earlier, and every later phase boundary is the gait's.
            np.testing.assert_allclose(np.cumsum(timed)[1:], np.cumsum(own)[1:])
            assert d.nominal != list(timed)  # the NLP's own (fitted) start moves every node
        else:
            np.testing.assert_allclose(timed, own)
    assert clamped == 1
    # The fixed solution mapped so meets the rows better than at the NLP's own start.
    x = solved[2].x  # type: ignore[attr-defined]
    p = resolve(TASK, TOWR_ANYMAL, flat).vector()
    mapped = to_optimised_variables(nlp, x)
    parts = nlp.split(mapped)
    for d in nlp.durations:
        parts[d.name] = d.pack(d.nominal)
    at_start = _violation(nlp, nlp.join(parts), p)
    assert _violation(nlp, mapped, p) < 0.8 * at_start


def test_with_bounds_that_admit_the_gait_the_mapping_is_exact_at_towr_s_bounds(
    flat: TerrainModel, solved: tuple[TrajoptProblem, TrajoptProblem, object]
) -> None:
    # TOWR's 0.2–1.0 s clamps the walk's 1.24 s front-right stance; with
    # phase_bounds_admit_gait nothing is clamped, and the converged fixed
    # solve mapped meets the optimised rows and objective as it met the fixed
    # NLP's (as with bounds wide enough for every phase).
    fixed, _, result = solved
    config = melon_config(
        steps=STEPS,
        duration=DURATION,
        optimize_durations=True,
        phase_bounds_admit_gait=True,
    )
    admitted = TrajoptProblem(TOWR_ANYMAL, flat, make_gait("walk", STEPS, DURATION), config)
    nlp = admitted.formulation
    gait = make_gait("walk", STEPS, DURATION)
    for d, timed, own in zip(nlp.durations, gait_durations(nlp), gait.durations, strict=True):
        np.testing.assert_allclose(timed, own, atol=1e-12)
        assert d.bounds[0] == 0.2 and d.bounds[1] >= 1.0
    assert max(max(own[:-1]) for own in gait.durations) > 1.0  # something was clamped before
    x = result.x  # type: ignore[attr-defined]
    p = resolve(TASK, TOWR_ANYMAL, flat).vector()
    mapped = to_optimised_variables(nlp, x)
    assert np.all((nlp.lbx <= mapped) & (mapped <= nlp.ubx))
    met = _violation(fixed.formulation, x, p)
    assert _violation(nlp, mapped, p) <= max(met, 1e-9) * 1.0001
    f_fixed = float(fixed.formulation.evaluator(x, p)[0])
    assert float(nlp.evaluator(mapped, p)[0]) == pytest.approx(f_fixed, 1e-9)


def test_the_guess_through_optimize_motion_is_the_model_s_in_the_optimised_layout(
    tmp_path: Path, flat: TerrainModel
) -> None:
    model = heuristic_guess_model()
    model.save(tmp_path / "tiny.npz")
    config = melon_config(
        steps=STEPS, duration=DURATION, optimize_durations=True, phase_duration_bounds=WIDE
    )
    init = f"{NAME}:{tmp_path / 'tiny.npz'}"
    result = optimize_motion("anymal_c", "flat", TASK, config=config, init=init, max_iter=0)
    assert result.x is not None
    assert "guess from fixed-duration learned model 'tiny'" in result.message
    parts = _problem(flat, True, WIDE).formulation.split(result.x)
    kept = np.concatenate([v for n, v in parts.items() if not n.startswith("durations")])
    np.testing.assert_allclose(kept, model.predict(TASK), atol=1e-9)
    for foot, own in enumerate(make_gait("walk", STEPS, DURATION).durations):
        np.testing.assert_allclose(parts[f"durations_{foot}"], own[:-1])


def test_a_problem_whose_layout_does_not_map_is_refused(tmp_path: Path, flat: TerrainModel) -> None:
    heuristic_guess_model(constraints=list(melon_config().constraints)).save(tmp_path / "t.npz")
    path = str(tmp_path / "t.npz")
    signature = {**SPEC.to_dict(), "optimize_durations": True}
    assert fixed_durations_model(path, signature).name == "t"
    for key, value, named in (
        ("steps", 6, "steps"),
        ("terrain", "single_pallet", "terrain"),
        ("swing_base_clearance", 0.5, "swing_base_clearance"),
    ):
        with pytest.raises(ConfigError, match=named):
            fixed_durations_model(path, {**signature, key: value})
    # Another node count: the same sets, other sizes.
    nlp = _problem(flat, True, WIDE).formulation
    layout = problem_signature(nlp)["layout"]
    layout[0] = [layout[0][0], layout[0][1] + 6]
    with pytest.raises(ConfigError, match="layout differs in base_lin"):
        fixed_durations_model(path, {**signature, "layout": layout})
    # Another constraint set than the model's.
    config = melon_config(
        steps=STEPS,
        duration=DURATION,
        optimize_durations=True,
        constraints=("dynamics", "range_of_motion", "total_duration", "initial_state"),
    )
    body = build_problem(SPEC).body  # the model's robot
    other = Formulation(config, body, make_gait("walk", STEPS, DURATION), flat)
    task = resolve(TASK, body, flat)
    with pytest.raises(ConfigError, match="trained on constraints"):
        FixedDurationsInitializer(path).guess(other, task)


def test_a_model_trained_with_optimised_durations_is_refused() -> None:
    spec = ProblemSpec(
        terrain="single_pallet", optimize_durations=True, swing_base_clearance=0.5
    ).to_dict()
    with pytest.raises(ConfigError, match="trained with optimised ones"):
        fixed_durations_model("anymal_c_single_pallet_walk16_swing05_optdur", spec)


def test_the_shipped_fixed_duration_model_is_picked_and_named() -> None:
    for terrain, steps, duration, name in (
        ("single_pallet", 16, 5.5, "anymal_c_single_pallet_walk16_swing05"),
        ("double_pallet", 20, 6.875, "anymal_c_double_pallet_walk20_swing05"),
    ):
        spec = ProblemSpec(
            terrain=terrain,
            steps=steps,
            duration=duration,
            optimize_durations=True,
            swing_base_clearance=0.5,
        )
        assert model_for_spec(NAME, spec).name == name


def test_the_tracking_bench_runs_it_and_names_its_model() -> None:
    bench = load_benchmark("bench_tracking")
    init = bench.learned_init("double_pallet", True, None, name=NAME)
    assert bench.learned_model_for("double_pallet", True, init) == ""
    assert bench.learned_model_name("double_pallet", True, init) == (
        "anymal_c_double_pallet_walk20_swing05"
    )
    assert bench.learned_model_name("double_pallet", True, "heuristic") is None
    # No optimised-duration double-pallet model: every initialiser solves the
    # fixed-duration model's NLP (its set holds total_duration).
    assert bench.learned_model_for("double_pallet", True, "learned") != ""
    constraints, _ = bench.shared_problem("double_pallet", True, None)
    assert constraints is not None and "unilateral_between_nodes" in constraints
    assert "total_duration" in constraints


def test_with_fixed_durations_its_guess_is_learned_s_so_the_bench_runs_it_once(
    tmp_path: Path,
) -> None:
    model = heuristic_guess_model()
    model.save(tmp_path / "tiny.npz")
    fixed = build_problem(SPEC)  # the tiny model's own (fixed-duration) problem
    resolved = resolve(TASK, fixed.body, fixed.terrain)
    ours = FixedDurationsInitializer(str(tmp_path / "tiny.npz"))
    theirs = LearnedInitializer(str(tmp_path / "tiny.npz"))
    nlp = fixed.formulation
    np.testing.assert_array_equal(ours.guess(nlp, resolved), theirs.guess(nlp, resolved))
    bench = load_benchmark("bench_tracking")
    assert bench.not_run(NAME, False) != ""
    assert bench.not_run(f"{NAME}:{tmp_path / 'tiny.npz'}", False) != ""
    assert bench.not_run(NAME, True) == ""
    assert bench.not_run("learned", False) == bench.not_run("heuristic", False) == ""


def test_learned_without_an_optimised_duration_model_points_to_this_initialiser() -> None:
    bench = load_benchmark("bench_tracking")
    why = bench.learned_model_for("double_pallet", True, "learned")
    assert "no shipped learned model fits" in why
    assert "learned_fixed_durations" in why
    # With fixed durations a missing model is not pointed there (it would not help).
    low = (("swing_base_clearance", "0.4"),)
    assert "learned_fixed_durations" not in bench.learned_model_for(
        "single_pallet", False, "learned", low
    )


def test_constraints_appended_after_the_model_s_are_taken_with_zero_multipliers(
    tmp_path: Path, flat: TerrainModel, solved: tuple[TrajoptProblem, TrajoptProblem, object]
) -> None:
    _, optimised, result = solved
    base = optimised.formulation.config.constraints
    extra = "unilateral_between_nodes"
    assert extra not in base
    config = melon_config(
        steps=STEPS,
        duration=DURATION,
        optimize_durations=True,
        phase_duration_bounds=WIDE,
        constraints=(*base, extra),
    )
    nlp = TrajoptProblem(TOWR_ANYMAL, flat, make_gait("walk", STEPS, DURATION), config).formulation
    lam_g = np.asarray(result.lam_g)  # type: ignore[attr-defined]
    mapped = to_optimised_rows(nlp, lam_g)
    assert mapped is not None and mapped.size == nlp.n_constraints
    where = nlp.row_slices()[extra]
    assert where.stop == nlp.n_constraints and not mapped[where].any()
    np.testing.assert_array_equal(
        mapped[: where.start], to_optimised_rows(optimised.formulation, lam_g)
    )
    # The initialiser takes such a problem, as learned does ...
    model = heuristic_guess_model(constraints=[n for n in base if n not in DURATION_ROWS])
    model.save(tmp_path / "tiny.npz")
    init = f"{NAME}:{tmp_path / 'tiny.npz'}"
    solve = optimize_motion("anymal_c", "flat", TASK, config=config, init=init, max_iter=0)
    assert solve.x is not None and extra in solve.config["constraints"]
    # ... but not one that changed the model's own set.
    dropped = melon_config(
        steps=STEPS, duration=DURATION, optimize_durations=True, constraints=base[1:]
    )
    with pytest.raises(ConfigError, match="optionally followed by others"):
        optimize_motion("anymal_c", "flat", TASK, config=dropped, init=init, max_iter=0)
