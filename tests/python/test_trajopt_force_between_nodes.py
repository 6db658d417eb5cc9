"""Contact forces that stay unilateral and inside the friction pyramid between the force nodes."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    TerrainModel,
    make_gait,
    melon_config,
    towr_config,
)
from roughwalk.trajopt.constraints.force_between_nodes import inner_control_points
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS, TOWR_CONSTRAINTS
from roughwalk.trajopt.task import Task, resolve
from roughwalk.trajopt.variables import NumericSpline

WITH_BETWEEN = (*MELON_REACH_CONSTRAINTS, "force_between_nodes")


@pytest.fixture(scope="module")
def flat() -> TerrainModel:
    return TerrainModel(load_terrain("flat"))


def _problem(
    flat: TerrainModel, optimize: bool = False
) -> tuple[Formulation, np.ndarray, np.ndarray]:
    config = melon_config(
        duration=2.0, steps=4, constraints=WITH_BETWEEN, optimize_durations=optimize
    )
    nlp = Formulation(config, TOWR_ANYMAL, make_gait("walk", 4, 2.0), flat)
    task = resolve(Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)), TOWR_ANYMAL, flat)
    return nlp, HeuristicInitializer().guess(nlp, task), task.vector()


def _violation(nlp: Formulation, x: np.ndarray, p: np.ndarray, name: str) -> float:
    g = np.asarray(nlp.evaluator(x, p)[1]).ravel()
    rows = nlp.row_slices()[name]
    below = nlp.lbg[rows] - g[rows]
    above = g[rows] - nlp.ubg[rows]
    return float(max(below.max(), above.max(), 0.0))


def test_segment_is_inside_the_hull_of_its_control_points() -> None:
    # The reason the rows suffice: the Hermite segment is the Bézier curve
    # through f0, the two inner control points and f1, so it stays in their hull.
    rng = np.random.default_rng(0)
    for _ in range(200):
        f0, v0, f1, v1 = (rng.normal(scale=s, size=3) for s in (100, 3000, 100, 3000))
        d = float(rng.uniform(0.05, 0.5))
        c1, c2 = (np.asarray(c).ravel() for c in inner_control_points(f0, v0, f1, v1, d))
        spline = NumericSpline([f0, f1], [v0, v1], [d])
        t = np.linspace(0.0, d, 101)
        values = spline.evaluate(t)[0]
        tau = (t / d)[:, None]
        bezier = (
            (1 - tau) ** 3 * f0
            + 3 * (1 - tau) ** 2 * tau * c1
            + 3 * (1 - tau) * tau**2 * c2
            + tau**3 * f1
        )
        np.testing.assert_allclose(values, bezier, atol=1e-8 * np.abs(values).max())
        hull = np.stack([f0, c1, c2, f1])
        assert np.all(values >= hull.min(axis=0) - 1e-9)
        assert np.all(values <= hull.max(axis=0) + 1e-9)


def test_force_that_pulls_between_positive_nodes_is_rejected(flat: TerrainModel) -> None:
    nlp, x, p = _problem(flat)
    force = nlp.forces[0]
    parts = nlp.split(x)
    pos, vel = force.unpack(parts[force.name])
    phase = nlp.stance_phases(0)[1]
    inner = force.inner_nodes(phase)
    # Every node pushes with 200 N straight down on the ground; the first inner
    # node's rate is so large that the segment after it dips below zero.
    pos[inner] = [0.0, 0.0, 200.0]
    vel[inner] = 0.0
    vel[inner[0], 2] = -8000.0
    parts[force.name] = force.pack(pos, vel)
    x = nlp.join(parts)
    k = inner[0]
    spline = NumericSpline(pos[k : k + 2], vel[k : k + 2], [force.spline.durations[k]])
    dense = spline.evaluate(np.linspace(0.0, force.spline.durations[k], 201))[0][:, 2]
    assert dense.min() < -50.0  # the spline does pull on the ground mid-segment
    assert _violation(nlp, x, p, "force") < 1e-9  # the node rows do not see it
    assert _violation(nlp, x, p, "force_between_nodes") > 50.0
    # With zero rates the same nodes hold the force at 200 N throughout: accepted.
    vel[inner] = 0.0
    parts[force.name] = force.pack(pos, vel)
    assert _violation(nlp, nlp.join(parts), p, "force_between_nodes") < 1e-9


@pytest.mark.parametrize("optimize", [False, True])
def test_jacobian_against_finite_differences(flat: TerrainModel, optimize: bool) -> None:
    # With optimised durations the control points depend on the phase durations too.
    nlp, x, p = _problem(flat, optimize)
    x = x + np.random.default_rng(1).normal(scale=0.01, size=x.size)
    rows = nlp.row_slices()["force_between_nodes"]
    names = [nlp.x[i].name() for i in range(x.size)]
    columns = [i for i, n in enumerate(names) if n.startswith(("foot_force_0", "phase_dur"))]
    assert columns
    _, jac = nlp.jac_g(x, p)
    jac = np.asarray(ca.densify(jac))[rows]
    h = 1e-6
    for j in columns:
        e = np.zeros_like(x)
        e[j] = h
        plus = np.asarray(nlp.evaluator(x + e, p)[1]).ravel()[rows]
        minus = np.asarray(nlp.evaluator(x - e, p)[1]).ravel()[rows]
        fd = (plus - minus) / (2 * h)
        np.testing.assert_allclose(jac[:, j], fd, rtol=1e-5, atol=1e-5 * max(1.0, np.abs(fd).max()))


def test_rows_add_no_variables(flat: TerrainModel) -> None:
    # TOWR's counts (848 fixed at 3.4 s, 952 optimised at 4.0 s) hold with the new rows.
    for duration, optimize, count in ((3.4, False, 848), (4.0, True, 952)):
        config = towr_config(
            optimize_durations=optimize, constraints=(*TOWR_CONSTRAINTS, "force_between_nodes")
        )
        nlp = Formulation(config, TOWR_ANYMAL, make_gait("walk", 16, duration), flat)
        assert nlp.n_variables == count
        # Ten rows per stance force segment: 3 segments per stance of each foot.
        stances = sum(len(nlp.stance_phases(f)) for f in range(nlp.n_feet))
        assert (
            nlp.row_slices()["force_between_nodes"].stop
            - nlp.row_slices()["force_between_nodes"].start
            == 10 * config.force_polys_per_stance * stances
        )


def test_unilateral_rows_reject_pulling_but_not_sliding(flat: TerrainModel) -> None:
    # unilateral_between_nodes keeps only 0 ≤ f·n at the inner control points:
    # two rows a segment; a segment that leaves the friction pyramid passes.
    config = melon_config(
        duration=2.0,
        steps=4,
        constraints=(*WITH_BETWEEN, "unilateral_between_nodes"),
    )
    nlp = Formulation(config, TOWR_ANYMAL, make_gait("walk", 4, 2.0), flat)
    task = resolve(Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)), TOWR_ANYMAL, flat)
    x, p = HeuristicInitializer().guess(nlp, task), task.vector()
    rows = nlp.row_slices()
    assert (
        rows["unilateral_between_nodes"].stop - rows["unilateral_between_nodes"].start
        == (rows["force_between_nodes"].stop - rows["force_between_nodes"].start) // 5
    )
    force = nlp.forces[0]
    parts = nlp.split(x)
    pos, vel = force.unpack(parts[force.name])
    inner = force.inner_nodes(nlp.stance_phases(0)[1])
    pos[inner] = [0.0, 0.0, 200.0]
    vel[inner] = 0.0
    vel[inner[0], 2] = -8000.0  # dips below zero mid-segment
    parts[force.name] = force.pack(pos, vel)
    assert _violation(nlp, nlp.join(parts), p, "unilateral_between_nodes") > 50.0
    vel[inner[0]] = [8000.0, 0.0, 0.0]  # slides: lateral force far outside the pyramid
    parts[force.name] = force.pack(pos, vel)
    assert _violation(nlp, nlp.join(parts), p, "force_between_nodes") > 50.0
    assert _violation(nlp, nlp.join(parts), p, "unilateral_between_nodes") < 1e-9
