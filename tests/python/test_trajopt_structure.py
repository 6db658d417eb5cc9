"""The NLP's structure: TOWR's variable counts, gaits, splines with symbolic durations."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    GAIT_NAMES,
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    TerrainModel,
    make_gait,
    melon_config,
    towr_config,
    valid_step_counts,
)
from roughwalk.trajopt.point_jacobian import points_jacobian
from roughwalk.trajopt.task import Task, resolve
from roughwalk.trajopt.variables import (
    NodeSpline,
    NumericSpline,
    PhaseDurations,
    hermite_point,
    sample_points,
)
from roughwalk.trajopt.variables.phase_durations import ADMIT_MARGIN


@pytest.fixture(scope="module")
def flat() -> TerrainModel:
    return TerrainModel(load_terrain("flat"))


def _formulation(
    flat: TerrainModel, duration: float, optimize: bool, **changes: object
) -> Formulation:
    config = towr_config(optimize_durations=optimize, **changes)
    return Formulation(config, TOWR_ANYMAL, make_gait("walk", 16, duration), flat)


def test_variable_counts_equal_towrs(flat: TerrainModel) -> None:
    # TOWR 1.4, ANYmal, 16-step walk: 848 variables at T = 3.4 s with fixed
    # durations, 952 at T = 4.0 s with optimised ones (Melon 2020, §V).
    assert _formulation(flat, 3.4, False).n_variables == 848
    assert _formulation(flat, 4.0, True).n_variables == 952
    # Constraints add rows, never variables.
    assert _formulation(flat, 4.0, True, constraints=()).n_variables == 952


def test_variable_count_matches_melons_formula(flat: TerrainModel) -> None:
    # N = 12 T/dt + 20 S + 120 (+ 2S with optimised durations), Melon 2020 §III-A.
    for duration in (2.4, 3.0, 5.5):
        n_fixed = 12 * round(duration / 0.1) + 20 * 16 + 120
        fixed = _formulation(flat, duration, False, constraints=())
        free = _formulation(flat, duration, True, constraints=())
        assert fixed.n_variables == n_fixed
        assert free.n_variables == n_fixed + 2 * 16


def test_gaits_make_their_step_counts() -> None:
    assert valid_step_counts("walk", 4) == [4, 8, 12, 16]
    assert valid_step_counts("trot", 8) == [2, 4, 6, 8, 10, 12, 14, 16]
    for gait in GAIT_NAMES:
        for steps in valid_step_counts(gait, 3):
            schedule = make_gait(gait, steps, 3.0)
            assert schedule.steps == steps
            for durations in schedule.durations:
                assert sum(durations) == pytest.approx(3.0)
                assert min(durations) > 0
            # Every gait opens and closes with all four feet down.
            assert all(schedule.in_contact_at_start)
            assert all(schedule.in_contact(f, 3.0)[0] for f in range(4))


def test_trot_makes_towrs_14_steps_and_any_even_count() -> None:
    # TOWR's flying trot (0.4 s diagonal stance, 0.1 s flight) between 0.3 s
    # stands, three strides and its end stride: 4.0 s, 14 steps; every
    # phase scales with the duration.
    towr = make_gait("trot", 14, 4.0)
    assert towr.durations[0] == pytest.approx((0.7, 0.6, 0.4, 0.6, 0.4, 0.6, 0.7))
    assert towr.durations[1] == pytest.approx((0.3, 0.5, 0.4, 0.6, 0.4, 0.6, 0.4, 0.5, 0.3))
    assert make_gait("trot", 14, 3.5).durations[0] == pytest.approx(
        [d * 3.5 / 4.0 for d in towr.durations[0]]
    )
    for steps in (2, 4, 8, 16):
        schedule = make_gait("trot", steps, 4.6)
        assert schedule.steps == steps
        # Diagonal pairs (LF, RH) and (RF, LH) lift and land together.
        assert schedule.durations[0] == schedule.durations[3]
        assert schedule.durations[1] == schedule.durations[2]
        assert all(schedule.in_contact(f, 4.6)[0] for f in range(4))
        times = np.linspace(0.0, 4.6, 461)
        # Never all four feet up for longer than the 0.1 s flight, never one foot alone.
        stance = np.array([schedule.in_contact(f, times) for f in range(4)])
        assert set(stance.sum(axis=0)) <= {0, 2, 4}
    sixteen = make_gait("trot", 16, 4.6)
    assert [sixteen.swing_count(f) for f in range(4)] == [4, 4, 4, 4]
    assert sixteen.durations[0] == pytest.approx((0.7, 0.6, 0.4, 0.6, 0.4, 0.6, 0.4, 0.6, 0.3))
    assert sixteen.durations[1] == pytest.approx((0.3, 0.5, 0.4, 0.6, 0.4, 0.6, 0.4, 0.6, 0.8))


def test_fitted_schedule_keeps_totals_and_moves_phases_into_bounds() -> None:
    # 5.5 s of a 16-step walk has stances over 1.0 s and, at 3.5 s, swings
    # under 0.2 s: outside TOWR's duration bounds.
    for duration in (3.5, 5.5):
        nominal = make_gait("walk", 16, duration)
        fitted = nominal.fitted((0.2, 1.0))
        assert fitted.in_contact_at_start == nominal.in_contact_at_start
        for before, after in zip(nominal.durations, fitted.durations, strict=True):
            assert sum(after) == pytest.approx(sum(before), abs=1e-12)
            assert min(after) >= 0.2 - 1e-12 and max(after) <= 1.0 + 1e-12
            # The phases that were not clamped share the difference in proportion.
            kept = [0.2 < b < 1.0 and 0.2 < a < 1.0 for a, b in zip(after, before, strict=True)]
            ratios = np.array(after)[kept] / np.array(before)[kept]
            assert ratios.size and np.ptp(ratios) < 1e-9
    within = make_gait("walk", 16, 4.0).fitted((0.1, 2.0))
    assert within.durations == make_gait("walk", 16, 4.0).durations
    # A foot whose phases cannot fit is left alone (the caller reports it).
    assert make_gait("walk", 4, 9.0).fitted((0.2, 1.0)).durations == (
        make_gait("walk", 4, 9.0).durations
    )


def test_bad_gaits_are_refused_by_name() -> None:
    with pytest.raises(InvalidArgumentError, match="walk gait cannot make 14 steps.*4, 8, 12"):
        make_gait("walk", 14, 3.0)
    with pytest.raises(InvalidArgumentError, match="unknown gait 'amble'.*walk, trot"):
        make_gait("amble", 4, 3.0)
    with pytest.raises(ConfigError, match="unknown constraint 'friction'"):
        _formulation(TerrainModel(load_terrain("flat")), 2.0, False, constraints=("friction",))


def test_numeric_spline_is_the_hermite_polynomial() -> None:
    rng = np.random.default_rng(0)
    pos, vel = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    durations = np.array([0.3, 0.2, 0.5])
    spline = NumericSpline(pos, vel, durations)
    # Nodes are hit with their values and derivatives.
    p, v, _ = spline.evaluate([0.0, 0.3, 0.5, 1.0])
    np.testing.assert_allclose(p, pos, atol=1e-12)
    np.testing.assert_allclose(v, vel, atol=1e-12)
    # Velocity and acceleration are the derivatives of position (central differences).
    t = np.linspace(0.01, 0.99, 37)
    h = 1e-6
    p_plus, v_plus, _ = spline.evaluate(t + h)
    p_minus, v_minus, _ = spline.evaluate(t - h)
    _, v_mid, a_mid = spline.evaluate(t)
    inside = np.all(np.abs(t[:, None] - np.array([0.3, 0.5])) > 2 * h, axis=1)
    np.testing.assert_allclose(((p_plus - p_minus) / (2 * h))[inside], v_mid[inside], atol=1e-6)
    np.testing.assert_allclose(((v_plus - v_minus) / (2 * h))[inside], a_mid[inside], atol=1e-5)


def test_symbolic_durations_pick_the_right_polynomial() -> None:
    # With symbolic durations the spline sums switched candidates; at any
    # durations it must equal the plain numeric spline.
    rng = np.random.default_rng(1)
    pos, vel = rng.normal(size=(5, 3)), rng.normal(size=(5, 3))
    d = ca.SX.sym("d", 4)
    windows = [(0.2 * k, 1.0 * (k + 1)) for k in range(4)]
    spline = NodeSpline(list(pos), list(vel), [d[k] for k in range(4)], windows)
    times = np.linspace(0.0, 1.6, 41)
    f = ca.Function("f", [d], [ca.horzcat(*[ca.vertcat(*spline.point(t)) for t in times])])
    for durations in ([0.4, 0.4, 0.4, 0.4], [0.25, 0.7, 0.2, 0.45], [0.2, 0.2, 0.2, 1.0]):
        values = np.asarray(f(durations))
        ref = NumericSpline(pos, vel, durations)
        t_in = np.minimum(times, sum(durations))
        p, v, a = ref.evaluate(t_in)
        ok = times <= sum(durations) + 1e-12
        np.testing.assert_allclose(values[0:3, ok].T, p[ok], atol=1e-10)
        np.testing.assert_allclose(values[3:6, ok].T, v[ok], atol=1e-10)
        np.testing.assert_allclose(values[6:9, ok].T, a[ok], atol=1e-9)


def test_picked_samples_jacobians_equal_casadis() -> None:
    # A sample among candidate polynomials carries its own Jacobian (the
    # Hermite derivatives written out, times the candidates' switches);
    # through points_jacobian it must equal CasADi's AD of the sample, also
    # at junctions, at t = 0 and at the end, and for one-candidate samples.
    rng = np.random.default_rng(3)
    x, v, d = ca.SX.sym("x", 3, 5), ca.SX.sym("v", 3, 5), ca.SX.sym("d", 3)
    durations = [d[0], d[1], d[2], 1.6 - d[0] - d[1] - d[2]]
    windows = [(0.0, 0.2), (0.05, 0.9), (0.2, 1.4), (0.4, 1.6)]
    spline = NodeSpline(ca.horzsplit(x), ca.horzsplit(v), durations, windows)
    times = [0.0, 0.05, 0.15, 0.3, 0.45, 0.6, 0.8, 1.0, 1.25, 1.6]
    points = [spline.point(t)[0] for t in times]
    assert any(len(spline.candidates(t)) == 1 for t in times)
    assert any(len(spline.candidates(t)) > 2 for t in times)
    u = ca.vertcat(*points)
    z = ca.vertcat(ca.vec(x), ca.vec(v), d)
    f = ca.Function("f", [z], [points_jacobian(u, z, spline.picked), ca.jacobian(u, z)])
    for schedule in ([0.1, 0.5, 0.4], [0.15, 0.3, 0.6], [0.05, 0.25, 0.3]):
        for _ in range(3):
            values = np.concatenate([rng.normal(size=30), schedule])
            ours, casadis = (np.asarray(j) for j in f(values))
            np.testing.assert_allclose(ours, casadis, rtol=1e-12, atol=1e-12)
            assert np.count_nonzero(ours) > 0


def test_mapped_spline_points_equal_the_single_ones() -> None:
    # Fixed durations: one mapped call must give the point-by-point values
    # bit for bit, junctions and the end included.
    x = ca.SX.sym("x", 3, 5)
    v = ca.SX.sym("v", 3, 5)
    durations = [0.3, 0.2, 0.5, 0.25]
    spline = NodeSpline(ca.horzsplit(x), ca.horzsplit(v), durations)
    times = [0.0, 0.1, 0.3, 0.45, 0.5, 0.9, 1.25]
    (mapped,) = sample_points([spline], times)
    single = [spline.point(t) for t in times]
    f = ca.Function(
        "f",
        [x, v],
        [
            ca.horzcat(*[ca.vertcat(*p) for p in mapped]),
            ca.horzcat(*[ca.vertcat(*p) for p in single]),
        ],
    )
    rng = np.random.default_rng(2)
    a, b = f(rng.normal(size=(3, 5)), rng.normal(size=(3, 5)))
    assert np.array_equal(np.asarray(a), np.asarray(b))
    assert not np.all(np.asarray(a) == 0)


def test_polynomial_windows_hold_every_admissible_schedule() -> None:
    # A spline sample only selects among the polynomials whose window holds
    # it: at any durations within their bounds (last phase >= 0) every
    # polynomial must start and end inside its window, and the windows must
    # be tighter than the phases' own (i*min, (i+1)*max) somewhere.
    durations = PhaseDurations(0, [3.5 / 9] * 9, (0.2, 1.0), optimize=True)
    rng = np.random.default_rng(3)
    tighter = False
    for m in (1, 2, 3):
        for phase in range(9):
            for j in range(m):
                lo, hi = durations.poly_window(phase, j, m)
                old_hi = 3.5 if phase == 8 else min(1.0 * (phase + 1), 3.5)
                assert 0.2 * phase - 1e-12 <= lo and hi <= old_hi + 1e-12
                tighter |= lo > 0.2 * phase + 1e-9 or hi < old_hi - 1e-9
    assert tighter
    checked = 0
    while checked < 300:
        free = rng.uniform(0.2, 1.0, 8)
        if rng.random() < 0.3:  # push some schedules onto the extremes
            free = np.where(rng.random(8) < 0.5, 0.2, 1.0)
        if free.sum() > 3.5:
            continue
        checked += 1
        d = np.append(free, 3.5 - free.sum())
        starts = np.concatenate([[0.0], np.cumsum(d)[:-1]])
        for m in (1, 2, 3):
            for phase in range(9):
                for j in range(m):
                    lo, hi = durations.poly_window(phase, j, m)
                    start = starts[phase] + j * d[phase] / m
                    assert lo - 1e-9 <= start and start + d[phase] / m <= hi + 1e-9


def test_bounds_that_admit_the_nominal_phases_widen_only_theirs_and_keep_windows() -> None:
    # 16-step walk in 5.5 s: the front-right foot's first stance (1.079 s)
    # is beyond TOWR's 1.0 s. Admitted, that phase alone is widened to it;
    # every polynomial of every schedule within the per-phase bounds still
    # starts and ends inside its window (the windows assume the widest phase).
    gait = make_gait("walk", 16, 5.5)
    foot = next(f for f, d in enumerate(gait.durations) if max(d[:-1]) > 1.0)
    nominal = list(gait.durations[foot])
    plain = PhaseDurations(foot, nominal, (0.2, 1.0), optimize=True)
    admitted = PhaseDurations(foot, nominal, (0.2, 1.0), optimize=True, admit_nominal=True)
    own = np.asarray(nominal[:-1])
    wide = own > 1.0
    assert wide.sum() == 1 and own[wide][0] == pytest.approx(1.079, abs=1e-3)
    np.testing.assert_allclose(admitted.upper[wide], own[wide] + ADMIT_MARGIN)
    np.testing.assert_array_equal(admitted.upper[~wide], plain.upper[~wide])
    np.testing.assert_array_equal(admitted.lower, plain.lower)
    assert admitted.bounds == (0.2, pytest.approx(own.max() + ADMIT_MARGIN))
    # The gait is feasible and off every bound (IPOPT would push it inside).
    assert np.all((admitted.lower < own - 1e-3) & (own + 1e-3 < admitted.upper))
    n, total = len(nominal), sum(nominal)
    rng = np.random.default_rng(4)
    checked = 0
    while checked < 300:
        free = rng.uniform(admitted.lower, admitted.upper)
        if rng.random() < 0.3:
            free = np.where(rng.random(n - 1) < 0.5, admitted.lower, admitted.upper)
        if free.sum() > total:
            continue
        checked += 1
        d = np.append(free, total - free.sum())
        starts = np.concatenate([[0.0], np.cumsum(d)[:-1]])
        for m in (1, 2, 3):
            for phase in range(n):
                for j in range(m):
                    lo, hi = admitted.poly_window(phase, j, m)
                    start = starts[phase] + j * d[phase] / m
                    assert lo - 1e-9 <= start and start + d[phase] / m <= hi + 1e-9
    # Through the formulation: the NLP starts from the gait itself, not a fitted schedule.
    nlp = Formulation(
        towr_config(optimize_durations=True, phase_bounds_admit_gait=True),
        TOWR_ANYMAL,
        gait,
        TerrainModel(load_terrain("flat")),
    )
    for d, own_durations in zip(nlp.durations, gait.durations, strict=True):
        assert d.nominal == list(own_durations)
        assert np.all((d.lower <= d.nominal[:-1]) & (np.asarray(d.nominal[:-1]) <= d.upper))


def test_optimised_durations_give_the_fixed_problem_at_equal_durations(flat: TerrainModel) -> None:
    # The same task, guess and durations through both formulations: every
    # constraint value must agree, so the duration machinery changes nothing
    # but the freedom. Durations are kept in their 0.2–1.0 s bounds, as IPOPT
    # keeps every iterate.
    free = _formulation(flat, 5.5, True)
    durations = []
    for d in free.durations:
        inner = np.clip(d.nominal[:-1], 0.2, 1.0)
        durations.append([*inner, d.total - inner.sum()])
    schedule = make_gait("walk", 16, 5.5).with_durations(durations)
    fixed = Formulation(towr_config(), TOWR_ANYMAL, schedule, flat)
    task = resolve(Task((0.0, 0.0, 0.0), (1.0, 0.1, 0.2)), TOWR_ANYMAL, flat)
    rng = np.random.default_rng(2)
    x_fixed = HeuristicInitializer().guess(fixed, task)
    x_fixed = x_fixed + rng.normal(scale=0.01, size=x_fixed.size)
    parts = fixed.split(x_fixed)
    for d, values in zip(free.durations, durations, strict=True):
        parts[d.name] = d.pack(values)
    x_free = free.join(parts)
    _, g_fixed, _ = fixed.evaluator(x_fixed, task.vector())
    _, g_free, _ = free.evaluator(x_free, task.vector())
    g_free = np.asarray(g_free).ravel()
    g_fixed = np.asarray(g_fixed).ravel()
    free_rows = free.row_slices()
    for name, rows in fixed.row_slices().items():
        np.testing.assert_allclose(g_free[free_rows[name]], g_fixed[rows], atol=1e-9, err_msg=name)


def test_hermite_point_matches_its_definition() -> None:
    x0, v0, x1, v1, d = 0.3, -1.0, 1.2, 0.5, 0.7
    p0, dp0, _ = hermite_point(x0, v0, x1, v1, d, 0.0)
    p1, dp1, _ = hermite_point(x0, v0, x1, v1, d, d)
    assert (p0, dp0) == pytest.approx((x0, v0))
    assert (p1, dp1) == pytest.approx((x1, v1))


def test_initialisers_by_name_and_the_learned_plug_in_point() -> None:
    from roughwalk.trajopt import initializer_names, make_initializer, register_initializer
    from roughwalk.trajopt.initializers import registry

    assert {"heuristic", "footsteps"} <= set(initializer_names())
    assert isinstance(make_initializer("heuristic"), HeuristicInitializer)
    # The learning wing registers "learned" when it is imported; without it
    # the plug-in point names its provider.
    learned = registry._REGISTRY.pop("learned", None)
    try:
        with pytest.raises(ConfigError, match="registered by roughwalk.learning"):
            make_initializer("learned")
        with pytest.raises(InvalidArgumentError, match="does not exist"):
            make_initializer("footsteps:/no/such/plan.json")
        register_initializer("learned", lambda argument: HeuristicInitializer(argument))
        assert isinstance(make_initializer("learned"), HeuristicInitializer)
    finally:
        registry._REGISTRY.pop("learned", None)
        if learned is not None:
            registry._REGISTRY["learned"] = learned


def test_ipopt_options_are_part_of_the_structure_key() -> None:
    # A cached problem carries the IPOPT options it was built with; another set must not reuse it.
    from roughwalk.trajopt.parameters import SolverOptions, TrajoptConfig

    plain = TrajoptConfig()
    adaptive = TrajoptConfig(solver=SolverOptions(ipopt_options=("mu_strategy=adaptive",)))
    assert plain.structure_key() != adaptive.structure_key()
    assert plain.structure_key() == TrajoptConfig().structure_key()
    # So are the warm-start sets: each problem holds its warm solvers too.
    for field in ("warm_ipopt_options", "guess_ipopt_options"):
        other = TrajoptConfig(solver=SolverOptions(**{field: ("mu_init=1e-3",)}))
        assert plain.structure_key() != other.structure_key()
    with pytest.raises(ConfigError, match="guess_ipopt_options entries are name=value"):
        SolverOptions(guess_ipopt_options=("mu_init",))


def test_dropped_picked_samples_lend_no_jacobian_to_later_expressions() -> None:
    # NodeSpline.picked is keyed by element hash, a node's address. A sample
    # whose position its caller drops frees its nodes; a later expression
    # (here the velocities of fresh samples) allocated at a freed address must
    # not take the dropped position's Jacobian in points_jacobian.
    x, v, d = ca.SX.sym("x", 3, 5), ca.SX.sym("v", 3, 5), ca.SX.sym("d", 4)
    windows = [(0.0, 0.4), (0.2, 0.8), (0.4, 1.2), (0.6, 1.6)]
    spline = NodeSpline(ca.horzsplit(x), ca.horzsplit(v), ca.vertsplit(d), windows)
    z = ca.vertcat(ca.vec(x), ca.vec(v), d)
    times = list(np.linspace(0.05, 1.1, 15))
    values = np.random.default_rng(1).uniform(0.25, 0.35, int(z.numel()))
    for _ in range(10):
        spline.points(times)  # positions dropped
        u = ca.vertcat(*[vel for _, vel, _ in spline.points(times)])
        f = ca.Function("f", [z], [points_jacobian(u, z, spline.picked) - ca.jacobian(u, z)])
        assert np.max(np.abs(np.asarray(f(values)))) < 1e-12


def test_an_admitted_phase_shorter_than_the_margin_keeps_a_positive_lower_bound() -> None:
    # A 6 ms phase admitted below TOWR's 0.2 s: its bound comes down to half
    # of itself, never to 0 or below (a zero-length phase has no polynomial).
    nominal = [0.006, 0.5, 0.5]
    admitted = PhaseDurations(0, nominal, (0.2, 1.0), optimize=True, admit_nominal=True)
    assert admitted.lower[0] == pytest.approx(0.003)
    assert admitted.lower[1] == pytest.approx(0.2)
    assert np.all(admitted.lower > 0.0) and np.all(admitted.lower < nominal[:-1])


def test_the_gait_is_admitted_by_default_but_not_in_towrs_problem(flat: TerrainModel) -> None:
    # On by default (melon_config, the pallet walks); TOWR's problem keeps
    # TOWR's bounds, and so its fitted start (its 3.5 s walk has phases under 0.2 s).
    assert melon_config().phase_bounds_admit_gait
    assert not towr_config().phase_bounds_admit_gait
    gait = make_gait("walk", 16, 5.5)
    default = Formulation(melon_config(optimize_durations=True), TOWR_ANYMAL, gait, flat)
    assert [list(d) for d in default.schedule.durations] == [list(d) for d in gait.durations]
    towr = _formulation(flat, 5.5, True)
    assert [list(d) for d in towr.schedule.durations] != [list(d) for d in gait.durations]
    assert max(float(d.upper.max()) for d in towr.durations) == pytest.approx(1.0)


def test_admitting_the_gait_changes_nothing_with_fixed_durations(flat: TerrainModel) -> None:
    # The option only widens optimised phases' bounds: with fixed durations
    # the NLP is the same, variable by variable and row by row.
    on = _formulation(flat, 5.5, False, phase_bounds_admit_gait=True)
    off = _formulation(flat, 5.5, False, phase_bounds_admit_gait=False)
    assert on.row_layout == off.row_layout
    assert [(v.name, v.size) for v in on.variable_sets] == [
        (v.name, v.size) for v in off.variable_sets
    ]
    for a, b in ((on.lbx, off.lbx), (on.ubx, off.ubx), (on.lbg, off.lbg), (on.ubg, off.ubg)):
        np.testing.assert_array_equal(a, b)
    task = resolve(Task((0.0, 0.0, 0.0), (1.0, 0.1, 0.2)), TOWR_ANYMAL, flat)
    x = HeuristicInitializer().guess(on, task)
    np.testing.assert_array_equal(x, HeuristicInitializer().guess(off, task))
    f_on, g_on, _ = on.evaluator(x, task.vector())
    f_off, g_off, _ = off.evaluator(x, task.vector())
    assert float(f_on) == float(f_off)
    np.testing.assert_array_equal(np.asarray(g_on), np.asarray(g_off))
